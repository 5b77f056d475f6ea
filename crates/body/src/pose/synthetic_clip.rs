//! Motion files written by garnet itself, for tests and examples that must not need a
//! motion-capture database: a CMU-style ASF skeleton (the 30 bones of the CMU subjects, in
//! their layout, file units and local axes, lengths rounded from an adult's) and AMC walks
//! of it (120 frames per second, walking along +Z, arms hanging).
//!
//! File units are the CMU ones (`length 0.45`: a unit is 1/0.45 inch, 5.64 cm); angles are
//! degrees, as in the CMU files.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use super::error::PoseError;

/// One ASF bone: name, parent (`None`: the root), rest direction (world axes, not yet
/// unit), length (file units), `axis` angles (degrees, `XYZ`) and dofs.
type BoneRow = (
    &'static str,
    Option<&'static str>,
    [f64; 3],
    f64,
    [f64; 3],
    &'static str,
);

/// The bones, in CMU file order.
#[rustfmt::skip]
const BONES: [BoneRow; 30] = [
    ("lhipjoint", None, [0.66, -0.71, 0.25], 2.5, [0.0, 0.0, 0.0], ""),
    ("lfemur", Some("lhipjoint"), [0.34, -0.94, 0.0], 7.6, [0.0, 0.0, 20.0], "rx ry rz"),
    ("ltibia", Some("lfemur"), [0.34, -0.94, 0.0], 7.3, [0.0, 0.0, 20.0], "rx"),
    ("lfoot", Some("ltibia"), [0.09, -0.24, 0.97], 2.2, [-90.0, 0.0, 20.0], "rx rz"),
    ("ltoes", Some("lfoot"), [0.0, 0.0, 1.0], 1.1, [-90.0, 0.0, 20.0], "rx"),
    ("rhipjoint", None, [-0.66, -0.71, 0.25], 2.5, [0.0, 0.0, 0.0], ""),
    ("rfemur", Some("rhipjoint"), [-0.34, -0.94, 0.0], 7.6, [0.0, 0.0, -20.0], "rx ry rz"),
    ("rtibia", Some("rfemur"), [-0.34, -0.94, 0.0], 7.3, [0.0, 0.0, -20.0], "rx"),
    ("rfoot", Some("rtibia"), [-0.09, -0.24, 0.97], 2.2, [-90.0, 0.0, -20.0], "rx rz"),
    ("rtoes", Some("rfoot"), [0.0, 0.0, 1.0], 1.1, [-90.0, 0.0, -20.0], "rx"),
    ("lowerback", None, [0.01, 1.0, -0.07], 2.06, [0.0; 3], "rx ry rz"),
    ("upperback", Some("lowerback"), [0.0, 1.0, -0.03], 2.07, [0.0; 3], "rx ry rz"),
    ("thorax", Some("upperback"), [0.0, 1.0, 0.0], 2.07, [0.0; 3], "rx ry rz"),
    ("lowerneck", Some("thorax"), [0.0, 1.0, 0.1], 1.57, [0.0; 3], "rx ry rz"),
    ("upperneck", Some("lowerneck"), [0.02, 1.0, -0.06], 1.56, [0.0; 3], "rx ry rz"),
    ("head", Some("upperneck"), [0.0, 1.0, -0.03], 1.63, [0.0; 3], "rx ry rz"),
    ("lclavicle", Some("thorax"), [0.97, 0.25, -0.05], 3.66, [0.0; 3], "ry rz"),
    ("lhumerus", Some("lclavicle"), [1.0, 0.0, 0.0], 4.9, [180.0, -30.0, -90.0], "rx ry rz"),
    ("lradius", Some("lhumerus"), [1.0, 0.0, 0.0], 3.36, [180.0, -30.0, -90.0], "rx"),
    ("lwrist", Some("lradius"), [1.0, 0.0, 0.0], 1.68, [0.0, 90.0, 90.0], "ry"),
    ("lhand", Some("lwrist"), [1.0, 0.0, 0.0], 0.7, [0.0, 90.0, 90.0], "rx rz"),
    ("lfingers", Some("lhand"), [1.0, 0.0, 0.0], 0.55, [0.0, 90.0, 90.0], "rx"),
    ("lthumb", Some("lwrist"), [1.0, 0.0, 1.0], 0.8, [-90.0, 45.0, 0.0], "rx rz"),
    ("rclavicle", Some("thorax"), [-0.97, 0.25, -0.05], 3.66, [0.0; 3], "ry rz"),
    ("rhumerus", Some("rclavicle"), [-1.0, 0.0, 0.0], 4.9, [180.0, 30.0, 90.0], "rx ry rz"),
    ("rradius", Some("rhumerus"), [-1.0, 0.0, 0.0], 3.36, [180.0, 30.0, 90.0], "rx"),
    ("rwrist", Some("rradius"), [-1.0, 0.0, 0.0], 1.68, [0.0, -90.0, -90.0], "ry"),
    ("rhand", Some("rwrist"), [-1.0, 0.0, 0.0], 0.7, [0.0, -90.0, -90.0], "rx rz"),
    ("rfingers", Some("rhand"), [-1.0, 0.0, 0.0], 0.55, [0.0, -90.0, -90.0], "rx"),
    ("rthumb", Some("rwrist"), [-1.0, 0.0, 1.0], 0.8, [-90.0, -45.0, 0.0], "rx rz"),
];

