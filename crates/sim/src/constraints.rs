//! Distance constraints (stretch along edges, bending between vertices two edges apart),
//! per-vertex masses, and the per-vertex incidence lists the solver gathers over.

use glam::{DVec3, Vec3};

use crate::error::{Result, SimError};
use crate::params::ClothParams;

/// One constraint as seen from one of its ends (16 bytes: the solver streams these every
/// iteration, so they are kept small; f32 weights and lengths are exact enough for the
/// right-hand side).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Incident {
    /// The other vertex.
    pub other: u32,
    /// Rest length, metres.
    pub rest: f32,
    /// Weight, N/m.
    pub weight: f32,
    /// Whether this is a bending pair (else a stretch edge).
    pub bend: bool,
}

/// The cloth's distance constraints and masses.
#[derive(Clone, Debug)]
pub struct Constraints {
    /// `[C]` vertex pairs: the `n_stretch` edges first (sorted, as
    /// [`geom::adjacency::edges`]), then the bending pairs (as
    /// [`geom::adjacency::two_ring_pairs`]).
    pub pairs: Vec<[u32; 2]>,
    /// `[C]` rest lengths, metres.
    pub rest: Vec<f64>,
    /// `[C]` weights, N/m.
    pub weight: Vec<f64>,
    /// Number of stretch (edge) constraints at the front of `pairs`.
    pub n_stretch: usize,
    /// `[n_stretch]` each edge's stretch modulus as a fraction of the cloth's
    /// ([`ClothParams::stretch_stiffness`]): 1 for the cloth, less for an elastic part.
    pub stretch_scale: Vec<f32>,
    /// `[N]` vertex masses, kg.
    pub mass: Vec<f64>,
    /// `[N+1]` offsets into `incident`.
    pub inc_offsets: Vec<u32>,
    /// Every constraint twice, grouped by vertex: row `i` is
    /// `incident[inc_offsets[i]..inc_offsets[i+1]]`.
    pub incident: Vec<Incident>,
}

/// Each vertex's area (`[N]`, m^2): a third of the area of each incident face.
pub fn vertex_areas(vertices: &[Vec3], faces: &[[u32; 3]]) -> Vec<f64> {
    let mut area = vec![0.0f64; vertices.len()];
    for f in faces {
        let [a, b, c] = f.map(|i| vertices[i as usize].as_dvec3());
        let third = 0.5 * (b - a).cross(c - a).length() / 3.0;
        for &i in f {
            area[i as usize] += third;
        }
    }
    area
}

/// Weights `k * A / r^2` for `pairs` where `A = a_i / n_i + a_j / n_j` (`a`: vertex areas,
/// `n`: constraints of this set at the vertex), so the `A` of a set add up to the surface area.
fn weights(pairs: &[[u32; 2]], rest: &[f64], area: &[f64], k: f64) -> Vec<f64> {
    let mut count = vec![0u32; area.len()];
    for p in pairs {
        count[p[0] as usize] += 1;
        count[p[1] as usize] += 1;
    }
    pairs
        .iter()
        .zip(rest)
        .map(|(&[i, j], &r)| {
            let share = area[i as usize] / count[i as usize] as f64
                + area[j as usize] / count[j as usize] as f64;
            if r > 0.0 {
                k * share / (r * r)
            } else {
                0.0
            }
        })
        .collect()
}

impl Constraints {
    /// Builds the constraints of `rest` (`vertices` `[N]` metres, `faces` `[F]`, validated by
    /// the caller) with `params`' stiffnesses and density. A vertex touching no face gets the
    /// mean vertex mass so the system stays positive definite.
    pub fn new(vertices: &[Vec3], faces: &[[u32; 3]], params: &ClothParams) -> Result<Self> {
        Self::with_stretch_scale(vertices, faces, params, &vec![1.0; vertices.len()])
    }

