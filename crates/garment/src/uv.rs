//! Texture coordinates of a garment: one cylindrical chart per body part (torso, each
//! sleeve or leg), laid side by side in the unit square at a common scale (metres of
//! cloth per UV unit are the same everywhere, so a texture is not stretched between
//! charts). Coordinates are per face corner, so chart seams are cut cleanly.

use body::self_contact::segment_of_bone;
use body::{Rig, SkinWeights};
use geom::TriMesh;
use glam::{Vec2, Vec3};

/// Per-face-corner UVs `[F]` in [0, 1]^2 for `mesh` skinned with `weights` to `rig`.
pub fn corner_uvs(mesh: &TriMesh, weights: &SkinWeights, rig: &Rig) -> Vec<[[f32; 2]; 3]> {
    let bone_chart: Vec<usize> = rig
        .bones
        .iter()
        .map(|b| chart_of_segment(segment_of_bone(&b.name)))
        .collect();
    let vertex_chart: Vec<usize> = (0..mesh.vertices.len())
        .map(|v| bone_chart[weights.heaviest(v)])
        .collect();
    let axes = chart_axes(rig);
    // (arc length around the axis, distance along it), metres, per corner.
    let mut raw: Vec<(usize, [Vec2; 3])> = mesh
        .faces
        .iter()
        .map(|f| {
            let c = f.map(|v| vertex_chart[v as usize]);
            let chart = if c[1] == c[2] { c[1] } else { c[0] };
            let axis = &axes[chart];
            let polar = f.map(|v| axis.polar(mesh.vertices[v as usize]));
            let mut corners = [Vec2::ZERO; 3];
            for k in 0..3 {
                let mut angle = polar[k].0;
                // Unwrap around the first corner so a face never spans the seam.
                while angle - polar[0].0 > std::f32::consts::PI {
                    angle -= std::f32::consts::TAU;
                }
                while polar[0].0 - angle > std::f32::consts::PI {
                    angle += std::f32::consts::TAU;
                }
                corners[k] = Vec2::new(angle * axis.radius, polar[k].1);
            }
            (chart, corners)
        })
        .collect();
    pack(&mut raw)
}

/// Charts: 0 torso, 1 left arm, 2 right arm, 3 left leg, 4 right leg.
fn chart_of_segment(segment: u8) -> usize {
    match segment {
        1 | 2 => 1,
        3 | 4 => 2,
        5 | 6 => 3,
        7 | 8 => 4,
        _ => 0,
    }
}

/// A cylinder axis: origin, unit direction, a unit reference perpendicular, and the
/// radius used to turn angles into arc length.
struct Axis {
    origin: Vec3,
    dir: Vec3,
    reference: Vec3,
    radius: f32,
}

impl Axis {
    fn new(origin: Vec3, dir: Vec3, radius: f32) -> Self {
        let dir = dir.normalize_or(Vec3::Y);
        let reference = (Vec3::Z - dir * dir.z).normalize_or(Vec3::X);
        Self {
            origin,
            dir,
            reference,
            radius,
        }
    }

    /// (angle around the axis in (-pi, pi], distance along it) of `p`.
    fn polar(&self, p: Vec3) -> (f32, f32) {
        let d = p - self.origin;
        let along = d.dot(self.dir);
        let radial = d - self.dir * along;
        let side = self.dir.cross(self.reference);
        (radial.dot(side).atan2(radial.dot(self.reference)), along)
    }
}

fn chart_axes(rig: &Rig) -> Vec<Axis> {
    let joint = |name: &str| {
        rig.index(name)
            .map(|i| (rig.bones[i].head, rig.bones[i].tail))
    };
    let limb = |upper: &str, lower: &str, radius: f32| match (joint(upper), joint(lower)) {
        (Some((h, _)), Some((_, t))) => Axis::new(h, t - h, radius),
        _ => Axis::new(Vec3::ZERO, Vec3::Y, radius),
    };
    vec![
        Axis::new(Vec3::ZERO, Vec3::Y, 0.15),
        limb("LeftArm", "LeftForeArm", 0.05),
        limb("RightArm", "RightForeArm", 0.05),
        limb("LeftUpLeg", "LeftLeg", 0.08),
        limb("RightUpLeg", "RightLeg", 0.08),
    ]
}

/// Lays the charts' boxes left to right with a small gap and scales everything
/// uniformly into [0, 1]^2.
fn pack(raw: &mut [(usize, [Vec2; 3])]) -> Vec<[[f32; 2]; 3]> {
    let mut lo = [Vec2::splat(f32::INFINITY); 5];
    let mut hi = [Vec2::splat(f32::NEG_INFINITY); 5];
    for (chart, corners) in raw.iter() {
        for c in corners {
            lo[*chart] = lo[*chart].min(*c);
            hi[*chart] = hi[*chart].max(*c);
        }
    }
    let gap = 0.02;
    let mut offset = [Vec2::ZERO; 5];
    let mut x = 0.0;
    let mut height = 0.0f32;
    for c in 0..5 {
        if lo[c].x.is_finite() {
            offset[c] = Vec2::new(x, 0.0) - lo[c];
            x += hi[c].x - lo[c].x + gap;
            height = height.max(hi[c].y - lo[c].y);
        }
    }
    let scale = 1.0 / (x - gap).max(height).max(1e-6);
    raw.iter()
        .map(|(chart, corners)| corners.map(|c| ((c + offset[*chart]) * scale).to_array()))
        .collect()
}
