//! Garment kinds and their cut parameters.
//!
//! Lengths are metres measured on the template body (the default phenotype in its rest
//! A-pose, 1.626 m tall); warping carries a garment to other shapes and poses.

use serde::{Deserialize, Serialize};

use crate::GarmentError;

/// The garments garnet builds, and user garments imported from a mesh.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum GarmentKind {
    /// Short-sleeved T-shirt: openings at the neck, the hem and two cuffs.
    Tshirt,
    /// Long-sleeved, looser and longer sweater: same openings as the T-shirt.
    Sweater,
    /// Jeans from the waist to the ankles: openings at the waist and two ankles.
    Jeans,
    /// A garment imported from a user's mesh, with its name.
    Custom(String),
}

impl GarmentKind {
    /// Parses `tshirt`, `sweater` or `jeans`.
    pub fn parse(name: &str) -> Result<Self, GarmentError> {
        match name.to_ascii_lowercase().replace(['-', '_'], "").as_str() {
            "tshirt" => Ok(Self::Tshirt),
            "sweater" => Ok(Self::Sweater),
            "jeans" => Ok(Self::Jeans),
            _ => Err(GarmentError::Parameter(format!(
                "unknown garment '{name}' (expected tshirt, sweater or jeans)"
            ))),
        }
    }

    /// Lower-case name.
    pub fn name(&self) -> &str {
        match self {
            Self::Tshirt => "tshirt",
            Self::Sweater => "sweater",
            Self::Jeans => "jeans",
            Self::Custom(name) => name,
        }
    }

    /// Whether the garment covers the upper body (sleeves, neck) or the legs.
    pub fn is_top(&self) -> bool {
        matches!(self, Self::Tshirt | Self::Sweater)
    }

    /// Number of openings (boundary loops) of a built template.
    pub fn openings(&self) -> Option<usize> {
        match self {
            Self::Tshirt | Self::Sweater => Some(4),
            Self::Jeans => Some(3),
            Self::Custom(_) => None,
        }
    }
}

/// Cut parameters of a garment (metres on the template body). Parameters a kind does
/// not use are ignored (`sleeve_length` and `neckline_depth` for jeans; `waist_height`,
/// `leg_length` and `thigh` for tops).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CutParams {
    /// Tops: from the base of the neck down to the hem.
    pub body_length: f32,
    /// Tops: from the shoulder joint along the arm to the cuff.
    pub sleeve_length: f32,
    /// Looseness: the garment's mean gap to the skin before draping.
    pub ease: f32,
    /// Tops: how far the front of the neckline drops below the neck base.
    pub neckline_depth: f32,
    /// Jeans: waistband height above the hip joint (negative: low-rise).
    pub waist_height: f32,
    /// Jeans: from the hip joint along the leg to the hem.
    pub leg_length: f32,
    /// Extra ease at the limb openings (sleeve cuffs, trouser hems): none up to a quarter of
    /// the way along the sleeve or leg, growing linearly to this at the opening, so the sleeve or
    /// leg hangs straight instead of following the arm or calf.
    pub flare: f32,
    /// How much the cloth spans the body's hollows (the armpits, the gluteal cleft, between
    /// the breasts) instead of following them into the folds, 0 to 1: the share of the
    /// template's bridging smoothing rounds kept (a fraction, not metres). Spanning the
    /// armpit leaves less cloth there than a raised arm unfolds the skin into.
    pub bridge: f32,
    /// Jeans: extra ease over the thighs and knees (a looser thigh, as "relaxed" and
    /// "carrot" cuts have): none at the hips, growing to this [`THIGH_PEAK`] of the way
    /// down the leg (above the knee), none again from `THIGH_PEAK + THIGH_SPAN` (75%) on.
    pub thigh: f32,
}

/// Where along the trouser leg (a fraction of the cut's leg length) the `thigh` room is
/// largest; it grows linearly from none at the hips (`THIGH_PEAK - THIGH_SPAN`) and falls
/// back to none at `THIGH_PEAK + THIGH_SPAN`.
pub const THIGH_PEAK: f32 = 0.4;
/// Half the length of the leg (a fraction) over which the `thigh` room spreads.
pub const THIGH_SPAN: f32 = 0.35;

