//! Validation of a parsed spec: every error names the file and the field.
//!
//! Checks that need the clips (their frame counts, so the pose pools) are made when the
//! plan is built ([`crate::plan::Plan::new`]).

use std::collections::BTreeSet;
use std::path::Path;

use body::pose::PoseKind;
use body::shape_sampler::ShapeDistribution;

use crate::cuts::GarmentPlan;
use crate::error::{DatasetError, Result};
use crate::spec::{ClipSource, Spec, SplitSize};

/// Most samples per shard.
pub const MAX_SHARD_SIZE: u32 = 4096;

/// Whether `name` is a usable dataset name (garments, splits): `[a-z0-9_-]+`.
pub fn valid_name(name: &str) -> bool {
    !name.is_empty()
        && name
            .bytes()
            .all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'_' || b == b'-')
}

/// Parses a procedural pose kind name.
pub fn parse_kind(name: &str) -> Option<PoseKind> {
    match name.to_ascii_lowercase().as_str() {
        "walk" => Some(PoseKind::Walk),
        "yoga" => Some(PoseKind::Yoga),
        "dance" => Some(PoseKind::Dance),
        "any" => Some(PoseKind::Any),
        _ => None,
    }
}

/// Checks every field of `spec` (read from `file`).
pub fn validate(spec: &Spec, file: &Path) -> Result<()> {
    let err = |field: &str, msg: String| Err(DatasetError::spec(file, field, msg));
    if !(1..=MAX_SHARD_SIZE).contains(&spec.shard_size) {
        return err("shard_size", format!("must be in 1..={MAX_SHARD_SIZE}"));
    }
    if spec.bodies.count == 0 {
        return err("bodies.count", "must be at least 1".into());
    }
    if let Err((field, msg)) = check_distribution(&spec.bodies.distribution) {
        return err(&format!("bodies.distribution.{field}"), msg);
    }
    if spec.garments.is_empty() {
        return err(
            "garments",
            "name at least one garment ([[garments]])".into(),
        );
    }
    let mut names = BTreeSet::new();
    for (i, g) in spec.garments.iter().enumerate() {
        let plan = GarmentPlan::from_spec(g).map_err(|(field, msg)| {
            DatasetError::spec(file, format!("garments[{i}].{field}"), msg)
        })?;
        if !valid_name(&plan.name) {
            return err(
                &format!("garments[{i}].name"),
                format!("'{}' must be lower-case letters, digits, - or _", plan.name),
            );
        }
        if !names.insert(plan.name.clone()) {
            return err(
                &format!("garments[{i}].name"),
                format!(
                    "'{}' is used twice (give each garment a distinct name)",
                    plan.name
                ),
            );
        }
        let (lo, hi) = garment::build::EDGE_RANGE;
        if !(lo..=hi).contains(&g.edge) {
            return err(
                &format!("garments[{i}].edge"),
                format!("{} m is outside [{lo}, {hi}] m", g.edge),
            );
        }
        if g.poses_per_body == 0 {
            return err(
                &format!("garments[{i}].poses_per_body"),
                "must be at least 1".into(),
            );
        }
    }
    check_poses(spec, file)?;
    check_splits(spec, file)?;
    if let Err((field, msg)) = spec.simulator.drape_options() {
        return err(&format!("simulator.{field}"), msg);
    }
    Ok(())
}

/// Rejects distributions the shape sampler would loop forever on or fail with.
fn check_distribution(d: &ShapeDistribution) -> Result<(), (String, String)> {
    let bad = |f: &str, m: &str| Err((f.to_string(), m.to_string()));
    if !(0.0..=1.0).contains(&d.female_share) {
        return bad("female_share", "must be in [0, 1]");
    }
    for (name, (mean, sd)) in [
        ("male_stature", d.male_stature),
        ("female_stature", d.female_stature),
    ] {
        if !((1.0..=2.3).contains(&mean) && sd > 0.0 && sd < 0.5) {
            return bad(
                name,
                "must be [mean, sd] in metres, mean in [1.0, 2.3], sd in (0, 0.5)",
            );
        }
    }
    let (median, log_sd) = d.bmi;
    if !(median > 0.0 && median.is_finite() && log_sd > 0.0 && log_sd < 1.0) {
        return bad(
            "bmi",
            "must be [median, log sd], median > 0, log sd in (0, 1)",
        );
    }
    let (lo, hi) = d.bmi_range;
    if !(lo < median && median < hi) {
        return bad("bmi_range", "must be [min, max] around the bmi median");
    }
    let (a, b) = d.age_range;
    if !(0.0 <= a && a <= b && b <= 1.0) {
        return bad("age_range", "must be [min, max] within [0, 1]");
    }
    if !(d.muscle_sd.is_finite() && d.muscle_sd >= 0.0) {
        return bad("muscle_sd", "must be non-negative");
    }
    if !(d.max_sigma.is_finite() && d.max_sigma >= 0.5) {
        return bad("max_sigma", "must be at least 0.5");
    }
    Ok(())
}

