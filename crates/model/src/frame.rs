//! The canonical frame: every sample is turned about the vertical axis and moved horizontally
//! so that its warped garment M lies over the garment template, before it enters the network.
//!
//! Mocap poses face every direction and drift over the floor; a PointNet on raw coordinates
//! would have to learn the same drape once per heading. Draping is unchanged by a turn about
//! gravity (+Y) and a horizontal move, so the network works in a frame fitted to its own
//! input: the yaw and offset that best map the template's rest vertices onto M (a weighted
//! 2D Procrustes fit in the XZ plane). Every loss term and metric is a distance or angle,
//! unchanged by the move; predictions are mapped back to the world with
//! [`CanonicalFrame::to_world`].

use glam::{Quat, Vec3};

/// A turn about +Y and a horizontal offset: `world = rotation * canonical + offset`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CanonicalFrame {
    /// Turn about +Y from the canonical frame to the world.
    pub rotation: Quat,
    /// Horizontal offset (metres, y = 0) from the canonical frame to the world.
    pub offset: Vec3,
}

impl CanonicalFrame {
    /// The yaw-and-offset that best maps `rest` `[N]` (the template, metres) onto `warped`
    /// `[N]` (M, metres) in the XZ plane (least squares). Heights are not moved. With fewer
    /// than two distinct horizontal positions, or `rest` and `warped` of different lengths,
    /// the identity.
    pub fn fit(rest: &[Vec3], warped: &[Vec3]) -> CanonicalFrame {
        let identity = CanonicalFrame {
            rotation: Quat::IDENTITY,
            offset: Vec3::ZERO,
        };
        if rest.len() != warped.len() || rest.is_empty() {
            return identity;
        }
        let n = rest.len() as f64;
        let centre = |pts: &[Vec3]| {
            let (x, z) = pts.iter().fold((0.0f64, 0.0f64), |(x, z), p| {
                (x + p.x as f64, z + p.z as f64)
            });
            (x / n, z / n)
        };
        let (rx, rz) = centre(rest);
        let (wx, wz) = centre(warped);
        // Rotation angle about +Y maximising sum(w . R r): a right-handed turn by `a` about
        // +Y maps (x, z) to (x cos a + z sin a, -x sin a + z cos a).
        let (mut dot, mut cross) = (0.0f64, 0.0f64);
        for (r, w) in rest.iter().zip(warped) {
            let (ax, az) = (r.x as f64 - rx, r.z as f64 - rz);
            let (bx, bz) = (w.x as f64 - wx, w.z as f64 - wz);
            dot += ax * bx + az * bz;
            cross += az * bx - ax * bz;
        }
        if dot == 0.0 && cross == 0.0 {
            return identity;
        }
        let angle = cross.atan2(dot);
        let rotation = Quat::from_rotation_y(angle as f32);
        let turned = rotation * Vec3::new(rx as f32, 0.0, rz as f32);
        let offset = Vec3::new(wx as f32 - turned.x, 0.0, wz as f32 - turned.z);
        CanonicalFrame { rotation, offset }
    }

    /// A world point (metres) in the canonical frame.
    pub fn to_canonical(&self, p: Vec3) -> Vec3 {
        self.rotation.inverse() * (p - self.offset)
    }

    /// A world direction in the canonical frame (turned only).
    pub fn direction_to_canonical(&self, d: Vec3) -> Vec3 {
        self.rotation.inverse() * d
    }

    /// A canonical point (metres) in the world.
    pub fn to_world(&self, p: Vec3) -> Vec3 {
        self.rotation * p + self.offset
    }

    /// `points` `[N]` in the canonical frame.
    pub fn points_to_canonical(&self, points: &[Vec3]) -> Vec<Vec3> {
        points.iter().map(|&p| self.to_canonical(p)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn shirt_like() -> Vec<Vec3> {
        (0..40)
            .map(|i| {
                let t = i as f32 * 0.37;
                Vec3::new(0.3 * t.cos(), 1.0 + 0.02 * i as f32, 0.12 * t.sin() + 0.05)
            })
            .collect()
    }

    #[test]
    fn recovers_a_turn_and_a_move() {
        let rest = shirt_like();
        for angle in [-2.9f32, -1.0, 0.0, 0.4, 1.7, 3.1] {
            let truth = CanonicalFrame {
                rotation: Quat::from_rotation_y(angle),
                offset: Vec3::new(0.7, 0.0, -1.3),
            };
            let warped: Vec<Vec3> = rest.iter().map(|&p| truth.to_world(p)).collect();
            let fit = CanonicalFrame::fit(&rest, &warped);
            for (&r, &w) in rest.iter().zip(&warped) {
                assert!(fit.to_world(r).distance(w) < 1e-4, "angle {angle}");
                assert!(fit.to_canonical(w).distance(r) < 1e-4, "angle {angle}");
            }
        }
    }

    #[test]
    fn heights_and_degenerate_inputs_are_left_alone() {
        let rest = shirt_like();
        let lifted: Vec<Vec3> = rest.iter().map(|&p| p + Vec3::Y * 0.3).collect();
        let fit = CanonicalFrame::fit(&rest, &lifted);
        assert!(fit.rotation.angle_between(Quat::IDENTITY) < 1e-5);
        assert!(fit.offset.length() < 1e-5);
        let still = CanonicalFrame::fit(&[Vec3::ONE], &[Vec3::ONE]);
        assert_eq!(still.rotation, Quat::IDENTITY);
        assert_eq!(CanonicalFrame::fit(&rest, &rest[1..]).offset, Vec3::ZERO);
    }
}
