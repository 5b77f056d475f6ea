//! Isotropic remeshing to a uniform target edge length, after Botsch & Kobbelt, "A remeshing
//! approach to multiresolution modeling" (SGP 2004), and a mesh quality report.
//!
//! [`isotropic_remesh`] repeats, `iterations` times:
//! 1. split every edge longer than 4/3 L at its midpoint (until none is);
//! 2. collapse every edge shorter than 4/5 L into its midpoint (into the constrained end when
//!    one end is on the boundary or a corner) unless that would create an edge longer than
//!    4/3 L, turn a face by more than 45 degrees, break manifoldness (link condition), or
//!    change the boundary topology (a boundary vertex only merges with its loop neighbour, an
//!    edge joining two boundary vertices across the surface is never collapsed, a loop keeps
//!    three vertices);
//! 3. flip interior edges whose flip brings the valences of its four vertices closer to 6 (4
//!    on a boundary), unless it turns a face by more than 45 degrees or puts a long edge
//!    (over 4/3 L) at the boundary;
//! 4. tangential relaxation: every vertex moves to the (area-weighted or uniform) centroid of
//!    its neighbours, projected onto its tangent plane;
//! 5. projection of every interior vertex back onto the input surface (closest point through
//!    a BVH).
//!
//! and finally flips edges of triangles with an angle under 25 degrees where that raises the
//! smallest angle (Delaunay criterion). The mean edge length comes out within a few percent of
//! L, the 5th and 95th percentiles typically near 0.85 L and 1.17 L.
//!
//! Boundaries: every input boundary loop stays one loop (so the genus and the number of loops
//! are kept), resampled to about L. Boundary vertices live on the input boundary polyline,
//! addressed by arc length (in f64): splits and collapses place them at arc-length midpoints,
//! relaxation moves them to the midpoint of their two loop neighbours, so openings keep their
//! exact shape and no boundary vertex ever passes another. Boundary vertices where the input
//! loop turns by more than [`RemeshOptions::corner_angle_deg`] are kept as they are. The
//! output boundary is as smooth as the input's: smooth jagged openings first (for example
//! [`crate::smooth::Smoother`] with interior vertices pinned and
//! [`crate::smooth::BoundarySmoothing::AlongLoop`]).
//!
//! The result records, for each new vertex, an input face and barycentric weights
//! ([`Remeshed::source_face`], [`Remeshed::source_bary`]) so attributes such as skinning
//! weights or UVs can be carried over ([`Remeshed::interpolate`]).

mod halfedge;
mod ops;
mod project;
mod quality;
mod relax;

use std::ops::{Add, Mul};

pub use quality::{mesh_quality, MeshQuality};

use crate::adjacency::{boundary_loops, check_manifold, EdgeTopology};
use crate::error::{GeomError, Result};
use crate::mesh::TriMesh;
use halfedge::{HeMesh, VTag};
use ops::Remesher;
use project::Projector;

/// What remeshing may do to the boundary loops.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BoundaryMode {
    /// Boundary vertices and edges are kept exactly as in the input (no split, collapse or
    /// move): use when the boundary must match another mesh.
    Fixed,
    /// Boundary edges are split and collapsed toward L (new vertices on the input boundary
    /// polyline, at arc-length midpoints) but relaxation does not move boundary vertices.
    Resample,
    /// As `Resample`, and boundary vertices also slide along the input boundary polyline
    /// during relaxation, giving evenly spaced boundary vertices (the default).
    #[default]
    Slide,
}

/// How tangential relaxation weighs a vertex's neighbours.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Relaxation {
    /// Plain mean of the neighbours.
    Uniform,
    /// Mean weighted by each neighbour's area (a third of its incident faces), which evens
    /// out triangle sizes (the default, as in Botsch et al., *Polygon Mesh Processing* 6.5).
    #[default]
    AreaWeighted,
}

