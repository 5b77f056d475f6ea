//! Plain reference versions of the optimised kernels, for tests: a dense Cholesky solve (the
//! check of the sparse factorisation) and a sequential projective dynamics step with dense
//! matrices (the check of [`crate::ClothSim::step`] without a body and without acceleration).
//! O(n^3) in time and O(n^2) in memory: small meshes only.

use geom::TriMesh;
use glam::{DVec3, Vec3};

use crate::constraints::Constraints;
use crate::error::{Result, SimError};
use crate::params::ClothParams;

/// Solves `A x = b` in place for a dense symmetric positive definite `a` (row-major
/// `[n * n]`) and `b` (`[n]`) by a plain Cholesky factorisation `A = L L^T`. Fails when the
/// lengths do not match or `A` is not positive definite.
pub fn dense_cholesky_solve(a: &[f64], b: &mut [f64]) -> Result<()> {
    let n = b.len();
    if a.len() != n * n {
        return Err(SimError::InvalidInput(format!(
            "dense matrix of {} entries for {n} unknowns",
            a.len()
        )));
    }
    let mut l = vec![0.0f64; n * n];
    for j in 0..n {
        let mut d = a[j * n + j];
        for k in 0..j {
            d -= l[j * n + k] * l[j * n + k];
        }
        if d <= 0.0 || !d.is_finite() {
            return Err(SimError::Solver(format!(
                "dense Cholesky: pivot {j} is {d} (not positive definite)"
            )));
        }
        let d = d.sqrt();
        l[j * n + j] = d;
        for i in j + 1..n {
            let mut s = a[i * n + j];
            for k in 0..j {
                s -= l[i * n + k] * l[j * n + k];
            }
            l[i * n + j] = s / d;
        }
    }
    for i in 0..n {
        let mut s = b[i];
        for k in 0..i {
            s -= l[i * n + k] * b[k];
        }
        b[i] = s / l[i * n + i];
    }
    for i in (0..n).rev() {
        let mut s = b[i];
        for k in i + 1..n {
            s -= l[k * n + i] * b[k];
        }
        b[i] = s / l[i * n + i];
    }
    Ok(())
}

