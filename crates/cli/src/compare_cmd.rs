//! `garnet compare`: the paper's errors between two drapes of one garment mesh, e.g. a
//! GarNet drape against the simulator's on the same body, or two simulator drapes of nearly
//! the same input (how repeatable the simulator is).

use std::path::{Path, PathBuf};

use anyhow::{bail, Context};
use clap::Args;
use geom::metrics::{m_to_cm, mesh_errors, precision_curve, vertex_distances};
use geom::TriMesh;
use serde::Serialize;
use sim::stats::percentile;

use crate::simulate_cmd::write_json;

/// Arguments of `garnet compare`.
#[derive(Args, Debug)]
pub struct CompareArgs {
    /// The reference drape (e.g. the simulator's): .obj, .ply or .glb, metres.
    pub reference: PathBuf,
    /// The drape to measure against it: the same mesh (vertex order and faces), moved.
    pub other: PathBuf,
    /// Also write the figures as JSON.
    #[arg(long, value_name = "FILE.json")]
    pub json: Option<PathBuf>,
}

/// How far one drape is from another of the same mesh: distances in cm, angles in degrees.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Comparison {
    /// Vertices compared.
    pub vertices: usize,
    /// Faces compared.
    pub faces: usize,
    /// E_dist: mean vertex distance, cm.
    pub e_dist_cm: f32,
    /// Median vertex distance, cm.
    pub dist_p50_cm: f32,
    /// 90th percentile of the vertex distances, cm.
    pub dist_p90_cm: f32,
    /// Largest vertex distance, cm.
    pub dist_max_cm: f32,
    /// E_norm: mean angle between corresponding face normals, degrees.
    pub e_norm_deg: f32,
    /// Share of vertices within 1 cm of the reference, percent.
    pub within_1cm_pct: f32,
    /// Share of vertices within 2 cm of the reference, percent.
    pub within_2cm_pct: f32,
}

impl Comparison {
    /// Compares `other` `[N]` vertices with `reference` `[N]` over the reference's faces
    /// `[F]` (metres in). Errors when the vertex counts differ, a face index is out of range
    /// or a coordinate is not finite; the message says which input.
    pub fn measure(reference: &TriMesh, other: &TriMesh) -> anyhow::Result<Comparison> {
        for (name, mesh) in [("reference", reference), ("other", other)] {
            if let Some(i) = mesh.vertices.iter().position(|v| !v.is_finite()) {
                bail!("the {name} mesh's vertex {i} is not finite");
            }
        }
        if reference.faces != other.faces {
            bail!(
                "the meshes are not the same garment mesh: {} vertices and {} faces against \
                 {} and {} (or the same counts with other faces)",
                reference.vertices.len(),
                reference.faces.len(),
                other.vertices.len(),
                other.faces.len()
            );
        }
        let errors = mesh_errors(&reference.vertices, &other.vertices, &reference.faces)?;
        let dist = vertex_distances(&reference.vertices, &other.vertices)?;
        let within = precision_curve(&dist, &[0.01, 0.02]);
        Ok(Comparison {
            vertices: dist.len(),
            faces: reference.faces.len(),
            e_dist_cm: errors.e_dist_cm,
            dist_p50_cm: m_to_cm(percentile(&dist, 0.5)),
            dist_p90_cm: m_to_cm(percentile(&dist, 0.9)),
            dist_max_cm: m_to_cm(dist.iter().copied().fold(0.0, f32::max)),
            e_norm_deg: errors.e_norm_deg,
            within_1cm_pct: within[0] * 100.0,
            within_2cm_pct: within[1] * 100.0,
        })
    }
}

fn read(path: &Path) -> anyhow::Result<TriMesh> {
    geom::io::read_mesh(path).with_context(|| format!("reading {}", path.display()))
}

/// Runs `garnet compare`.
pub fn run(args: &CompareArgs) -> anyhow::Result<()> {
    let reference = read(&args.reference)?;
    let other = read(&args.other)?;
    let c = Comparison::measure(&reference, &other).with_context(|| {
        format!(
            "comparing {} with {}",
            args.other.display(),
            args.reference.display()
        )
    })?;
    println!(
        "{} against {}: {} vertices, E_dist {:.2} cm (p50 {:.2}, p90 {:.2}, max {:.2}), \
         E_norm {:.1} deg, within 1 cm {:.1}%, within 2 cm {:.1}%",
        args.other.display(),
        args.reference.display(),
        c.vertices,
        c.e_dist_cm,
        c.dist_p50_cm,
        c.dist_p90_cm,
        c.dist_max_cm,
        c.e_norm_deg,
        c.within_1cm_pct,
        c.within_2cm_pct
    );
    if let Some(p) = &args.json {
        write_json(p, &c)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit square in the xz plane: faces [0,2,1] and [1,2,3], vertex 1 in both.
    fn square() -> TriMesh {
        TriMesh::grid(2, 2, 1.0)
    }

    /// Hand-computed: lifting one corner of a unit square 3 cm out of its plane moves one
    /// vertex of four (E_dist 0.75 cm) and tilts both faces, right-angled triangles with that
    /// corner at the end of a unit leg, by atan(0.03).
    #[test]
    fn one_moved_corner_gives_the_hand_computed_errors() {
        let a = square();
        let mut b = square();
        b.vertices[1].y = 0.03;
        let c = Comparison::measure(&a, &b).unwrap();
        assert!((c.e_dist_cm - 0.75).abs() < 1e-5, "{c:?}");
        assert!((c.dist_max_cm - 3.0).abs() < 1e-5);
        assert_eq!(c.dist_p50_cm, 0.0);
        assert_eq!(c.within_1cm_pct, 75.0);
        assert_eq!(c.within_2cm_pct, 75.0);
        let tilt = 0.03f32.atan().to_degrees();
        assert!(
            (c.e_norm_deg - tilt).abs() < 1e-3,
            "{} vs {tilt}",
            c.e_norm_deg
        );
        assert_eq!(Comparison::measure(&a, &a).unwrap().e_dist_cm, 0.0);
    }

    #[test]
    fn other_meshes_and_non_finite_vertices_are_refused() {
        let a = square();
        let mut fewer = square();
        fewer.vertices.pop();
        fewer.faces.pop();
        let e = Comparison::measure(&a, &fewer).unwrap_err().to_string();
        assert!(e.contains("not the same garment mesh"), "{e}");
        let mut flipped = square();
        flipped.faces[1] = [1, 3, 2];
        assert!(Comparison::measure(&a, &flipped).is_err());
        let mut nan = square();
        nan.vertices[1].x = f32::NAN;
        let e = Comparison::measure(&a, &nan).unwrap_err().to_string();
        assert!(e.contains("other mesh's vertex 1"), "{e}");
    }
}