fn check_poses(spec: &Spec, file: &Path) -> Result<()> {
    let err = |field: String, msg: &str| Err(DatasetError::spec(file, field, msg));
    let p = &spec.poses;
    if p.amc.is_empty() && p.bvh.is_empty() && p.procedural.is_empty() {
        return err(
            "poses".into(),
            "name at least one pose source ([[poses.amc]], [[poses.bvh]] or [[poses.procedural]])",
        );
    }
    let clips = p.amc.iter().map(|c| ("amc", c));
    for (i, (what, c)) in clips.chain(p.bvh.iter().map(|c| ("bvh", c))).enumerate() {
        let index = if what == "amc" { i } else { i - p.amc.len() };
        check_clip_source(c, what)
            .or_else(|(f, m)| err(format!("poses.{what}[{index}].{f}"), &m))?;
    }
    for (i, s) in p.procedural.iter().enumerate() {
        if parse_kind(&s.kind).is_none() {
            return err(
                format!("poses.procedural[{i}].kind"),
                "must be walk, yoga, dance or any",
            );
        }
        if s.count == 0 {
            return err(format!("poses.procedural[{i}].count"), "must be at least 1");
        }
    }
    Ok(())
}

fn check_clip_source(c: &ClipSource, what: &str) -> Result<(), (String, String)> {
    let bad = |f: &str, m: &str| Err((f.to_string(), m.to_string()));
    if c.clips.is_empty() {
        return bad("clips", "name at least one clip");
    }
    for (j, clip) in c.clips.iter().enumerate() {
        let ext = Path::new(clip).extension().and_then(|e| e.to_str());
        if ext.map(str::to_ascii_lowercase).as_deref() != Some(what) {
            return bad(
                &format!("clips[{j}]"),
                &format!("'{clip}' is not a .{what} file"),
            );
        }
    }
    match (c.every, c.random) {
        (Some(0), _) => return bad("every", "must be at least 1"),
        (_, Some(0)) => return bad("random", "must be at least 1"),
        (Some(_), Some(_)) => return bad("every", "give either `every` or `random`, not both"),
        (None, None) => {
            return bad(
                "every",
                "give `every = K` (every K-th frame) or `random = N`",
            )
        }
        _ => {}
    }
    if c.end.is_some_and(|e| e <= c.start) {
        return bad("end", "must be after `start`");
    }
    if what == "bvh" && c.asf.is_some() {
        return bad("asf", "only AMC clips have an ASF skeleton");
    }
    if what == "amc" && c.bvh_unit.is_some() {
        return bad("bvh_unit", "only BVH clips have a unit");
    }
    if c.bvh_unit.is_some_and(|u| !(u.is_finite() && u > 0.0)) {
        return bad("bvh_unit", "must be positive metres per unit");
    }
    Ok(())
}

fn check_splits(spec: &Spec, file: &Path) -> Result<()> {
    let err = |field: String, msg: String| Err(DatasetError::spec(file, field, msg));
    let s = &spec.splits;
    if s.bodies.is_empty() {
        return err("splits.bodies".into(), "name at least one split".into());
    }
    for name in s.bodies.keys() {
        if !valid_name(name) {
            return err(
                format!("splits.bodies.{name}"),
                "split names must be lower-case letters, digits, - or _".into(),
            );
        }
    }
    let kinds: BTreeSet<bool> = s
        .bodies
        .values()
        .map(|v| matches!(v, SplitSize::Count(_)))
        .collect();
    if kinds.len() > 1 {
        return err(
            "splits.bodies".into(),
            "give all splits as counts (integers) or all as fractions (floats)".into(),
        );
    }
    let counts = crate::plan::split_counts(&s.bodies, spec.bodies.count)
        .map_err(|m| DatasetError::spec(file, "splits.bodies", m))?;
    if let Some((name, _)) = s.bodies.keys().zip(&counts).find(|(_, &c)| c == 0) {
        return err(
            format!("splits.bodies.{name}"),
            format!("gets no body of {}", spec.bodies.count),
        );
    }
    if let Some(u) = &s.unseen_poses {
        if !(u.seen_fraction > 0.0 && u.seen_fraction < 1.0) {
            return err(
                "splits.unseen_poses.seen_fraction".into(),
                format!("{} must be in (0, 1)", u.seen_fraction),
            );
        }
        if u.held_out.is_empty() || u.held_out.len() >= s.bodies.len() {
            return err(
                "splits.unseen_poses.held_out".into(),
                "name at least one split, and leave at least one out".into(),
            );
        }
        for name in &u.held_out {
            if !s.bodies.contains_key(name) {
                return err(
                    "splits.unseen_poses.held_out".into(),
                    format!("'{name}' is not a split of splits.bodies"),
                );
            }
        }
    }
    Ok(())
}
