//! Rotations about coordinate axes and their compositions in the orders the motion file
//! formats use (f64: the readers and the BVH writer round-trip through Euler angles).

use glam::{DQuat, DVec3};

/// A coordinate axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Axis {
    /// The X axis.
    X,
    /// The Y axis.
    Y,
    /// The Z axis.
    Z,
}

impl Axis {
    /// The unit vector of the axis.
    pub fn unit(self) -> DVec3 {
        match self {
            Axis::X => DVec3::X,
            Axis::Y => DVec3::Y,
            Axis::Z => DVec3::Z,
        }
    }

    /// The rotation by `angle` radians about the axis (right-handed).
    pub fn rotation(self, angle: f64) -> DQuat {
        match self {
            Axis::X => DQuat::from_rotation_x(angle),
            Axis::Y => DQuat::from_rotation_y(angle),
            Axis::Z => DQuat::from_rotation_z(angle),
        }
    }

    /// Parses `x`/`y`/`z` (either case).
    pub fn from_char(c: char) -> Option<Axis> {
        match c.to_ascii_lowercase() {
            'x' => Some(Axis::X),
            'y' => Some(Axis::Y),
            'z' => Some(Axis::Z),
            _ => None,
        }
    }

    /// Parses a three-letter order such as `XYZ` (each axis once).
    pub fn parse_order(s: &str) -> Option<[Axis; 3]> {
        let mut chars = s.chars();
        let order = [
            Axis::from_char(chars.next()?)?,
            Axis::from_char(chars.next()?)?,
            Axis::from_char(chars.next()?)?,
        ];
        let distinct = order[0] != order[1] && order[1] != order[2] && order[0] != order[2];
        (chars.next().is_none() && distinct).then_some(order)
    }
}

/// Rotations applied one after the other in the listed order (the ASF/AMC convention:
/// `dof rx ry rz` and `axis ... XYZ` give `Rz * Ry * Rx`). Angles in radians.
pub fn applied_in_order(axes: &[Axis], angles: &[f64]) -> DQuat {
    axes.iter()
        .zip(angles)
        .fold(DQuat::IDENTITY, |acc, (a, &t)| a.rotation(t) * acc)
}

/// Intrinsic rotations composed left to right in the listed order (the BVH convention:
/// `Zrotation Yrotation Xrotation` gives `Rz * Ry * Rx`). Angles in radians.
pub fn intrinsic(axes: &[Axis], angles: &[f64]) -> DQuat {
    axes.iter()
        .zip(angles)
        .fold(DQuat::IDENTITY, |acc, (a, &t)| acc * a.rotation(t))
}

/// Angles `(z, y, x)` in radians with `q = Rz(z) * Ry(y) * Rx(x)`.
pub fn to_zyx(q: DQuat) -> (f64, f64, f64) {
    q.normalize().to_euler(glam::EulerRot::ZYX)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orders_and_decomposition() {
        let axes = [Axis::Z, Axis::Y, Axis::X];
        let (z, y, x) = (0.3, -1.1, 2.0);
        let a = intrinsic(&axes, &[z, y, x]);
        let b = applied_in_order(&[Axis::X, Axis::Y, Axis::Z], &[x, y, z]);
        let m = DQuat::from_rotation_z(z) * DQuat::from_rotation_y(y) * DQuat::from_rotation_x(x);
        assert!(a.angle_between(m) < 1e-7 && b.angle_between(m) < 1e-7);
        let (z2, y2, x2) = to_zyx(m);
        assert!(intrinsic(&axes, &[z2, y2, x2]).angle_between(m) < 1e-7);
        assert_eq!(Axis::parse_order("xZy"), Some([Axis::X, Axis::Z, Axis::Y]));
        assert_eq!(Axis::parse_order("XXY"), None);
        assert_eq!(Axis::parse_order("XYZW"), None);
    }
}