    /// [`Constraints::new`] with a stretch modulus that varies over the cloth: `scale` (`[N]`,
    /// positive) is each vertex's modulus as a fraction of `params.stretch_stiffness`, and an
    /// edge takes the smaller of its ends' (an elastic band sewn to stiff cloth: the edges
    /// joining them stretch like the band). Errors on a wrong length or a scale that is not
    /// positive and finite, naming the vertex.
    pub fn with_stretch_scale(
        vertices: &[Vec3],
        faces: &[[u32; 3]],
        params: &ClothParams,
        scale: &[f32],
    ) -> Result<Self> {
        let n = vertices.len();
        if scale.len() != n {
            return Err(SimError::InvalidInput(format!(
                "{} stretch scales for {n} vertices",
                scale.len()
            )));
        }
        if let Some(i) = scale.iter().position(|s| !(s.is_finite() && *s > 0.0)) {
            return Err(SimError::InvalidInput(format!(
                "stretch scale of vertex {i} must be positive and finite, got {}",
                scale[i]
            )));
        }
        let edges = geom::adjacency::edges(faces);
        let bends = geom::adjacency::two_ring_pairs(n, faces)?;
        let length =
            |&[i, j]: &[u32; 2]| vertices[i as usize].distance(vertices[j as usize]) as f64;
        let edge_rest: Vec<f64> = edges.iter().map(length).collect();
        let bend_rest: Vec<f64> = bends.iter().map(length).collect();
        if let Some(e) = edges.iter().zip(&edge_rest).position(|(_, &r)| r <= 0.0) {
            return Err(SimError::InvalidMesh(format!(
                "edge {:?} has zero rest length (coincident vertices)",
                edges[e]
            )));
        }
        let area = vertex_areas(vertices, faces);
        let stretch_scale: Vec<f32> = edges
            .iter()
            .map(|&[i, j]| scale[i as usize].min(scale[j as usize]))
            .collect();
        let mut edge_w = weights(&edges, &edge_rest, &area, params.stretch_stiffness as f64);
        for (w, &s) in edge_w.iter_mut().zip(&stretch_scale) {
            *w *= s as f64;
        }
        let bend_w = weights(&bends, &bend_rest, &area, params.bend_stiffness as f64);
        let total: f64 = area.iter().sum();
        let mean_mass = params.density as f64 * total / n.max(1) as f64;
        let mass: Vec<f64> = area
            .iter()
            .map(|&a| {
                let m = params.density as f64 * a;
                if m > 0.0 {
                    m
                } else {
                    mean_mass.max(1e-9)
                }
            })
            .collect();
        let n_stretch = edges.len();
        let mut pairs = edges;
        pairs.extend_from_slice(&bends);
        let mut rest = edge_rest;
        rest.extend_from_slice(&bend_rest);
        edge_w.extend_from_slice(&bend_w);
        let weight = edge_w;
        // Incidence lists.
        let mut inc_offsets = vec![0u32; n + 1];
        for p in &pairs {
            inc_offsets[p[0] as usize + 1] += 1;
            inc_offsets[p[1] as usize + 1] += 1;
        }
        for i in 0..n {
            inc_offsets[i + 1] += inc_offsets[i];
        }
        let mut fill = inc_offsets.clone();
        let empty = Incident {
            other: 0,
            rest: 0.0,
            weight: 0.0,
            bend: false,
        };
        let mut incident = vec![empty; pairs.len() * 2];
        for (c, &[i, j]) in pairs.iter().enumerate() {
            for (a, b) in [(i, j), (j, i)] {
                let slot = &mut fill[a as usize];
                incident[*slot as usize] = Incident {
                    other: b,
                    rest: rest[c] as f32,
                    weight: weight[c] as f32,
                    bend: c >= n_stretch,
                };
                *slot += 1;
            }
        }
        Ok(Constraints {
            pairs,
            rest,
            weight,
            n_stretch,
            stretch_scale,
            mass,
            inc_offsets,
            incident,
        })
    }

    /// Whether stretch edge `c` (`< n_stretch`) is elastic: softer than the cloth.
    #[inline]
    pub fn is_elastic(&self, c: usize) -> bool {
        self.stretch_scale[c] < 1.0
    }

    /// The constraints at vertex `i` (each seen from `i`).
    #[inline]
    pub fn at(&self, i: usize) -> &[Incident] {
        &self.incident[self.inc_offsets[i] as usize..self.inc_offsets[i + 1] as usize]
    }

    /// Elastic energy `sum 1/2 w (|x_a - x_b| - r)^2` of positions `x` (`[N]`), joules.
    pub fn energy(&self, x: &[DVec3]) -> f64 {
        self.pairs
            .iter()
            .zip(&self.rest)
            .zip(&self.weight)
            .map(|((&[a, b], &r), &w)| {
                let l = x[a as usize].distance(x[b as usize]);
                0.5 * w * (l - r) * (l - r)
            })
            .sum()
    }

    /// Strains `[n_stretch]` of the edges: length / rest - 1.
    pub fn strains(&self, x: &[Vec3]) -> Vec<f32> {
        self.pairs[..self.n_stretch]
            .iter()
            .zip(&self.rest)
            .map(|(&[a, b], &r)| (x[a as usize].distance(x[b as usize]) as f64 / r - 1.0) as f32)
            .collect()
    }

    /// Strain of each vertex `[N]`: the largest strain (length / rest - 1) of its stretch
    /// edges at positions `x` (`[N]`), elastic edges (stretch scale under 1) left out; 0 for
    /// a vertex without such edges.
    pub fn vertex_strains(&self, x: &[Vec3]) -> Vec<f32> {
        let mut out = vec![0.0f32; self.mass.len()];
        let strains = self.strains(x);
        for (c, &[a, b]) in self.pairs[..self.n_stretch].iter().enumerate() {
            if self.is_elastic(c) {
                continue;
            }
            for v in [a as usize, b as usize] {
                out[v] = out[v].max(strains[c]);
            }
        }
        out
    }

