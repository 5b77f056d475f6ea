//! Geometry for garnet: triangle meshes, their I/O, adjacency, spatial queries and metrics.
//!
//! Conventions (see DESIGN.md section 3): metres, right-handed, Y up, the body facing +Z;
//! f32 positions; vertices `[N]` of [`glam::Vec3`] (row-major `[N,3]` when flattened), faces
//! `[F]` of `[u32; 3]`, counter-clockwise seen from outside. No function panics on bad input:
//! fallible ones return [`GeomError`]; the per-step numeric kernels ([`normals`]) are total.

#![warn(missing_docs)]

pub mod adjacency;
pub mod bvh;
pub mod error;
pub mod io;
pub mod knn;
pub mod mesh;
pub mod metrics;
pub mod normals;
pub mod primitives;
pub mod remesh;
pub mod smooth;
pub mod tri;

pub use bvh::{Bvh, ClosestHit, SegmentHit};
pub use error::{GeomError, Result};
pub use knn::{KnnIndex, KnnResult};
pub use mesh::TriMesh;