/// Frames per second of the walks (as the CMU clips).
pub const WALK_FRAME_RATE: f64 = 120.0;

/// Walking speed of the walks, metres per second.
pub const WALK_SPEED: f64 = 1.2;

/// Metres per ASF unit of the skeleton (`0.0254 / 0.45`).
const METRES_PER_UNIT: f64 = 0.0254 / 0.45;

/// The text of the CMU-style ASF skeleton (see the module documentation).
pub fn cmu_asf_text() -> String {
    let mut out = String::from(
        "# CMU-style skeleton written by garnet\n:version 1.10\n:name VICON\n:units\n  \
         mass 1.0\n  length 0.45\n  angle deg\n:documentation\n   synthetic\n:root\n   \
         order TX TY TZ RX RY RZ\n   axis XYZ\n   position 0 0 0\n   orientation 0 0 0\n\
         :bonedata\n",
    );
    for (i, (name, _, dir, length, axis, dofs)) in BONES.iter().enumerate() {
        let norm = dir.iter().map(|d| d * d).sum::<f64>().sqrt();
        let d = dir.map(|x| x / norm);
        let _ = writeln!(
            out,
            "  begin\n     id {}\n     name {name}\n     direction {} {} {}\n     \
             length {length}\n     axis {} {} {} XYZ",
            i + 1,
            d[0],
            d[1],
            d[2],
            axis[0],
            axis[1],
            axis[2]
        );
        if !dofs.is_empty() {
            let _ = writeln!(out, "    dof {dofs}");
        }
        out.push_str("  end\n");
    }
    out.push_str(":hierarchy\n  begin\n");
    let children = |parent: Option<&str>| -> Vec<&str> {
        BONES
            .iter()
            .filter(|b| b.1 == parent)
            .map(|b| b.0)
            .collect()
    };
    let _ = writeln!(out, "    root {}", children(None).join(" "));
    for (name, ..) in BONES {
        let kids = children(Some(name));
        if !kids.is_empty() {
            let _ = writeln!(out, "    {name} {}", kids.join(" "));
        }
    }
    out.push_str("  end\n");
    out
}

/// The AMC values (degrees; the root's translation in file units) of one bone in frame `f`
/// of walk `variant`.
fn walk_values(name: &str, f: usize, variant: u32) -> Vec<f64> {
    let t = f as f64 / WALK_FRAME_RATE;
    // A stride (two steps) takes 1.1 s; each variant starts elsewhere in it and swings its
    // legs a little further.
    let phase = std::f64::consts::TAU * t / 1.1 + 0.7 * variant as f64;
    let swing = 18.0 + 2.0 * (variant % 4) as f64;
    let (s, c) = phase.sin_cos();
    let knee = |x: f64| 5.0 + 30.0 * x.max(0.0);
    match name {
        "root" => vec![
            0.0,
            16.7 + 0.2 * (2.0 * phase).cos(),
            WALK_SPEED * t / METRES_PER_UNIT,
            0.0,
            0.0,
            0.0,
        ],
        "lfemur" => vec![-swing * s, 0.0, 0.0],
        "rfemur" => vec![swing * s, 0.0, 0.0],
        "ltibia" => vec![knee(c)],
        "rtibia" => vec![knee(-c)],
        "lfoot" | "rfoot" => vec![-5.0, 0.0],
        "lowerback" => vec![4.0, 2.0 * s, 0.0],
        "upperback" => vec![2.0, 0.0, 0.0],
        // The arms hang at the sides, swinging against the legs.
        "lhumerus" => vec![-25.0 - 8.0 * s, -15.0, 82.0],
        "rhumerus" => vec![-25.0 + 8.0 * s, 15.0, -82.0],
        "lradius" | "rradius" => vec![10.0],
        _ => {
            let dofs = BONES.iter().find(|b| b.0 == name).map_or("", |b| b.5);
            vec![0.0; dofs.split_whitespace().count()]
        }
    }
}