/// Valid range of each parameter, `(name, min, max)`: metres, except `bridge` (a fraction).
pub const RANGES: [(&str, f32, f32); 9] = [
    ("body_length", 0.35, 0.62),
    ("sleeve_length", 0.06, 0.5),
    ("ease", 0.005, 0.06),
    ("neckline_depth", 0.0, 0.12),
    ("waist_height", -0.06, 0.14),
    ("leg_length", 0.2, 0.8),
    ("flare", 0.0, 0.08),
    ("bridge", 0.0, 1.0),
    ("thigh", 0.0, 0.06),
];

impl CutParams {
    /// The default cut of a kind: a regular T-shirt and a loose long sweater, both with
    /// straight sleeves (`flare` 3 cm) and cloth that follows the armpit fold (`bridge` 0),
    /// so that they fit arms raised overhead; relaxed, tapered jeans (4 cm of ease and 3 cm
    /// more over the thighs and knees) up to the natural waist (`waist_height` 0.10, where
    /// the body is narrower than the hips, so the simulator's elastic waistband holds them
    /// up), following the body's hollows (`bridge` 0: more cloth behind the knees and in the
    /// seat). Measured on the 30-drape sheet at 1 cm: 26 drapes at rest under 2% strain p99
    /// (every top, 6 of 10 jeans), against 21 with the [`first_for`](Self::first_for) cut;
    /// with the waistband, all 30 (without the thigh room 9 of 10 jeans, with `bridge` 0.5
    /// 7).
    pub fn default_for(kind: &GarmentKind) -> Self {
        let first = Self::first_for(kind);
        match kind {
            GarmentKind::Tshirt | GarmentKind::Sweater => Self {
                flare: 0.03,
                bridge: 0.0,
                ..first
            },
            GarmentKind::Jeans => Self {
                bridge: 0.0,
                ease: 0.04,
                waist_height: 0.10,
                thigh: 0.03,
                ..first
            },
            GarmentKind::Custom(_) => first,
        }
    }

    /// The first cut of garnet's garments (tops without flare, bridging the armpits): the
    /// cut [`default_for`](Self::default_for) starts from, and the one the benchmark dataset
    /// spec (`specs/standard-lbs.toml`) names in full.
    pub fn first_for(kind: &GarmentKind) -> Self {
        match kind {
            GarmentKind::Sweater => Self {
                body_length: 0.6,
                sleeve_length: 0.46,
                ease: 0.05,
                neckline_depth: 0.02,
                ..Self::TSHIRT
            },
            GarmentKind::Jeans => Self {
                ease: 0.02,
                ..Self::TSHIRT
            },
            _ => Self::TSHIRT,
        }
    }

    const TSHIRT: Self = Self {
        body_length: 0.59,
        sleeve_length: 0.28,
        ease: 0.04,
        neckline_depth: 0.04,
        waist_height: 0.04,
        leg_length: 0.75,
        flare: 0.0,
        bridge: 1.0,
        thigh: 0.0,
    };

