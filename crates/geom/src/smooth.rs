//! Laplacian and Taubin smoothing of vertex positions over the 1-ring.
//!
//! One step moves every free vertex `x_i` toward the weighted mean of its neighbours:
//! `x_i += f * (sum_j w_ij x_j / sum_j w_ij - x_i)`, all vertices at once (Jacobi), so the
//! result does not depend on vertex order. Plain Laplacian smoothing (`f = lambda` every step)
//! shrinks a surface; Taubin smoothing alternates a shrinking step `lambda > 0` with an
//! inflating step `mu < -lambda`, which removes noise without shrinking (Taubin, "A signal
//! processing approach to fair surface design", SIGGRAPH 1995).
//!
//! Weights ([`LaplacianWeights`]) are uniform or inverse edge length; no cotangents, so the
//! operator is well behaved on badly shaped triangles. Boundary vertices (on an edge with one
//! face) are pinned, smoothed only along their boundary loop (a 1-D Laplacian over their two
//! loop neighbours, so an opening keeps its place on the surface), or treated like interior
//! vertices ([`BoundarySmoothing`]). A per-vertex pin mask fixes any other vertex.
//!
//! Positions are `[N]` of [`glam::Vec3`] in metres; faces `[F]`.

use glam::Vec3;

use crate::adjacency::{one_ring, Csr, EdgeTopology};
use crate::error::{GeomError, Result};
use crate::mesh::TriMesh;

/// Neighbour weights of the Laplacian.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LaplacianWeights {
    /// Every neighbour counts the same (the "umbrella" operator).
    #[default]
    Uniform,
    /// Neighbour `j` weighs `1 / |x_j - x_i|` (Fujiwara's scale-dependent umbrella), which
    /// moves vertices less along the edges of a non-uniform mesh and so keeps its sampling.
    InverseEdgeLength,
}

/// What happens to boundary vertices (on an edge that has a single face).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BoundarySmoothing {
    /// Boundary vertices do not move.
    Pinned,
    /// Each boundary vertex is smoothed over its two neighbours along the boundary loop only
    /// (a 1-D Laplacian of the loop): the loop gets smoother and evenly spaced but does not
    /// shrink into the surface. A boundary vertex with other than two boundary neighbours (a
    /// non-manifold pinch) stays pinned (the default).
    #[default]
    AlongLoop,
    /// Boundary vertices are smoothed over their whole 1-ring like interior ones; this pulls
    /// openings inward.
    Free,
}

/// Options of [`Smoother::smooth`], [`laplacian_smooth`] and [`taubin_smooth`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SmoothOptions {
    /// Number of steps; a Taubin iteration is two steps (lambda then mu) counted once.
    pub iterations: u32,
    /// Step factor of the smoothing step, in (0, 1] (0.5 is usual).
    pub lambda: f32,
    /// Taubin's inflating factor, negative with `|mu| > lambda` (-0.53 with lambda 0.5 is
    /// usual); `None` for plain Laplacian smoothing.
    pub mu: Option<f32>,
    /// Neighbour weights.
    pub weights: LaplacianWeights,
    /// Boundary treatment.
    pub boundary: BoundarySmoothing,
}

impl SmoothOptions {
    /// Plain Laplacian smoothing: `iterations` steps of factor `lambda`, uniform weights,
    /// boundaries smoothed along their loops.
    pub fn laplacian(iterations: u32, lambda: f32) -> Self {
        SmoothOptions {
            iterations,
            lambda,
            mu: None,
            weights: LaplacianWeights::Uniform,
            boundary: BoundarySmoothing::AlongLoop,
        }
    }

    /// Taubin smoothing with lambda 0.5, mu -0.53 (pass-band about 0.1), uniform weights,
    /// boundaries smoothed along their loops.
    pub fn taubin(iterations: u32) -> Self {
        SmoothOptions {
            iterations,
            lambda: 0.5,
            mu: Some(-0.53),
            weights: LaplacianWeights::Uniform,
            boundary: BoundarySmoothing::AlongLoop,
        }
    }

