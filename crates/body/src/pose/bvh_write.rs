//! Writing an ASF/AMC clip as a BVH file with the joint structure of the CMU BVH
//! conversions: one JOINT per ASF bone named as the rig names it, the OFFSET of a joint
//! being its parent bone's vector, an End Site on every leaf carrying the leaf's vector,
//! `Zrotation Yrotation Xrotation` channels on every joint and three position channels on
//! the root.

use std::fmt::Write as _;
use std::path::Path;

use glam::{DQuat, DVec3};

use super::amc::Amc;
use super::asf::Asf;
use super::cmu::rig_name_for_asf;
use super::error::PoseError;
use super::euler::to_zyx;

/// Options of [`bvh_string`] and [`save_bvh`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BvhWriteOptions {
    /// Seconds per frame (CMU: 1/120).
    pub frame_time: f64,
    /// Length unit of the written OFFSETs and positions in metres; `None` keeps the ASF's
    /// unit, as the CMU conversions do.
    pub metres_per_unit: Option<f64>,
}

impl Default for BvhWriteOptions {
    fn default() -> Self {
        Self {
            frame_time: 1.0 / 120.0,
            metres_per_unit: None,
        }
    }
}

fn v3(out: &mut String, v: DVec3) {
    let _ = write!(out, "{:.6} {:.6} {:.6}", v.x, v.y, v.z);
}

/// The BVH text of every frame of `amc` on `asf`.
pub fn bvh_string(asf: &Asf, amc: &Amc, opts: &BvhWriteOptions) -> Result<String, PoseError> {
    let unit = opts
        .metres_per_unit
        .unwrap_or_else(|| asf.metres_per_unit());
    if !(unit.is_finite() && unit > 0.0 && opts.frame_time.is_finite() && opts.frame_time > 0.0) {
        return Err(PoseError::Invalid(format!(
            "BVH unit {unit} m and frame time {} s must be positive",
            opts.frame_time
        )));
    }
    let scale = asf.metres_per_unit() / unit;
    let mut out = String::new();
    out.push_str("HIERARCHY\nROOT Hips\n{\n\tOFFSET ");
    v3(&mut out, asf.root.position * scale);
    out.push_str("\n\tCHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation\n");
    // Joints in depth-first order: the order their channels appear in a frame row.
    let mut dfs: Vec<usize> = Vec::with_capacity(asf.bones.len());
    let children =
        |p: Option<usize>| (0..asf.bones.len()).filter(move |&i| asf.bones[i].parent == p);
    fn write_joint(
        asf: &Asf,
        i: usize,
        depth: usize,
        scale: f64,
        out: &mut String,
        dfs: &mut Vec<usize>,
    ) {
        let bone = &asf.bones[i];
        let tabs = "\t".repeat(depth);
        let name = rig_name_for_asf(&bone.name).unwrap_or(&bone.name);
        let offset = bone.parent.map_or(DVec3::ZERO, |p| {
            let pb = &asf.bones[p];
            pb.direction * pb.length * scale
        });
        let _ = write!(out, "{tabs}JOINT {name}\n{tabs}{{\n{tabs}\tOFFSET ");
        v3(out, offset);
        let _ = writeln!(out, "\n{tabs}\tCHANNELS 3 Zrotation Yrotation Xrotation");
        dfs.push(i);
        let kids: Vec<usize> = (0..asf.bones.len())
            .filter(|&c| asf.bones[c].parent == Some(i))
            .collect();
        if kids.is_empty() {
            let _ = write!(out, "{tabs}\tEnd Site\n{tabs}\t{{\n{tabs}\t\tOFFSET ");
            v3(out, bone.direction * bone.length * scale);
            let _ = writeln!(out, "\n{tabs}\t}}");
        }
        for c in kids {
            write_joint(asf, c, depth + 1, scale, out, dfs);
        }
        let _ = writeln!(out, "{tabs}}}");
    }
    for c in children(None) {
        write_joint(asf, c, 1, scale, &mut out, &mut dfs);
    }
    let _ = write!(
        out,
        "}}\nMOTION\nFrames: {}\nFrame Time: {:.8}\n",
        amc.frame_count(),
        opts.frame_time
    );
    let deg = |q: DQuat, out: &mut String| {
        let (z, y, x) = to_zyx(q);
        let _ = write!(
            out,
            " {:.6} {:.6} {:.6}",
            z.to_degrees(),
            y.to_degrees(),
            x.to_degrees()
        );
    };
    for f in 0..amc.frame_count() {
        let pose = asf.pose_of(amc, f)?;
        v3(&mut out, (pose.root_position - asf.root.position) * scale);
        deg(pose.root_rotation, &mut out);
        for &i in &dfs {
            let parent = asf.bones[i]
                .parent
                .map_or(pose.root_rotation, |p| pose.world[p]);
            deg(parent.inverse() * pose.world[i], &mut out);
        }
        out.push('\n');
    }
    Ok(out)
}

/// Writes [`bvh_string`] to `path` (through a temporary file renamed into place).
pub fn save_bvh(
    path: impl AsRef<Path>,
    asf: &Asf,
    amc: &Amc,
    opts: &BvhWriteOptions,
) -> Result<(), PoseError> {
    let path = path.as_ref();
    let text = bvh_string(asf, amc, opts)?;
    let io = |source| PoseError::Io {
        path: path.to_path_buf(),
        source,
    };
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".tmp");
    std::fs::write(&tmp, text).map_err(io)?;
    std::fs::rename(&tmp, path).map_err(io)
}