    /// `(name, value)` of every parameter, in [`RANGES`] order.
    pub fn named(&self) -> [(&'static str, f32); 9] {
        [
            ("body_length", self.body_length),
            ("sleeve_length", self.sleeve_length),
            ("ease", self.ease),
            ("neckline_depth", self.neckline_depth),
            ("waist_height", self.waist_height),
            ("leg_length", self.leg_length),
            ("flare", self.flare),
            ("bridge", self.bridge),
            ("thigh", self.thigh),
        ]
    }

    /// The parameter at `index` of [`RANGES`] (an index past the end gives the last).
    pub fn field_mut(&mut self, index: usize) -> &mut f32 {
        match index {
            0 => &mut self.body_length,
            1 => &mut self.sleeve_length,
            2 => &mut self.ease,
            3 => &mut self.neckline_depth,
            4 => &mut self.waist_height,
            5 => &mut self.leg_length,
            6 => &mut self.flare,
            7 => &mut self.bridge,
            _ => &mut self.thigh,
        }
    }

    /// Index in [`RANGES`] of the parameter `name`; the error lists the names.
    pub fn index_of(name: &str) -> Result<usize, GarmentError> {
        RANGES
            .iter()
            .position(|(n, _, _)| *n == name)
            .ok_or_else(|| {
                GarmentError::Parameter(format!(
                    "unknown cut parameter '{name}', expected one of {}",
                    RANGES.map(|r| r.0).join(", ")
                ))
            })
    }

    /// Applies `KEY=VALUE[,KEY=VALUE...]` (names as in [`RANGES`], values in metres or the
    /// fraction `bridge` takes), then validates the whole cut.
    pub fn apply(&mut self, settings: &str) -> Result<(), GarmentError> {
        for item in settings.split(',').filter(|s| !s.trim().is_empty()) {
            let (key, value) = item
                .split_once('=')
                .ok_or_else(|| GarmentError::Parameter(format!("'{item}' is not KEY=VALUE")))?;
            let index = Self::index_of(key.trim())?;
            *self.field_mut(index) = value.trim().parse().map_err(|_| {
                GarmentError::Parameter(format!("{key} = '{value}' is not a number"))
            })?;
        }
        self.validate()
    }

    /// Checks every parameter is finite and within [`RANGES`].
    pub fn validate(&self) -> Result<(), GarmentError> {
        for ((name, v), (_, lo, hi)) in self.named().iter().zip(RANGES) {
            if !v.is_finite() || *v < lo || *v > hi {
                return Err(GarmentError::Parameter(format!(
                    "{name} = {v} m is outside [{lo}, {hi}] m"
                )));
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_kinds_parse() {
        for name in ["tshirt", "T-shirt", "sweater", "jeans"] {
            let kind = GarmentKind::parse(name).unwrap();
            CutParams::default_for(&kind).validate().unwrap();
        }
        assert!(GarmentKind::parse("hat").is_err());
        let bad = CutParams {
            ease: f32::NAN,
            ..CutParams::default_for(&GarmentKind::Tshirt)
        };
        assert!(bad.validate().unwrap_err().to_string().contains("ease"));
        let bad = CutParams {
            bridge: 1.5,
            ..CutParams::default_for(&GarmentKind::Jeans)
        };
        assert!(bad.validate().unwrap_err().to_string().contains("bridge"));
        let bad = CutParams {
            sleeve_length: 2.0,
            ..CutParams::default_for(&GarmentKind::Tshirt)
        };
        assert!(bad.validate().is_err());
    }

    #[test]
    fn settings_apply_by_name_and_bad_ones_are_refused() {
        for (i, (name, lo, hi)) in RANGES.iter().enumerate() {
            let mut cut = CutParams::default_for(&GarmentKind::Jeans);
            let v = 0.5 * (lo + hi);
            cut.apply(&format!("{name}={v}")).unwrap();
            assert_eq!(cut.named()[i], (*name, v));
        }
        let mut cut = CutParams::default_for(&GarmentKind::Tshirt);
        cut.apply("flare=0.03, bridge=0").unwrap();
        assert_eq!((cut.flare, cut.bridge), (0.03, 0.0));
        for (bad, says) in [
            ("sleeves=0.2", "unknown cut parameter 'sleeves'"),
            ("flare", "not KEY=VALUE"),
            ("flare=wide", "not a number"),
            ("flare=0.5", "flare"),
        ] {
            let err = cut.apply(bad).unwrap_err().to_string();
            assert!(err.contains(says), "{bad}: {err}");
        }
    }

    #[test]
    fn a_cut_names_every_parameter_and_the_defaults_are_the_current_cuts() {
        let json = r#"{"body_length":0.59,"sleeve_length":0.28,"ease":0.04,
            "neckline_depth":0.04,"waist_height":0.04,"leg_length":0.75}"#;
        let err = serde_json::from_str::<CutParams>(json)
            .unwrap_err()
            .to_string();
        assert!(err.contains("flare"), "{err}");
        let first = CutParams::first_for(&GarmentKind::Tshirt);
        assert_eq!((first.flare, first.bridge, first.thigh), (0.0, 1.0, 0.0));
        let tshirt = CutParams::default_for(&GarmentKind::Tshirt);
        assert_eq!((tshirt.flare, tshirt.bridge), (0.03, 0.0));
        let jeans = CutParams::default_for(&GarmentKind::Jeans);
        assert_eq!((jeans.flare, jeans.bridge), (0.0, 0.0));
        assert_eq!(
            (jeans.ease, jeans.waist_height, jeans.thigh),
            (0.04, 0.10, 0.03)
        );
    }
}
