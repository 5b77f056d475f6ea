//! A dataset garment resolved from its spec: kind, template edge, and its cut, fixed or
//! drawn per body.

use garment::cut::RANGES;
use garment::{CutParams, GarmentKind};

use crate::rng::{derive, SplitMix64, Stream};
use crate::spec::GarmentSpec;

/// One garment of the plan.
#[derive(Clone, Debug, PartialEq)]
pub struct GarmentPlan {
    /// Its name in the dataset (unique).
    pub name: String,
    /// The garment kind.
    pub kind: GarmentKind,
    /// Template edge length, metres.
    pub edge: f32,
    /// Samples per body.
    pub poses_per_body: u32,
    /// The cut: the kind's default cut ([`CutParams::default_for`], as `garnet garment
    /// make` cuts it) with the spec's fixed values (metres).
    pub base: CutParams,
    /// Parameters drawn per body: `(index in RANGES, min, max)`, metres.
    pub ranges: Vec<(usize, f32, f32)>,
}

impl GarmentPlan {
    /// Resolves `spec`; errors are `(field within the garment, message)`.
    pub fn from_spec(spec: &GarmentSpec) -> Result<Self, (String, String)> {
        let kind = GarmentKind::parse(&spec.kind).map_err(|e| ("kind".into(), e.to_string()))?;
        let name = spec.name.clone().unwrap_or_else(|| kind.name().to_string());
        let mut base = CutParams::default_for(&kind);
        for (key, &v) in &spec.cut {
            let i = CutParams::index_of(key).map_err(|e| (format!("cut.{key}"), e.to_string()))?;
            *base.field_mut(i) = v;
        }
        base.validate()
            .map_err(|e| ("cut".to_string(), e.to_string()))?;
        let mut ranges = Vec::new();
        for (key, &[lo, hi]) in &spec.cut_ranges {
            let field = format!("cut_ranges.{key}");
            let i = CutParams::index_of(key).map_err(|e| (field.clone(), e.to_string()))?;
            if spec.cut.contains_key(key) {
                return Err((field, "is also fixed in `cut`".into()));
            }
            let (_, min, max) = RANGES[i];
            if !(lo.is_finite() && hi.is_finite() && lo <= hi && lo >= min && hi <= max) {
                return Err((
                    field,
                    format!("[{lo}, {hi}] must be an interval within [{min}, {max}] metres"),
                ));
            }
            ranges.push((i, lo, hi));
        }
        Ok(Self {
            name,
            kind,
            edge: spec.edge,
            poses_per_body: spec.poses_per_body,
            base,
            ranges,
        })
    }

    /// Whether each body gets its own cut (and template).
    pub fn per_body(&self) -> bool {
        !self.ranges.is_empty()
    }

    /// The cut body `body` wears: the base cut, with the ranged parameters drawn from
    /// the dataset `seed`, this garment's index `garment` and `body`.
    pub fn cut_for(&self, seed: u64, garment: usize, body: u32) -> CutParams {
        let mut cut = self.base;
        let mut rng = SplitMix64::new(derive(seed, Stream::Cut, &[garment as u64, body as u64]));
        for &(i, lo, hi) in &self.ranges {
            *cut.field_mut(i) = lo + (hi - lo) * rng.unit() as f32;
        }
        cut
    }

    /// The id of the template body `body` wears: the garment's name, with the body
    /// (`tshirt-b00012`) when cuts are drawn per body.
    pub fn template_id(&self, body: u32) -> String {
        if self.per_body() {
            format!("{}-b{body:05}", self.name)
        } else {
            self.name.clone()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    fn spec() -> GarmentSpec {
        GarmentSpec {
            kind: "sweater".into(),
            name: None,
            edge: 0.03,
            poses_per_body: 2,
            cut: BTreeMap::from([("sleeve_length".to_string(), 0.3)]),
            cut_ranges: BTreeMap::from([("ease".to_string(), [0.02, 0.05])]),
        }
    }

    #[test]
    fn cuts_are_fixed_or_drawn_per_body() {
        let g = GarmentPlan::from_spec(&spec()).unwrap();
        assert_eq!(g.name, "sweater");
        assert_eq!(g.base.sleeve_length, 0.3);
        let a = g.cut_for(1, 0, 3);
        assert_eq!(a, g.cut_for(1, 0, 3));
        assert_ne!(a.ease, g.cut_for(1, 0, 4).ease);
        assert!((0.02..=0.05).contains(&a.ease) && a.sleeve_length == 0.3);
        assert_eq!(g.template_id(3), "sweater-b00003");
        let mut fixed = spec();
        fixed.cut_ranges.clear();
        let f = GarmentPlan::from_spec(&fixed).unwrap();
        assert_eq!(f.cut_for(1, 0, 3), f.base);
        assert_eq!(f.template_id(3), "sweater");
    }

    #[test]
    fn bad_cuts_name_the_field() {
        let mut s = spec();
        s.cut.insert("sleeves".into(), 0.2);
        assert_eq!(GarmentPlan::from_spec(&s).unwrap_err().0, "cut.sleeves");
        let mut s = spec();
        s.cut_ranges.insert("leg_length".into(), [0.1, 0.5]);
        assert_eq!(
            GarmentPlan::from_spec(&s).unwrap_err().0,
            "cut_ranges.leg_length"
        );
        let mut s = spec();
        s.cut.insert("ease".into(), 0.03);
        assert_eq!(GarmentPlan::from_spec(&s).unwrap_err().0, "cut_ranges.ease");
        let mut s = spec();
        s.kind = "hat".into();
        assert_eq!(GarmentPlan::from_spec(&s).unwrap_err().0, "kind");
    }
}