/// One projective dynamics step of the cloth `rest` (`[N]` vertices, `[F]` faces) from
/// positions `x` and velocities `v` (`[N]` each) with `pinned` (`[N]`) vertices held in
/// place, `iterations` local/global iterations, no body, no acceleration: the same
/// algorithm as [`crate::ClothSim::step`] written plainly, with constraint data in f64 and
/// dense matrices. With `split_bending` the bending pairs' off-diagonal entries are taken from
/// the iterate, as the optimised solver does; without, they are in the matrix (plain
/// projective dynamics: a different iteration with the same fixed point). Returns the new
/// positions and velocities `[N]`.
pub fn plain_step(
    rest: &TriMesh,
    params: &ClothParams,
    x: &[Vec3],
    v: &[Vec3],
    pinned: &[bool],
    iterations: u32,
    split_bending: bool,
) -> Result<(Vec<Vec3>, Vec<Vec3>)> {
    let n = rest.vertices.len();
    if x.len() != n || v.len() != n || pinned.len() != n {
        return Err(SimError::InvalidInput(
            "state arrays must have N entries".into(),
        ));
    }
    let cons = Constraints::new(&rest.vertices, &rest.faces, params)?;
    let h = params.dt as f64;
    let inv_h2 = 1.0 / (h * h);
    let drag = 1.0 / (1.0 + params.damping as f64 * h);
    let g = params.gravity.as_dvec3();
    let free: Vec<usize> = (0..n).filter(|&i| !pinned[i]).collect();
    let mut fidx = vec![usize::MAX; n];
    for (k, &i) in free.iter().enumerate() {
        fidx[i] = k;
    }
    let nf = free.len();
    let y: Vec<DVec3> = (0..n)
        .map(|i| {
            let xi = x[i].as_dvec3();
            if pinned[i] {
                xi
            } else {
                xi + h * drag * v[i].as_dvec3() + h * h * g
            }
        })
        .collect();
    let in_matrix = |c: usize| c < cons.n_stretch || !split_bending;
    let mut a = vec![0.0f64; nf * nf];
    for (k, &i) in free.iter().enumerate() {
        a[k * nf + k] += cons.mass[i] * inv_h2;
    }
    for (c, &[p, q]) in cons.pairs.iter().enumerate() {
        let w = cons.weight[c];
        let (fp, fq) = (fidx[p as usize], fidx[q as usize]);
        if fp != usize::MAX {
            a[fp * nf + fp] += w;
        }
        if fq != usize::MAX {
            a[fq * nf + fq] += w;
        }
        if fp != usize::MAX && fq != usize::MAX && in_matrix(c) {
            a[fp * nf + fq] -= w;
            a[fq * nf + fp] -= w;
        }
    }
    let mut xs: Vec<DVec3> = (0..n)
        .map(|i| if pinned[i] { y[i] } else { y[i] - h * h * g })
        .collect();
    for _ in 0..iterations {
        let mut rhs: Vec<DVec3> = free.iter().map(|&i| cons.mass[i] * inv_h2 * y[i]).collect();
        for (c, &[p, q]) in cons.pairs.iter().enumerate() {
            let (p, q) = (p as usize, q as usize);
            let w = cons.weight[c];
            let d = xs[p] - xs[q];
            let l = d.length();
            let proj = if l > 1e-12 {
                d * (cons.rest[c] / l)
            } else {
                DVec3::ZERO
            };
            // Each end: w * (projection toward itself) + w * (the other end when that
            // coupling is not in the matrix).
            for (me, other, sign) in [(p, q, 1.0), (q, p, -1.0)] {
                let k = fidx[me];
                if k == usize::MAX {
                    continue;
                }
                rhs[k] += w * sign * proj;
                if pinned[other] || !in_matrix(c) {
                    rhs[k] += w * xs[other];
                }
            }
        }
        for axis in 0..3 {
            let mut b: Vec<f64> = rhs.iter().map(|r| r[axis]).collect();
            dense_cholesky_solve(&a, &mut b)?;
            for (k, &i) in free.iter().enumerate() {
                xs[i][axis] = b[k];
            }
        }
    }
    let x1: Vec<Vec3> = xs.iter().map(|p| p.as_vec3()).collect();
    let v1: Vec<Vec3> = (0..n).map(|i| (x1[i] - x[i]) / params.dt).collect();
    Ok((x1, v1))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::{ScalarPattern, SpdSolver};
    use crate::ClothSim;

    /// A small crumpled cloth: a grid with a deterministic out-of-plane wave.
    fn wavy(nx: usize) -> (TriMesh, Vec<Vec3>) {
        let m = TriMesh::grid(nx, nx, 0.02);
        let x = m
            .vertices
            .iter()
            .map(|p| p + Vec3::new(0.0, 0.01 * (40.0 * p.x).sin() * (30.0 * p.z).cos(), 0.0))
            .collect();
        (m, x)
    }

    #[test]
    fn sparse_cholesky_matches_dense() {
        // The system matrix of a small cloth plus some contact weights.
        let (m, _) = wavy(7);
        let p = ClothParams::default();
        let c = Constraints::new(&m.vertices, &m.faces, &p).unwrap();
        let n = m.vertices.len();
        let pairs: Vec<(u32, u32)> = c.pairs[..c.n_stretch]
            .iter()
            .map(|&[a, b]| (a, b))
            .collect();
        let pat = ScalarPattern::new(n, &pairs).unwrap();
        let mut values = vec![0.0; pat.nnz()];
        let h2 = (p.dt as f64).powi(2);
        for i in 0..n {
            values[pat.diag(i)] = c.mass[i] / h2 + if i % 5 == 0 { 7.0 } else { 0.0 };
        }
        for (k, &(a, b)) in pairs.iter().enumerate() {
            let w = c.weight[k];
            values[pat.off[k] as usize] -= w;
            values[pat.diag(a as usize)] += w;
            values[pat.diag(b as usize)] += w;
        }
        let mut s = SpdSolver::new(n, pat.col_ptr.clone(), pat.row_idx.clone()).unwrap();
        s.factor(&values).unwrap();
        let dense = s.to_dense(&values);
        let rhs: Vec<f64> = (0..3 * n)
            .map(|i| ((i * 37 % 11) as f64 - 5.0) * 0.1)
            .collect();
        let mut sparse = rhs.clone();
        s.solve_in_place(&mut sparse, 3).unwrap();
        let scale = sparse.iter().fold(0.0f64, |a, b| a.max(b.abs()));
        for col in 0..3 {
            let mut b = rhs[col * n..(col + 1) * n].to_vec();
            dense_cholesky_solve(&dense, &mut b).unwrap();
            for i in 0..n {
                let d = (b[i] - sparse[col * n + i]).abs();
                assert!(
                    d <= 1e-9 * scale,
                    "column {col} row {i}: {} vs {}",
                    b[i],
                    sparse[col * n + i]
                );
            }
        }
        // And the product reproduces the right-hand side.
        let mut back = vec![0.0; n];
        s.mul(&values, &sparse[..n], &mut back);
        for i in 0..n {
            assert!((back[i] - rhs[i]).abs() < 1e-9, "{} vs {}", back[i], rhs[i]);
        }
    }

    #[test]
    fn dense_cholesky_rejects_indefinite() {
        let mut b = vec![1.0, 1.0];
        assert!(dense_cholesky_solve(&[1.0, 2.0, 2.0, 1.0], &mut b).is_err());
        assert!(dense_cholesky_solve(&[1.0], &mut b).is_err());
    }

    #[test]
    fn optimised_step_matches_plain_step() {
        let (m, x) = wavy(8);
        let params = ClothParams {
            chebyshev_rho: 0.0,
            iterations: 5,
            ..Default::default()
        };
        let n = m.vertices.len();
        let mut pinned = vec![false; n];
        pinned[0] = true;
        pinned[7] = true;
        let v: Vec<Vec3> = (0..n)
            .map(|i| {
                if pinned[i] {
                    Vec3::ZERO
                } else {
                    Vec3::new(0.01 * (i % 3) as f32, 0.0, 0.02)
                }
            })
            .collect();
        let mut sim = ClothSim::new(&m, &params).unwrap();
        sim.set_positions(&x).unwrap();
        sim.set_pinned(&[0, 7]).unwrap();
        // set_positions zeroes velocities; reach the same state by a reference velocity of
        // zero and compare two steps.
        let mut rx = x.clone();
        let mut rv = vec![Vec3::ZERO; n];
        for _ in 0..2 {
            sim.step(None).unwrap();
            let (nx, nv) = plain_step(&m, &params, &rx, &rv, &pinned, 5, true).unwrap();
            rx = nx;
            rv = nv;
        }
        let _ = v;
        for i in 0..n {
            let d = sim.positions()[i].distance(rx[i]);
            assert!(
                d < 2e-6,
                "vertex {i}: {} vs {} ({d})",
                sim.positions()[i],
                rx[i]
            );
            let dv = sim.velocities()[i].distance(rv[i]);
            assert!(
                dv < 2e-4,
                "vertex {i} velocity: {} vs {}",
                sim.velocities()[i],
                rv[i]
            );
        }
    }

    #[test]
    fn split_solve_gives_the_same_steps_to_the_bit() {
        let (m, x) = wavy(8);
        let run = |split_solve: bool| {
            let params = ClothParams {
                split_solve,
                ..Default::default()
            };
            let mut sim = ClothSim::new(&m, &params).unwrap();
            sim.set_positions(&x).unwrap();
            sim.set_pinned(&[0, 7]).unwrap();
            for _ in 0..3 {
                sim.step(None).unwrap();
            }
            sim.positions().to_vec()
        };
        let (split, single) = (run(true), run(false));
        assert!(split.iter().zip(&x).any(|(a, b)| a != b), "the cloth moved");
        assert_eq!(split, single);
    }

    #[test]
    fn split_bending_has_the_same_fixed_point() {
        // Both iterations converge to the same step: their difference shrinks with the
        // iteration count.
        let (m, x) = wavy(6);
        let params = ClothParams {
            bend_stiffness: 50.0,
            ..Default::default()
        };
        let n = m.vertices.len();
        let mut pinned = vec![false; n];
        pinned[0] = true;
        let v = vec![Vec3::ZERO; n];
        let diff = |iters: u32| {
            let (a, _) = plain_step(&m, &params, &x, &v, &pinned, iters, true).unwrap();
            let (b, _) = plain_step(&m, &params, &x, &v, &pinned, iters, false).unwrap();
            (0..n).map(|i| a[i].distance(b[i])).fold(0.0f32, f32::max)
        };
        let (d1, d2) = (diff(500), diff(4000));
        assert!(d2 < 0.3 * d1 && d2 < 3e-5, "{d1} then {d2}");
    }
}
