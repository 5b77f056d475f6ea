//! Acclaim skeleton files (ASF), as in the CMU motion capture database.
//!
//! Values are kept in the file's length unit (see [`Asf::metres_per_unit`]); angles are
//! converted to radians while reading.

use std::path::{Path, PathBuf};

use glam::DVec3;

use super::error::{read_text, PoseError};
use super::euler::Axis;

/// One degree of freedom of an ASF bone or of the root.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dof {
    /// Rotation about the local X axis (angle).
    Rx,
    /// Rotation about the local Y axis (angle).
    Ry,
    /// Rotation about the local Z axis (angle).
    Rz,
    /// Translation along X (file length unit).
    Tx,
    /// Translation along Y (file length unit).
    Ty,
    /// Translation along Z (file length unit).
    Tz,
    /// Bone length change (file length unit); read but not applied.
    L,
}

impl Dof {
    /// Parses `rx`, `ry`, `rz`, `tx`, `ty`, `tz` or `l` (either case).
    pub(super) fn parse(s: &str) -> Option<Dof> {
        Some(match s.to_ascii_lowercase().as_str() {
            "rx" => Dof::Rx,
            "ry" => Dof::Ry,
            "rz" => Dof::Rz,
            "tx" => Dof::Tx,
            "ty" => Dof::Ty,
            "tz" => Dof::Tz,
            "l" => Dof::L,
            _ => return None,
        })
    }

    /// The rotation axis of a rotational dof, `None` for translations and length.
    pub fn rotation_axis(self) -> Option<Axis> {
        match self {
            Dof::Rx => Some(Axis::X),
            Dof::Ry => Some(Axis::Y),
            Dof::Rz => Some(Axis::Z),
            _ => None,
        }
    }
}

/// The `:units` section.
#[derive(Clone, Debug, PartialEq)]
pub struct AsfUnits {
    /// `mass` multiplier (unused).
    pub mass: f64,
    /// `length` multiplier: the CMU files say 0.45, meaning one unit is 1/0.45 inch.
    pub length: f64,
    /// Whether angles in the ASF (and, unless it says otherwise, the AMC) are degrees.
    pub degrees: bool,
}

/// The `:root` section.
#[derive(Clone, Debug, PartialEq)]
pub struct AsfRoot {
    /// Order of the six root values in every AMC frame (`TX TY TZ RX RY RZ`); the
    /// rotations are applied in this order.
    pub order: Vec<Dof>,
    /// Order of the `orientation` rotations.
    pub axis: [Axis; 3],
    /// Rest position of the root, file length unit.
    pub position: DVec3,
    /// Rest orientation of the root, radians, applied in `axis` order.
    pub orientation: DVec3,
}

/// One bone of the `:bonedata` section.
#[derive(Clone, Debug, PartialEq)]
pub struct AsfBone {
    /// The `id` field, if present.
    pub id: Option<i64>,
    /// The bone name (`lfemur`).
    pub name: String,
    /// Unit rest direction from the bone's head to its tail, in world axes (zero for a
    /// zero-length bone).
    pub direction: DVec3,
    /// Length, file length unit.
    pub length: f64,
    /// The `axis` angles (radians) giving the bone's local frame C.
    pub axis: DVec3,
    /// Order in which the `axis` rotations are applied (`XYZ`: C = Rz * Ry * Rx).
    pub axis_order: [Axis; 3],
    /// The degrees of freedom, in the order of their values in an AMC line.
    pub dofs: Vec<Dof>,
    /// `(min, max)` per dof (radians for rotations); infinite where the file says inf.
    pub limits: Vec<(f64, f64)>,
    /// Index of the parent bone in [`Asf::bones`]; `None` for a child of the root.
    pub parent: Option<usize>,
}

/// A parsed ASF skeleton. Bones are in file order; [`Asf::order`] lists them parents first.
#[derive(Clone, Debug, PartialEq)]
pub struct Asf {
    /// The file it was read from (for messages).
    pub path: PathBuf,
    /// The `:name` value.
    pub name: String,
    /// The `:units` section.
    pub units: AsfUnits,
    /// The `:root` section.
    pub root: AsfRoot,
    /// The bones, in file order.
    pub bones: Vec<AsfBone>,
    pub(super) order: Vec<usize>,
}

impl Asf {
    /// Reads and parses an ASF file.
    pub fn read(path: impl AsRef<Path>) -> Result<Asf, PoseError> {
        let path = path.as_ref();
        Self::parse(&read_text(path)?, path)
    }

    /// Parses ASF text; `path` is used in error messages.
    pub fn parse(text: &str, path: &Path) -> Result<Asf, PoseError> {
        super::asf_parse::parse(text, path)
    }

    /// Metres per file length unit: `0.0254 / units.length` (the CMU convention: a unit
    /// is `1 / length` inches, so a CMU femur of 7.59 units is 0.43 m).
    pub fn metres_per_unit(&self) -> f64 {
        0.0254 / self.units.length
    }

    /// Index of the bone called `name` in [`Asf::bones`].
    pub fn bone_index(&self, name: &str) -> Option<usize> {
        self.bones.iter().position(|b| b.name == name)
    }

    /// Bone indices with every parent before its children.
    pub fn order(&self) -> &[usize] {
        &self.order
    }

    /// Where each bone's values start in an AMC frame's value row, and the row length:
    /// the root's values first (in `root.order`), then every bone's dofs in file order.
    pub fn value_layout(&self) -> (Vec<usize>, usize) {
        let mut offsets = Vec::with_capacity(self.bones.len());
        let mut at = self.root.order.len();
        for b in &self.bones {
            offsets.push(at);
            at += b.dofs.len();
        }
        (offsets, at)
    }
}