/// The text of an AMC walk of [`cmu_asf_text`]'s skeleton: `frames` frames, numbered
/// from one, at [`WALK_FRAME_RATE`], walking along +Z at [`WALK_SPEED`]; `variant` shifts
/// where in the stride it starts and how far the legs swing, so that clips of several
/// variants differ.
pub fn walk_amc_text(frames: usize, variant: u32) -> String {
    let mut out = String::from("#!OML:ASF synthetic.asf\n:FULLY-SPECIFIED\n:DEGREES\n");
    for f in 0..frames {
        let _ = writeln!(out, "{}", f + 1);
        let names = std::iter::once("root").chain(BONES.iter().map(|b| b.0));
        for name in names {
            let values = walk_values(name, f, variant);
            if name != "root" && values.is_empty() {
                continue;
            }
            out.push_str(name);
            for v in values {
                let _ = write!(out, " {v:.6}");
            }
            out.push('\n');
        }
    }
    out
}

/// Writes a walk of `frames` frames at `root/clip` (a CMU-style path such as
/// `cmu/02/02_01.amc`) and the skeleton beside it as the CMU subjects' `SUBJECT.asf`
/// (`cmu/02/02.asf`, the name dataset specs expect by default). The walk's variant follows
/// the clip's trial number (`02_07` -> 7). Returns the AMC's path.
pub fn write_cmu_clip(root: &Path, clip: &str, frames: usize) -> Result<PathBuf, PoseError> {
    let amc = root.join(clip);
    let stem = amc.file_stem().and_then(|s| s.to_str()).unwrap_or_default();
    let (subject, trial) = stem.split_once('_').unwrap_or((stem, "0"));
    let dir = amc.parent().unwrap_or(root);
    let io = |path: &Path, e| PoseError::Io {
        path: path.to_path_buf(),
        source: e,
    };
    std::fs::create_dir_all(dir).map_err(|e| io(dir, e))?;
    let asf = dir.join(format!("{subject}.asf"));
    std::fs::write(&asf, cmu_asf_text()).map_err(|e| io(&asf, e))?;
    let variant = trial.parse().unwrap_or(0);
    std::fs::write(&amc, walk_amc_text(frames, variant)).map_err(|e| io(&amc, e))?;
    Ok(amc)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pose::{Amc, Asf};

    #[test]
    fn the_skeleton_and_walk_parse() {
        let asf = Asf::parse(&cmu_asf_text(), Path::new("s.asf")).unwrap();
        assert_eq!(asf.bones.len(), 30);
        let femur = &asf.bones[asf.bone_index("lfemur").unwrap()];
        assert!((femur.length * asf.metres_per_unit() - 0.429).abs() < 1e-3);
        assert!((femur.direction.length() - 1.0).abs() < 1e-9);
        let amc = Amc::parse(&walk_amc_text(12, 3), Path::new("w.amc"), &asf).unwrap();
        assert_eq!(amc.frame_count(), 12);
        assert_eq!(amc.frame_numbers[11], 12);
        assert_ne!(walk_amc_text(2, 1), walk_amc_text(2, 2));
    }

    #[test]
    fn clips_are_written_beside_their_skeleton() {
        let dir = tempfile::tempdir().unwrap();
        let amc = write_cmu_clip(dir.path(), "cmu/02/02_07.amc", 5).unwrap();
        let asf = Asf::read(dir.path().join("cmu/02/02.asf")).unwrap();
        assert_eq!(Amc::read(&amc, &asf).unwrap().frame_count(), 5);
    }
}
