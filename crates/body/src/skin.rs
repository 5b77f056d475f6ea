//! Skinning weights and the two skinning methods: linear blend skinning (LBS) and dual
//! quaternion skinning (DQS, Kavan et al. 2007).

use glam::{Quat, Vec3};
use rayon::prelude::*;

use crate::rig::RigidTransform;

/// Sparse per-vertex bone weights in compressed rows: vertex `v` has the influences
/// `bones[offsets[v]..offsets[v+1]]` with `weights[..]` alike, each row summing to 1.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SkinWeights {
    /// `[N+1]` row starts.
    pub offsets: Vec<u32>,
    /// `[nnz]` bone indices (rig order).
    pub bones: Vec<u16>,
    /// `[nnz]` weights in (0, 1].
    pub weights: Vec<f32>,
}

/// Which skinning method to use.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Skinning {
    /// Linear blend skinning: weighted sum of the transformed points.
    Lbs,
    /// Dual quaternion skinning: blend of rigid transforms (no candy-wrapper collapse).
    #[default]
    Dqs,
}

impl Skinning {
    /// The method's short name: `"lbs"` or `"dqs"`.
    pub fn name(self) -> &'static str {
        match self {
            Skinning::Lbs => "lbs",
            Skinning::Dqs => "dqs",
        }
    }

    /// The method named `name` (`lbs` or `dqs`, any case); `None` for any other name.
    pub fn from_name(name: &str) -> Option<Skinning> {
        match name.to_ascii_lowercase().as_str() {
            "lbs" => Some(Skinning::Lbs),
            "dqs" => Some(Skinning::Dqs),
            _ => None,
        }
    }
}

impl SkinWeights {
    /// Number of vertices.
    pub fn len(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    /// Whether there are no vertices.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Builds rows from per-vertex `(bone, weight)` lists, dropping non-positive
    /// weights and normalising each row to sum to 1. A row left empty is an error
    /// (returns the vertex index).
    pub fn from_rows(rows: &[Vec<(u16, f32)>]) -> Result<Self, usize> {
        let mut out = SkinWeights {
            offsets: vec![0],
            ..Default::default()
        };
        for (v, row) in rows.iter().enumerate() {
            let total: f32 = row.iter().filter(|(_, w)| *w > 0.0).map(|(_, w)| w).sum();
            if total <= 0.0 || !total.is_finite() {
                return Err(v);
            }
            for &(b, w) in row.iter().filter(|(_, w)| *w > 0.0) {
                out.bones.push(b);
                out.weights.push(w / total);
            }
            out.offsets.push(out.bones.len() as u32);
        }
        Ok(out)
    }

    /// The influences of vertex `v` as `(bone, weight)` pairs.
    pub fn row(&self, v: usize) -> impl Iterator<Item = (usize, f32)> + '_ {
        let (a, b) = (self.offsets[v] as usize, self.offsets[v + 1] as usize);
        self.bones[a..b]
            .iter()
            .zip(&self.weights[a..b])
            .map(|(&b, &w)| (b as usize, w))
    }

    /// The bone with the largest weight on vertex `v` (the first of equal ones).
    pub fn heaviest(&self, v: usize) -> usize {
        self.row(v)
            .fold(
                (0, -1.0),
                |best, (b, w)| if w > best.1 { (b, w) } else { best },
            )
            .0
    }

    /// Skins rest positions `rest` `[N]` with per-bone `transforms` `[B]`, returning the
    /// posed positions `[N]` (metres).
    pub fn apply(
        &self,
        rest: &[Vec3],
        transforms: &[RigidTransform],
        method: Skinning,
    ) -> Vec<Vec3> {
        assert_eq!(
            rest.len(),
            self.len(),
            "rest positions and weight rows differ"
        );
        match method {
            Skinning::Lbs => rest
                .par_iter()
                .enumerate()
                .map(|(v, &p)| self.row(v).map(|(b, w)| w * transforms[b].apply(p)).sum())
                .collect(),
            Skinning::Dqs => {
                let duals: Vec<DualQuat> = transforms.iter().map(DualQuat::from_rigid).collect();
                rest.par_iter()
                    .enumerate()
                    .map(|(v, &p)| blend_dual(|| self.row(v), &duals).transform_point(p))
                    .collect()
            }
        }
    }
}

/// A unit dual quaternion `real + eps * dual` representing a rigid transform.
#[derive(Clone, Copy, Debug)]
pub struct DualQuat {
    pub real: Quat,
    pub dual: Quat,
}

