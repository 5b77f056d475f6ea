//! Turning the spec's `[simulator]` overrides into the simulator's drape options.

use std::path::Path;

use body::Skinning;
use sim::drape::DrapeOptions;

use crate::error::{DatasetError, Result};
use crate::spec::SimulatorSpec;

/// The drape options given by the simulator settings file at `path` (see
/// [`SimulatorSpec::load`]): the defaults with its overrides, checked. Errors name the file
/// and the key at fault.
pub fn load_drape_options(path: &Path) -> Result<DrapeOptions> {
    SimulatorSpec::load(path)?
        .drape_options()
        .map_err(|(field, message)| DatasetError::spec(path, field, message))
}

/// The drape options of the settings file at `path` ([`load_drape_options`]), or the
/// simulator's defaults when there is none.
pub fn load_drape_options_or_default(path: Option<&Path>) -> Result<DrapeOptions> {
    match path {
        Some(p) => load_drape_options(p),
        None => Ok(DrapeOptions::default()),
    }
}

impl SimulatorSpec {
    /// The drape options: the simulator's defaults with this spec's overrides. Errors are
    /// `(field, message)` with the field named as in the spec.
    pub fn drape_options(&self) -> Result<DrapeOptions, (String, String)> {
        let mut o = DrapeOptions::default();
        let c = &mut o.cloth;
        let set = |dst: &mut f32, v: Option<f32>| {
            if let Some(v) = v {
                *dst = v;
            }
        };
        set(&mut c.density, self.density);
        set(&mut c.stretch_stiffness, self.stretch_stiffness);
        set(&mut c.bend_stiffness, self.bend_stiffness);
        set(&mut c.damping, self.damping);
        set(&mut c.friction, self.friction);
        set(&mut c.thickness, self.thickness);
        set(&mut c.contact_margin, self.contact_margin);
        set(&mut c.dt, self.dt);
        set(&mut c.chebyshev_rho, self.chebyshev_rho);
        c.iterations = self.iterations.unwrap_or(c.iterations);
        c.static_friction = self.static_friction.unwrap_or(c.static_friction);
        o.morph_steps = self.morph_steps.unwrap_or(o.morph_steps);
        o.pose_steps = self.pose_steps.unwrap_or(o.pose_steps);
        set(&mut o.body_step, self.body_step);
        o.max_settle_steps = self.max_settle_steps.unwrap_or(o.max_settle_steps);
        set(&mut o.rest_speed, self.rest_speed);
        set(&mut o.explode_speed, self.explode_speed);
        set(&mut o.max_penetration, self.max_penetration);
        o.grade = self.grade.unwrap_or(o.grade);
        match self.waistband {
            Some(false) => o.waistband = None,
            Some(true) => o.waistband = o.waistband.or_else(|| Some(Default::default())),
            None => {}
        }
        if let Some(s) = &self.skinning {
            o.skinning = Skinning::from_name(s).ok_or_else(|| {
                (
                    "skinning".to_string(),
                    format!("'{s}' is not a skinning method (dqs or lbs)"),
                )
            })?;
        }
        if let Some(s) = &self.start {
            o.start = sim::drape::Start::from_name(s).ok_or_else(|| {
                (
                    "start".to_string(),
                    format!("'{s}' is not a start (animate or fitted)"),
                )
            })?;
        }
        if let Err(e) = o.cloth.validate() {
            let text = e.to_string();
            // The simulator's message starts with the field name after its prefix.
            let field = text
                .trim_start_matches("invalid parameter: ")
                .split_whitespace()
                .next()
                .unwrap_or("")
                .to_string();
            return Err((field, text));
        }
        for (name, v) in [("morph_steps", o.morph_steps), ("pose_steps", o.pose_steps)] {
            if v == 0 {
                return Err((name.into(), "must be at least 1".into()));
            }
        }
        let positive = [
            ("rest_speed", o.rest_speed),
            ("explode_speed", o.explode_speed),
        ];
        for (name, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return Err((name.into(), format!("must be positive and finite, got {v}")));
            }
        }
        if !(o.body_step.is_finite() && o.body_step >= 0.0) {
            return Err((
                "body_step".into(),
                format!("must be non-negative metres, got {}", o.body_step),
            ));
        }
        if !(o.max_penetration.is_finite() && o.max_penetration >= 0.0) {
            return Err((
                "max_penetration".into(),
                format!("must be non-negative metres, got {}", o.max_penetration),
            ));
        }
        Ok(o)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overrides_apply_and_bad_values_name_the_field() {
        let s = SimulatorSpec {
            iterations: Some(4),
            max_settle_steps: Some(10),
            friction: Some(0.2),
            skinning: Some("LBS".into()),
            ..Default::default()
        };
        let o = s.drape_options().unwrap();
        assert_eq!(o.cloth.iterations, 4);
        assert_eq!(o.max_settle_steps, 10);
        assert_eq!(o.cloth.friction, 0.2);
        assert_eq!(o.skinning, Skinning::Lbs);
        assert_eq!(o.pose_steps, DrapeOptions::default().pose_steps);
        // A spec that names nothing gets the simulator's defaults.
        let plain = SimulatorSpec::default().drape_options().unwrap();
        let defaults = DrapeOptions::default();
        assert_eq!(plain.skinning, defaults.skinning);
        assert_eq!(plain.waistband, defaults.waistband);
        assert!(plain.waistband.is_some());
        let bare = SimulatorSpec {
            waistband: Some(false),
            skinning: Some("dqs".into()),
            ..Default::default()
        };
        let bare = bare.drape_options().unwrap();
        assert_eq!((bare.waistband, bare.skinning), (None, Skinning::Dqs));
        let bad = SimulatorSpec {
            density: Some(-1.0),
            ..Default::default()
        };
        assert_eq!(bad.drape_options().unwrap_err().0, "density");
        let bad = SimulatorSpec {
            body_step: Some(f32::NAN),
            ..Default::default()
        };
        assert_eq!(bad.drape_options().unwrap_err().0, "body_step");
        let full = SimulatorSpec {
            body_step: Some(0.0),
            ..Default::default()
        };
        assert_eq!(full.drape_options().unwrap().body_step, 0.0);
        let bad = SimulatorSpec {
            iterations: Some(0),
            ..Default::default()
        };
        assert_eq!(bad.drape_options().unwrap_err().0, "iterations");
        let bad = SimulatorSpec {
            rest_speed: Some(0.0),
            ..Default::default()
        };
        assert_eq!(bad.drape_options().unwrap_err().0, "rest_speed");
        let fitted = SimulatorSpec {
            start: Some("fitted".into()),
            static_friction: Some(true),
            ..Default::default()
        };
        let o = fitted.drape_options().unwrap();
        assert_eq!(o.start, sim::drape::Start::Fitted);
        assert!(o.cloth.static_friction);
        let bad = SimulatorSpec {
            start: Some("teleport".into()),
            ..Default::default()
        };
        let (field, message) = bad.drape_options().unwrap_err();
        assert_eq!(field, "start");
        assert!(message.contains("'teleport'"), "{message}");
    }
}