/// Options of [`isotropic_remesh`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RemeshOptions {
    /// Target edge length L (metres); the output's mean edge length comes out close to L.
    pub target_edge_length: f32,
    /// Number of split / collapse / flip / relax / project iterations (default 8).
    pub iterations: u32,
    /// Project interior vertices back onto the input surface after each relaxation (default
    /// `true`). Without it, vertices only move tangentially and drift off curved surfaces.
    pub project: bool,
    /// What may happen to the boundary (default [`BoundaryMode::Slide`]).
    pub boundary: BoundaryMode,
    /// Weights of tangential relaxation (default [`Relaxation::AreaWeighted`]).
    pub relaxation: Relaxation,
    /// An input boundary vertex where the loop turns by more than this angle (degrees) is a
    /// corner and is kept in place (default 60). Use 180 to keep no corner.
    pub corner_angle_deg: f32,
}

impl Default for RemeshOptions {
    /// L = 1 cm (the GarNet paper's garment resolution), 8 iterations, projection on,
    /// sliding boundary, area-weighted relaxation, 60-degree corners.
    fn default() -> Self {
        RemeshOptions {
            target_edge_length: 0.01,
            iterations: 8,
            project: true,
            boundary: BoundaryMode::Slide,
            relaxation: Relaxation::AreaWeighted,
            corner_angle_deg: 60.0,
        }
    }
}

impl RemeshOptions {
    /// The defaults with target edge length `l` (metres).
    pub fn new(l: f32) -> Self {
        RemeshOptions {
            target_edge_length: l,
            ..Default::default()
        }
    }
}

/// Counts of what [`isotropic_remesh`] did, summed over iterations.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RemeshStats {
    /// Edge splits.
    pub splits: usize,
    /// Edge collapses.
    pub collapses: usize,
    /// Edge flips.
    pub flips: usize,
    /// Boundary loops of the input (and of the output).
    pub boundary_loops: usize,
}

/// The result of [`isotropic_remesh`].
#[derive(Clone, Debug, Default)]
pub struct Remeshed {
    /// The new mesh: vertices `[N']` (metres), faces `[F']`, oriented as the input.
    pub mesh: TriMesh,
    /// `[N']` for each new vertex, the input face its source point lies in: the closest point
    /// of the input surface (interior vertices) or its place on the input boundary polyline
    /// (boundary vertices).
    pub source_face: Vec<u32>,
    /// `[N']` barycentric weights (non-negative, sum 1) of the source point over the three
    /// vertices of `source_face`, in that face's corner order.
    pub source_bary: Vec<[f32; 3]>,
    /// What the passes did.
    pub stats: RemeshStats,
}

impl Remeshed {
    /// Carries per-vertex values of the input (`values`: `[N]`, one per input vertex) over to
    /// the new vertices by barycentric interpolation: `[N']`. `input_faces` are the input's
    /// `[F]` faces. Works for `f32`, [`glam::Vec2`], [`glam::Vec3`] and any type with
    /// `T + T` and `T * f32`. Fails when a face or index is out of range.
    pub fn interpolate<T>(&self, input_faces: &[[u32; 3]], values: &[T]) -> Result<Vec<T>>
    where
        T: Copy + Add<Output = T> + Mul<f32, Output = T>,
    {
        self.source_face
            .iter()
            .zip(&self.source_bary)
            .map(|(&f, w)| {
                let face = input_faces.get(f as usize).ok_or_else(|| {
                    GeomError::InvalidInput(format!(
                        "source face {f} is out of range ({} faces)",
                        input_faces.len()
                    ))
                })?;
                let v = |c: usize| {
                    values.get(face[c] as usize).copied().ok_or_else(|| {
                        GeomError::InvalidInput(format!(
                            "vertex {} is out of range ({} values)",
                            face[c],
                            values.len()
                        ))
                    })
                };
                Ok(v(0)? * w[0] + v(1)? * w[1] + v(2)? * w[2])
            })
            .collect()
    }
}

/// Triangles with an angle below this (degrees) get a last Delaunay flip where that helps.
const SLIVER_ANGLE_DEG: f32 = 25.0;

/// Largest number of output faces [`isotropic_remesh`] accepts to produce (estimated from the
/// surface area and L before starting).
pub const MAX_REMESH_FACES: f64 = 5.0e7;