impl DualQuat {
    /// The dual quaternion of `x -> R x + t`: real = R, dual = 0.5 * (t, 0) * R.
    pub fn from_rigid(t: &RigidTransform) -> Self {
        let tq = Quat::from_xyzw(t.translation.x, t.translation.y, t.translation.z, 0.0);
        Self {
            real: t.rotation,
            dual: (tq * t.rotation) * 0.5,
        }
    }

    /// Applies the (normalised) transform to a point.
    pub fn transform_point(&self, p: Vec3) -> Vec3 {
        let r = self.real;
        let d = self.dual;
        // Translation t = 2 * dual * conj(real).
        let t = (d * r.conjugate()) * 2.0;
        r * p + Vec3::new(t.x, t.y, t.z)
    }
}

/// Blends bone dual quaternions with weights (`row` yields `(bone, weight)` and may be
/// iterated twice), flipping each to the hemisphere of the heaviest influence (shortest
/// path), then normalises by the real part's norm.
fn blend_dual<I: Iterator<Item = (usize, f32)>>(
    row: impl Fn() -> I,
    duals: &[DualQuat],
) -> DualQuat {
    let zero = Quat::from_xyzw(0.0, 0.0, 0.0, 0.0);
    let pivot = row()
        .fold((Quat::IDENTITY, -1.0f32), |best, (b, w)| {
            if w > best.1 {
                (duals[b].real, w)
            } else {
                best
            }
        })
        .0;
    let (mut real, mut dual) = (zero, zero);
    for (b, w) in row() {
        let q = duals[b];
        let s = if q.real.dot(pivot) < 0.0 { -w } else { w };
        real += q.real * s;
        dual += q.dual * s;
    }
    let n = real.length();
    if n < 1e-12 {
        return DualQuat {
            real: Quat::IDENTITY,
            dual: zero,
        };
    }
    DualQuat {
        real: real / n,
        dual: dual / n,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn skinning_names_round_trip() {
        for s in [Skinning::Lbs, Skinning::Dqs] {
            assert_eq!(Skinning::from_name(s.name()), Some(s));
        }
        assert_eq!(Skinning::from_name("LBS"), Some(Skinning::Lbs));
        assert_eq!(Skinning::from_name("cubic"), None);
    }

    fn two_bone_weights() -> SkinWeights {
        SkinWeights::from_rows(&[vec![(0, 1.0)], vec![(1, 2.0)], vec![(0, 1.0), (1, 1.0)]]).unwrap()
    }

    #[test]
    fn rows_are_normalised() {
        let w = two_bone_weights();
        assert_eq!(w.len(), 3);
        let s: f32 = w.row(2).map(|(_, w)| w).sum();
        assert!((s - 1.0).abs() < 1e-6);
        assert_eq!(w.row(1).next(), Some((1, 1.0)));
        assert_eq!(SkinWeights::from_rows(&[vec![(0, 0.0)]]), Err(0));
    }

    #[test]
    fn dual_quaternion_reproduces_a_rigid_transform() {
        let t = RigidTransform {
            rotation: Quat::from_axis_angle(Vec3::new(1.0, 2.0, 3.0).normalize(), 1.1),
            translation: Vec3::new(0.3, -0.2, 0.5),
        };
        let p = Vec3::new(0.1, 0.7, -0.4);
        let dq = DualQuat::from_rigid(&t);
        assert!((dq.transform_point(p) - t.apply(p)).length() < 1e-5);
    }

    #[test]
    fn lbs_and_dqs_agree_for_single_influences_and_differ_when_blended() {
        let w = two_bone_weights();
        let rest = vec![Vec3::X, Vec3::Y, Vec3::new(1.0, 1.0, 0.0)];
        let tf = [
            RigidTransform::IDENTITY,
            RigidTransform {
                rotation: Quat::from_rotation_z(std::f32::consts::FRAC_PI_2 * 1.8),
                translation: Vec3::ZERO,
            },
        ];
        let lbs = w.apply(&rest, &tf, Skinning::Lbs);
        let dqs = w.apply(&rest, &tf, Skinning::Dqs);
        for v in 0..2 {
            assert!((lbs[v] - dqs[v]).length() < 1e-5);
        }
        // Blended vertex: DQS keeps the distance to the rotation centre, LBS shrinks it.
        let r = rest[2].length();
        assert!((dqs[2].length() - r).abs() < 1e-4);
        assert!(lbs[2].length() < r * 0.8);
    }
}