    fn check(&self) -> Result<()> {
        let ok = self.lambda.is_finite() && self.mu.is_none_or(f32::is_finite);
        if !ok {
            return Err(GeomError::InvalidInput(format!(
                "smoothing factors must be finite (lambda {}, mu {:?})",
                self.lambda, self.mu
            )));
        }
        Ok(())
    }
}

/// Marker for "no loop neighbours" in [`Smoother`].
const NONE: u32 = u32::MAX;

/// The connectivity smoothing needs, built once per mesh and reused across calls.
#[derive(Clone, Debug)]
pub struct Smoother {
    /// 1-ring neighbours.
    ring: Csr,
    /// `[N]` whether the vertex is on a boundary edge.
    boundary: Vec<bool>,
    /// `[N]` the two boundary neighbours of a boundary vertex; `[NONE, NONE]` otherwise or
    /// when it does not have exactly two.
    loop_nbrs: Vec<[u32; 2]>,
}

impl Smoother {
    /// Prepares smoothing of meshes with these `[F]` faces over `n_vertices` vertices.
    /// Fails on an out-of-range index.
    pub fn new(n_vertices: usize, faces: &[[u32; 3]]) -> Result<Self> {
        let ring = one_ring(n_vertices, faces)?;
        let topo = EdgeTopology::new(n_vertices, faces)?;
        let mut boundary = vec![false; n_vertices];
        let mut loop_nbrs = vec![[NONE, NONE]; n_vertices];
        let mut count = vec![0u8; n_vertices];
        for e in topo.boundary_edges() {
            let [a, b] = topo.edges[e as usize];
            for (v, w) in [(a, b), (b, a)] {
                boundary[v as usize] = true;
                let c = &mut count[v as usize];
                if *c < 2 {
                    loop_nbrs[v as usize][*c as usize] = w;
                }
                *c = c.saturating_add(1);
            }
        }
        for (nb, &c) in loop_nbrs.iter_mut().zip(&count) {
            if c != 2 {
                *nb = [NONE, NONE];
            }
        }
        Ok(Smoother {
            ring,
            boundary,
            loop_nbrs,
        })
    }

    /// Number of vertices N the smoother was built for.
    pub fn num_vertices(&self) -> usize {
        self.boundary.len()
    }

    /// Whether vertex `v` is on a boundary edge (`false` when out of range).
    pub fn is_boundary(&self, v: usize) -> bool {
        self.boundary.get(v).copied().unwrap_or(false)
    }

    /// Smooths `vertices` (`[N]`, metres) in place. `pinned`, if given (`[N]`), fixes the
    /// vertices marked `true`. Fails (leaving `vertices` unchanged) on a length mismatch or
    /// non-finite factors.
    pub fn smooth(
        &self,
        vertices: &mut [Vec3],
        opts: &SmoothOptions,
        pinned: Option<&[bool]>,
    ) -> Result<()> {
        let n = self.num_vertices();
        if vertices.len() != n || pinned.is_some_and(|p| p.len() != n) {
            return Err(GeomError::InvalidInput(format!(
                "smoother built for {n} vertices, got {} positions and {:?} pin flags",
                vertices.len(),
                pinned.map(<[bool]>::len)
            )));
        }
        opts.check()?;
        let mut scratch = vertices.to_vec();
        for _ in 0..opts.iterations {
            self.step(vertices, &mut scratch, opts.lambda, opts, pinned);
            if let Some(mu) = opts.mu {
                self.step(vertices, &mut scratch, mu, opts, pinned);
            }
        }
        Ok(())
    }

