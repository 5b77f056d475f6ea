//! Phenotype parameters and the blending weights of the MakeHuman macro targets.
//!
//! Every macro target file is named by the labels it stands for (for instance
//! `universal-female-young-averagemuscle-maxweight`); its coefficient is the product of
//! the weights of those labels. Each continuous parameter is interpolated piecewise
//! linearly between anchors: gender (male 0, female 1), age (baby 0, child 1/3,
//! young 2/3, old 1), muscle and weight (min 0, average 0.5, max 1), height (min 0,
//! max 1), proportions (ideal 0, uncommon 1), breast cup size and firmness (min 0,
//! average 0.5, max 1); race shares are normalised to sum to one.

use serde::{Deserialize, Serialize};

use crate::BodyError;

/// Shape parameters of a body, each in [0, 1] (race shares: any non-negative values,
/// normalised). The default (all 0.5, equal race shares) stands 1.626 m tall.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Phenotype {
    /// 0 male, 1 female.
    pub gender: f32,
    /// 0 baby, 1/3 child, 2/3 young adult (25 years), 1 old (90 years).
    pub age: f32,
    pub muscle: f32,
    pub weight: f32,
    pub height: f32,
    /// 0 ideal, 1 uncommon proportions.
    pub proportions: f32,
    pub cupsize: f32,
    pub firmness: f32,
    pub african: f32,
    pub asian: f32,
    pub caucasian: f32,
}

impl Default for Phenotype {
    fn default() -> Self {
        Self {
            gender: 0.5,
            age: 0.5,
            muscle: 0.5,
            weight: 0.5,
            height: 0.5,
            proportions: 0.5,
            cupsize: 0.5,
            firmness: 0.5,
            african: 1.0 / 3.0,
            asian: 1.0 / 3.0,
            caucasian: 1.0 / 3.0,
        }
    }
}

/// The labels of one phenotype axis, in anchor order, with their anchor values.
pub struct Axis {
    pub labels: &'static [&'static str],
    pub anchors: &'static [f32],
}

pub const GENDER: Axis = Axis {
    labels: &["male", "female"],
    anchors: &[0.0, 1.0],
};
pub const AGE: Axis = Axis {
    labels: &["baby", "child", "young", "old"],
    anchors: &[0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0],
};
pub const MUSCLE: Axis = Axis {
    labels: &["minmuscle", "averagemuscle", "maxmuscle"],
    anchors: &[0.0, 0.5, 1.0],
};
pub const WEIGHT: Axis = Axis {
    labels: &["minweight", "averageweight", "maxweight"],
    anchors: &[0.0, 0.5, 1.0],
};
pub const HEIGHT: Axis = Axis {
    labels: &["minheight", "maxheight"],
    anchors: &[0.0, 1.0],
};
pub const PROPORTIONS: Axis = Axis {
    labels: &["idealproportions", "uncommonproportions"],
    anchors: &[0.0, 1.0],
};
pub const CUPSIZE: Axis = Axis {
    labels: &["mincup", "averagecup", "maxcup"],
    anchors: &[0.0, 0.5, 1.0],
};
pub const FIRMNESS: Axis = Axis {
    labels: &["minfirmness", "averagefirmness", "maxfirmness"],
    anchors: &[0.0, 0.5, 1.0],
};
pub const RACES: [&str; 3] = ["african", "asian", "caucasian"];

/// Piecewise-linear interpolation weights of `value` over `anchors` (clamped to the
/// anchors' range): at most two neighbouring entries are non-zero and they sum to 1.
pub fn interpolation_weights(value: f32, anchors: &[f32]) -> Vec<f32> {
    let mut w = vec![0.0; anchors.len()];
    let v = value.clamp(anchors[0], anchors[anchors.len() - 1]);
    let seg = anchors
        .windows(2)
        .position(|p| v <= p[1])
        .unwrap_or(anchors.len() - 2);
    let t = (v - anchors[seg]) / (anchors[seg + 1] - anchors[seg]);
    w[seg] = 1.0 - t;
    w[seg + 1] = t;
    w
}

impl Phenotype {
    /// Checks that every parameter is finite and in [0, 1] and that the race shares do
    /// not all vanish.
    pub fn validate(&self) -> Result<(), BodyError> {
        for (name, v) in self.named_values() {
            if !v.is_finite() || !(0.0..=1.0).contains(&v) {
                return Err(BodyError::Parameter(format!(
                    "phenotype {name} = {v} is outside [0, 1]"
                )));
            }
        }
        if self.african + self.asian + self.caucasian <= 0.0 {
            return Err(BodyError::Parameter(
                "phenotype race shares must not all be zero".into(),
            ));
        }
        Ok(())
    }

    /// The phenotype of `values`, in [`Phenotype::named_values`] order (11 values);
    /// errors if there are not 11 or they fail [`Phenotype::validate`].
    pub fn from_values(values: &[f32]) -> Result<Self, BodyError> {
        let v: [f32; 11] = values.try_into().map_err(|_| {
            BodyError::Parameter(format!("a phenotype has 11 values, got {}", values.len()))
        })?;
        let p = Self {
            gender: v[0],
            age: v[1],
            muscle: v[2],
            weight: v[3],
            height: v[4],
            proportions: v[5],
            cupsize: v[6],
            firmness: v[7],
            african: v[8],
            asian: v[9],
            caucasian: v[10],
        };
        p.validate()?;
        Ok(p)
    }