/// Remeshes `mesh` (vertices `[N]` in metres, faces `[F]`) to near-equilateral triangles of
/// edge length about `opts.target_edge_length`, keeping its topology (genus, boundary loops)
/// and its orientation; see the module documentation for the algorithm.
///
/// The input must be a manifold, consistently oriented triangle mesh without degenerate faces
/// (repeated index); unreferenced vertices are ignored. Fails on a non-positive or non-finite
/// target length, zero iterations are allowed (the input comes back with its sources), an
/// empty or invalid mesh, or an estimated output above [`MAX_REMESH_FACES`] faces.
/// Deterministic: the same input and options give bit-identical output.
pub fn isotropic_remesh(mesh: &TriMesh, opts: &RemeshOptions) -> Result<Remeshed> {
    let l = opts.target_edge_length;
    if !(l.is_finite() && l > 0.0) {
        return Err(GeomError::InvalidInput(format!(
            "target edge length must be positive and finite, got {l}"
        )));
    }
    if opts.corner_angle_deg.is_nan() {
        return Err(GeomError::InvalidInput("corner angle is NaN".into()));
    }
    mesh.validate()?;
    if mesh.faces.is_empty() {
        return Err(GeomError::InvalidInput(
            "cannot remesh a mesh without faces".into(),
        ));
    }
    let report = check_manifold(mesh.vertices.len(), &mesh.faces)?;
    if !report.is_ok() {
        return Err(GeomError::InvalidMesh(format!(
            "remeshing needs a manifold, consistently oriented mesh: {report}"
        )));
    }
    let estimate = mesh.surface_area() as f64 / (3f64.sqrt() / 4.0 * (l as f64).powi(2));
    if estimate > MAX_REMESH_FACES {
        return Err(GeomError::InvalidInput(format!(
            "target edge length {l} m would give about {estimate:.0} faces (limit {MAX_REMESH_FACES})"
        )));
    }
    // Drop unreferenced vertices; faces keep their indices in the input (for the sources).
    let mut used = vec![false; mesh.vertices.len()];
    for f in &mesh.faces {
        for &v in f {
            used[v as usize] = true;
        }
    }
    let mut remap = vec![u32::MAX; mesh.vertices.len()];
    let mut pos = Vec::new();
    for (v, &u) in used.iter().enumerate() {
        if u {
            remap[v] = pos.len() as u32;
            pos.push(mesh.vertices[v]);
        }
    }
    let faces: Vec<[u32; 3]> = mesh
        .faces
        .iter()
        .map(|f| f.map(|v| remap[v as usize]))
        .collect();
    let topo = EdgeTopology::new(pos.len(), &faces)?;
    let loops = boundary_loops(pos.len(), &faces)?;
    let proj = Projector::new(&pos, &faces, &topo, &loops)?;

    let corner_cos = opts.corner_angle_deg.clamp(0.0, 180.0).to_radians().cos();
    let mut tags = vec![VTag::INTERIOR; pos.len()];
    for (lp, line) in proj.loops.iter().enumerate() {
        let k = line.pts.len();
        for i in 0..k {
            let din = line.pts[i] - line.pts[(i + k - 1) % k];
            let dout = line.pts[(i + 1) % k] - line.pts[i];
            let corner = din.normalize_or_zero().dot(dout.normalize_or_zero()) < corner_cos;
            tags[line.verts[i] as usize] = VTag {
                lp: lp as u32,
                s: line.cum[i],
                locked: corner || opts.boundary == BoundaryMode::Fixed,
            };
        }
    }
    let loop_len = proj.loops.iter().map(|l| l.verts.len() as u32).collect();
    let he = HeMesh::build(pos, tags, &faces, &topo);
    let mut r = Remesher::new(he, &proj, *opts, loop_len);
    r.stats.boundary_loops = proj.loops.len();
    for _ in 0..opts.iterations {
        r.split_long_edges();
        r.collapse_short_edges(4);
        r.equalize_valences();
        r.relax();
        if opts.project {
            r.project();
        }
        r.m.compact();
    }
    if opts.iterations > 0 {
        r.flip_slivers(SLIVER_ANGLE_DEG, 3);
    }
    let (source_face, source_bary) = r.sources();
    let faces = r.m.faces();
    Ok(Remeshed {
        mesh: TriMesh::new(r.m.pos, faces),
        source_face,
        source_bary,
        stats: r.stats,
    })
}