    /// One Jacobi step of factor `f`: reads `x`, writes into `out`, then swaps back into `x`.
    fn step(
        &self,
        x: &mut [Vec3],
        out: &mut [Vec3],
        f: f32,
        opts: &SmoothOptions,
        pinned: Option<&[bool]>,
    ) {
        for (i, o) in out.iter_mut().enumerate() {
            let p = x[i];
            *o = p;
            if pinned.is_some_and(|m| m[i]) {
                continue;
            }
            let ring: &[u32] = if self.boundary[i] {
                match opts.boundary {
                    BoundarySmoothing::Pinned => continue,
                    BoundarySmoothing::AlongLoop if self.loop_nbrs[i][0] == NONE => continue,
                    BoundarySmoothing::AlongLoop => &self.loop_nbrs[i],
                    BoundarySmoothing::Free => self.ring.row(i),
                }
            } else {
                self.ring.row(i)
            };
            let mut sum = Vec3::ZERO;
            let mut wsum = 0f32;
            for &j in ring {
                let q = x[j as usize];
                let w = match opts.weights {
                    LaplacianWeights::Uniform => 1.0,
                    LaplacianWeights::InverseEdgeLength => 1.0 / q.distance(p).max(1e-12),
                };
                sum += w * q;
                wsum += w;
            }
            if wsum > 0.0 {
                *o = p + f * (sum / wsum - p);
            }
        }
        x.copy_from_slice(out);
    }
}

/// Plain Laplacian smoothing of `mesh` with `opts` (its `mu` is ignored): new positions `[N]`.
/// `pinned` as in [`Smoother::smooth`].
pub fn laplacian_smooth(
    mesh: &TriMesh,
    opts: &SmoothOptions,
    pinned: Option<&[bool]>,
) -> Result<Vec<Vec3>> {
    let opts = SmoothOptions { mu: None, ..*opts };
    let mut v = mesh.vertices.clone();
    Smoother::new(v.len(), &mesh.faces)?.smooth(&mut v, &opts, pinned)?;
    Ok(v)
}