    /// `(name, value)` of every parameter.
    pub fn named_values(&self) -> [(&'static str, f32); 11] {
        [
            ("gender", self.gender),
            ("age", self.age),
            ("muscle", self.muscle),
            ("weight", self.weight),
            ("height", self.height),
            ("proportions", self.proportions),
            ("cupsize", self.cupsize),
            ("firmness", self.firmness),
            ("african", self.african),
            ("asian", self.asian),
            ("caucasian", self.caucasian),
        ]
    }

    /// The weight of every label (`"female"`, `"young"`, `"maxweight"`, `"asian"`, ...)
    /// for this phenotype, as `(label, weight)` pairs.
    pub fn label_weights(&self) -> Vec<(&'static str, f32)> {
        let mut out = Vec::new();
        for (axis, value) in [
            (&GENDER, self.gender),
            (&AGE, self.age),
            (&MUSCLE, self.muscle),
            (&WEIGHT, self.weight),
            (&HEIGHT, self.height),
            (&PROPORTIONS, self.proportions),
            (&CUPSIZE, self.cupsize),
            (&FIRMNESS, self.firmness),
        ] {
            let w = interpolation_weights(value, axis.anchors);
            out.extend(axis.labels.iter().copied().zip(w));
        }
        let total = self.african + self.asian + self.caucasian;
        for (label, v) in RACES.iter().zip([self.african, self.asian, self.caucasian]) {
            out.push((label, if total > 0.0 { v / total } else { 1.0 / 3.0 }));
        }
        out
    }

    /// Coefficient of a target named by dash-separated labels (for instance
    /// `female-young-averagemuscle-averageweight-maxheight`); `universal` counts as 1.
    /// Returns `None` if a label is unknown.
    pub fn target_coefficient(&self, name: &str) -> Option<f32> {
        let weights = self.label_weights();
        name.split('-')
            .filter(|l| *l != "universal")
            .map(|label| weights.iter().find(|(l, _)| *l == label).map(|(_, w)| *w))
            .product()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolation_is_piecewise_linear_and_partitions_unity() {
        let mid = interpolation_weights(0.5, AGE.anchors);
        assert!(
            (mid[1] - 0.5).abs() < 1e-6 && (mid[2] - 0.5).abs() < 1e-6,
            "{mid:?}"
        );
        assert_eq!(
            interpolation_weights(0.0, MUSCLE.anchors),
            vec![1.0, 0.0, 0.0]
        );
        assert_eq!(
            interpolation_weights(2.0, MUSCLE.anchors),
            vec![0.0, 0.0, 1.0]
        );
        let w = interpolation_weights(0.75, WEIGHT.anchors);
        assert!((w[1] - 0.5).abs() < 1e-6 && (w[2] - 0.5).abs() < 1e-6);
        for v in [0.0, 0.1, 0.33, 0.5, 0.9, 1.0] {
            let s: f32 = interpolation_weights(v, AGE.anchors).iter().sum();
            assert!((s - 1.0).abs() < 1e-6);
        }
    }

    #[test]
    fn from_values_inverts_named_values() {
        let p = Phenotype {
            gender: 0.9,
            weight: 0.2,
            asian: 0.7,
            ..Default::default()
        };
        let values: Vec<f32> = p.named_values().map(|(_, v)| v).to_vec();
        assert_eq!(Phenotype::from_values(&values).unwrap(), p);
        let e = Phenotype::from_values(&values[..10]).unwrap_err();
        assert!(e.to_string().contains("11 values, got 10"), "{e}");
        let mut bad = values.clone();
        bad[3] = f32::NAN;
        assert!(Phenotype::from_values(&bad).is_err());
    }

    #[test]
    fn target_coefficients_are_label_products() {
        let p = Phenotype {
            gender: 1.0,
            age: 2.0 / 3.0,
            weight: 0.75,
            ..Default::default()
        };
        let c = p
            .target_coefficient("universal-female-young-averagemuscle-maxweight")
            .unwrap();
        assert!((c - 0.5).abs() < 1e-5);
        assert_eq!(
            p.target_coefficient("male-young-averagemuscle-averageweight-maxheight"),
            Some(0.0)
        );
        let r = Phenotype::default()
            .target_coefficient("asian-female-young")
            .unwrap();
        assert!((r - 1.0 / 3.0 * 0.5 * 0.5).abs() < 1e-6);
        assert_eq!(p.target_coefficient("female-teen"), None);
    }

    #[test]
    fn validation_rejects_nan_and_out_of_range() {
        assert!(Phenotype::default().validate().is_ok());
        let bad = Phenotype {
            height: f32::NAN,
            ..Default::default()
        };
        assert!(bad.validate().unwrap_err().to_string().contains("height"));
        let bad = Phenotype {
            weight: 1.5,
            ..Default::default()
        };
        assert!(bad.validate().is_err());
    }
}