    /// Sum of the stretch weights at each vertex (`[N]`, N/m): the scale of the cloth's
    /// stiffness there.
    pub fn stretch_diag(&self) -> Vec<f64> {
        let mut d = vec![0.0; self.mass.len()];
        for (c, &[a, b]) in self.pairs[..self.n_stretch].iter().enumerate() {
            d[a as usize] += self.weight[c];
            d[b as usize] += self.weight[c];
        }
        d
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use geom::TriMesh;

    #[test]
    fn shares_add_up_to_area_and_energy_is_zero_at_rest() {
        let m = TriMesh::grid(7, 5, 0.1);
        let p = ClothParams {
            stretch_stiffness: 3.0,
            bend_stiffness: 5.0,
            ..Default::default()
        };
        let c = Constraints::new(&m.vertices, &m.faces, &p).unwrap();
        let area = m.surface_area() as f64;
        for (range, k) in [(0..c.n_stretch, 3.0), (c.n_stretch..c.pairs.len(), 5.0)] {
            let sum: f64 = range.map(|i| c.weight[i] * c.rest[i] * c.rest[i] / k).sum();
            assert!((sum - area).abs() < 1e-6 * area.max(1.0), "{sum} vs {area}");
        }
        let mass: f64 = c.mass.iter().sum();
        assert!((mass - 0.15 * area).abs() < 1e-6);
        let x: Vec<DVec3> = m.vertices.iter().map(|v| v.as_dvec3()).collect();
        assert!(c.energy(&x).abs() < 1e-15);
        assert!(c.strains(&m.vertices).iter().all(|s| s.abs() < 1e-6));
        assert_eq!(c.incident.len(), 2 * c.pairs.len());
    }

    #[test]
    fn vertex_strain_is_the_largest_of_its_edges() {
        let m = TriMesh::grid(4, 3, 0.1);
        let c = Constraints::new(&m.vertices, &m.faces, &ClothParams::default()).unwrap();
        let scaled = |sx: f32| -> Vec<Vec3> {
            m.vertices
                .iter()
                .map(|v| Vec3::new(v.x * sx, v.y, v.z))
                .collect()
        };
        // Stretched 10% along x: every vertex has an edge along x, diagonals stretch less.
        for s in c.vertex_strains(&scaled(1.1)) {
            assert!((s - 0.1).abs() < 1e-5, "{s}");
        }
        // Compressed along x: the largest is the unchanged edge along z.
        for s in c.vertex_strains(&scaled(0.9)) {
            assert!(s.abs() < 1e-6, "{s}");
        }
    }

    #[test]
    fn an_edge_takes_the_softer_of_its_ends_stretch_scale() {
        let m = TriMesh::grid(5, 4, 0.1);
        let p = ClothParams::default();
        let plain = Constraints::new(&m.vertices, &m.faces, &p).unwrap();
        // The first row of vertices is elastic, half as stiff.
        let scale: Vec<f32> = m
            .vertices
            .iter()
            .map(|v| if v.z < -0.1 { 0.5 } else { 1.0 })
            .collect();
        let c = Constraints::with_stretch_scale(&m.vertices, &m.faces, &p, &scale).unwrap();
        assert_eq!(c.pairs, plain.pairs);
        let mut elastic = 0;
        for (k, &[a, b]) in c.pairs.iter().enumerate() {
            let expected = if k < c.n_stretch {
                let s = scale[a as usize].min(scale[b as usize]);
                assert_eq!(c.stretch_scale[k], s);
                elastic += (s < 1.0) as usize;
                plain.weight[k] * s as f64
            } else {
                plain.weight[k]
            };
            assert!((c.weight[k] - expected).abs() < 1e-9 * expected, "{k}");
        }
        assert!(elastic > 0 && elastic < c.n_stretch);
        // Stretched along x, the elastic edges count for no vertex's strain: the elastic
        // row's vertices have only elastic edges.
        let x: Vec<Vec3> = m
            .vertices
            .iter()
            .map(|v| Vec3::new(v.x * 1.1, v.y, v.z))
            .collect();
        for (s, k) in c.vertex_strains(&x).into_iter().zip(&scale) {
            let expected = if *k < 1.0 { 0.0 } else { 0.1 };
            assert!((s - expected).abs() < 1e-5, "{s} for scale {k}");
        }
        for bad in [
            vec![1.0; 3],
            vec![0.0; scale.len()],
            vec![f32::NAN; scale.len()],
        ] {
            let e = Constraints::with_stretch_scale(&m.vertices, &m.faces, &p, &bad);
            assert!(matches!(e, Err(SimError::InvalidInput(_))), "{e:?}");
        }
    }
}