/// Taubin smoothing of `mesh` with `opts` (its `mu` defaults to -0.53 when `None`): new
/// positions `[N]`. `pinned` as in [`Smoother::smooth`].
pub fn taubin_smooth(
    mesh: &TriMesh,
    opts: &SmoothOptions,
    pinned: Option<&[bool]>,
) -> Result<Vec<Vec3>> {
    let opts = SmoothOptions {
        mu: Some(opts.mu.unwrap_or(-0.53)),
        ..*opts
    };
    let mut v = mesh.vertices.clone();
    Smoother::new(v.len(), &mesh.faces)?.smooth(&mut v, &opts, pinned)?;
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit icosphere with deterministic radial noise of +-`amp`.
    fn noisy_sphere(amp: f32) -> TriMesh {
        let mut m = TriMesh::icosphere(3, 1.0);
        let mut s = 7u64;
        for v in &mut m.vertices {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let r = ((s >> 40) as f32 / (1u64 << 24) as f32 - 0.5) * 2.0;
            *v *= 1.0 + amp * r;
        }
        m
    }

    fn radii(v: &[Vec3]) -> (f32, f32) {
        let n = v.len() as f32;
        let mean = v.iter().map(|p| p.length()).sum::<f32>() / n;
        let sd = (v.iter().map(|p| (p.length() - mean).powi(2)).sum::<f32>() / n).sqrt();
        (mean, sd)
    }

    #[test]
    fn taubin_denoises_without_shrinking() {
        let m = noisy_sphere(0.03);
        let (r0, sd0) = radii(&m.vertices);
        let lap = laplacian_smooth(&m, &SmoothOptions::laplacian(30, 0.5), None).unwrap();
        let tau = taubin_smooth(&m, &SmoothOptions::taubin(30), None).unwrap();
        let (rl, sdl) = radii(&lap);
        let (rt, sdt) = radii(&tau);
        assert!(sdl < 0.4 * sd0 && sdt < 0.4 * sd0, "{sd0} {sdl} {sdt}");
        assert!(rl < r0 - 0.03, "Laplacian should shrink: {r0} -> {rl}");
        // Taubin's pass band keeps (even slightly inflates) the lowest frequencies.
        assert!(
            (rt - r0).abs() < 0.015,
            "Taubin should not shrink: {r0} -> {rt}"
        );
        assert!((rt - r0).abs() < 0.25 * (rl - r0).abs(), "{r0} {rl} {rt}");
        for w in [
            LaplacianWeights::Uniform,
            LaplacianWeights::InverseEdgeLength,
        ] {
            let o = SmoothOptions {
                weights: w,
                ..SmoothOptions::taubin(10)
            };
            let (_, sd) = radii(&taubin_smooth(&m, &o, None).unwrap());
            assert!(sd < 0.5 * sd0, "{w:?}");
        }
    }

    #[test]
    fn pins_and_boundary_modes() {
        // A flat grid whose boundary vertices are shifted along their side: along-loop
        // smoothing keeps them on the side lines and evens their spacing; interior vertices
        // stay in the plane; pinned corners and pinned vertices do not move.
        let mut g = TriMesh::grid(9, 9, 0.1);
        let half = 0.4f32;
        for (i, v) in g.vertices.iter_mut().enumerate() {
            let on_x = (v.x.abs() - half).abs() < 1e-6;
            let on_z = (v.z.abs() - half).abs() < 1e-6;
            if on_x != on_z {
                let d = 0.03 * if i % 2 == 0 { 1.0 } else { -1.0 };
                if on_x {
                    v.z += d;
                } else {
                    v.x += d;
                }
            }
        }
        let corners: Vec<bool> = g
            .vertices
            .iter()
            .map(|v| (v.x.abs() - half).abs() < 1e-6 && (v.z.abs() - half).abs() < 1e-6)
            .collect();
        let mut pins = corners.clone();
        pins[40] = true; // the centre
        let out = laplacian_smooth(&g, &SmoothOptions::laplacian(200, 0.5), Some(&pins)).unwrap();
        for (i, (a, b)) in g.vertices.iter().zip(&out).enumerate() {
            assert!(b.y.abs() < 1e-6);
            if pins[i] {
                assert_eq!(a, b);
            }
            let on_x = (a.x.abs() - half).abs() < 1e-6;
            let on_z = (a.z.abs() - half).abs() < 1e-6;
            if on_x {
                assert!((b.x - a.x).abs() < 1e-6);
            }
            if on_z {
                assert!((b.z - a.z).abs() < 1e-6);
            }
            if on_x != on_z {
                // Evenly spaced along the side again.
                let t = if on_x { b.z } else { b.x };
                assert!((t / 0.1 - (t / 0.1).round()).abs() < 1e-3, "{i}: {b}");
            }
        }
        let o = SmoothOptions {
            boundary: BoundarySmoothing::Pinned,
            ..SmoothOptions::taubin(5)
        };
        let out = taubin_smooth(&g, &o, None).unwrap();
        let s = Smoother::new(81, &g.faces).unwrap();
        for (i, (o, v)) in out.iter().zip(&g.vertices).enumerate() {
            if s.is_boundary(i) {
                assert_eq!(o, v);
            }
        }
        let o = SmoothOptions {
            boundary: BoundarySmoothing::Free,
            ..SmoothOptions::laplacian(20, 0.5)
        };
        let out = laplacian_smooth(&g, &o, None).unwrap();
        assert!(
            out[0].length() < g.vertices[0].length() - 0.05,
            "free corners move in"
        );
    }

    #[test]
    fn bad_input() {
        let g = TriMesh::grid(3, 3, 1.0);
        let s = Smoother::new(9, &g.faces).unwrap();
        let mut v = g.vertices.clone();
        assert!(s
            .smooth(&mut v[..5], &SmoothOptions::taubin(1), None)
            .is_err());
        let pins = [false; 3];
        assert!(s
            .smooth(&mut v, &SmoothOptions::taubin(1), Some(&pins))
            .is_err());
        let nan = SmoothOptions::laplacian(1, f32::NAN);
        assert!(s.smooth(&mut v, &nan, None).is_err());
        assert_eq!(v, g.vertices);
        assert!(Smoother::new(3, &g.faces).is_err());
    }
}
