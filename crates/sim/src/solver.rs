//! Sparse symmetric positive definite solves: a fixed sparsity pattern (lower triangle, CSC),
//! its symbolic Cholesky factorisation computed once (faer, AMD ordering), numeric
//! refactorisations as the values change, and solves.
//!
//! [`ScalarPattern`] lays out the cloth's `[n, n]` system matrix (a diagonal entry per free
//! vertex, an off-diagonal one per stretch edge between free vertices) with the position of
//! every entry in the value array, so assembling it is a scatter into known slots.
//!
//! f64 throughout: the matrix mixes a mass term `m / h^2` (about 0.05 N/m for a 1 cm cloth
//! vertex at 60 steps per second) with stretch weights near 1e3 N/m and contact weights, a
//! spread that f32 pivots would resolve poorly. Its tests are in [`crate::reference`]
//! (sparse against dense).

use faer::linalg::solvers::SolveCore;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Side};

use crate::error::{Result, SimError};

/// A symmetric `[n, n]` sparsity pattern (lower triangle, CSC with sorted rows) with its
/// symbolic Cholesky factorisation and, once [`SpdSolver::factor`] succeeded, a numeric one.
#[derive(Clone)]
pub struct SpdSolver {
    n: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    symbolic: SymbolicLlt<usize>,
    llt: Option<Llt<usize, f64>>,
}

impl std::fmt::Debug for SpdSolver {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SpdSolver")
            .field("n", &self.n)
            .field("nnz_lower", &self.row_idx.len())
            .field("factored", &self.llt.is_some())
            .finish()
    }
}

fn llt_error(e: impl std::fmt::Display) -> SimError {
    SimError::Solver(format!("sparse Cholesky failed: {e}"))
}

impl SpdSolver {
    /// The symbolic factorisation of the pattern `col_ptr` (`[n+1]`) / `row_idx` (`[nnz]`,
    /// rows `>=` their column, sorted within a column). Fails on an invalid pattern.
    pub fn new(n: usize, col_ptr: Vec<usize>, row_idx: Vec<usize>) -> Result<Self> {
        let ok = col_ptr.len() == n + 1
            && col_ptr.first() == Some(&0)
            && col_ptr.last() == Some(&row_idx.len())
            && col_ptr.windows(2).all(|w| w[0] <= w[1])
            && (0..n).all(|c| {
                let rows = &row_idx[col_ptr[c]..col_ptr[c + 1]];
                rows.iter().all(|&r| r >= c && r < n) && rows.windows(2).all(|w| w[0] < w[1])
            });
        if !ok {
            return Err(SimError::Solver("invalid sparsity pattern".into()));
        }
        let sym = SymbolicSparseColMatRef::new_checked(n, n, &col_ptr, None, &row_idx);
        let symbolic = SymbolicLlt::try_new(sym, Side::Lower).map_err(llt_error)?;
        Ok(SpdSolver {
            n,
            col_ptr,
            row_idx,
            symbolic,
            llt: None,
        })
    }

    /// Dimension n.
    pub fn n(&self) -> usize {
        self.n
    }

    /// Stored entries of the lower triangle (`[nnz]` is the length `values` must have).
    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }

    /// `[n+1]` column starts of the pattern.
    pub fn col_ptr(&self) -> &[usize] {
        &self.col_ptr
    }

    /// `[nnz]` row of each stored entry.
    pub fn row_idx(&self) -> &[usize] {
        &self.row_idx
    }

    /// Numeric Cholesky factorisation of the matrix with lower-triangle `values` (`[nnz]`, in
    /// pattern order). Fails (keeping no factor) when the length is wrong or the matrix is
    /// not positive definite.
    pub fn factor(&mut self, values: &[f64]) -> Result<()> {
        self.llt = None;
        if values.len() != self.row_idx.len() {
            return Err(SimError::Solver(format!(
                "{} values for a pattern of {} entries",
                values.len(),
                self.row_idx.len()
            )));
        }
        if values.iter().any(|v| !v.is_finite()) {
            return Err(SimError::Solver("non-finite matrix entry".into()));
        }
        let sym = SymbolicSparseColMatRef::new_checked(
            self.n,
            self.n,
            &self.col_ptr,
            None,
            &self.row_idx,
        );
        self.llt = Some(
            Llt::try_new_with_symbolic(
                self.symbolic.clone(),
                SparseColMatRef::new(sym, values),
                Side::Lower,
            )
            .map_err(llt_error)?,
        );
        Ok(())
    }

    /// Whether a numeric factorisation is held.
    pub fn is_factored(&self) -> bool {
        self.llt.is_some()
    }

    /// Solves `A X = B` in place for `cols` right-hand sides stored column-major in `rhs`
    /// (`[n * cols]`). Fails when nothing is factored or the length does not match.
    pub fn solve_in_place(&self, rhs: &mut [f64], cols: usize) -> Result<()> {
        let llt = self
            .llt
            .as_ref()
            .ok_or_else(|| SimError::Solver("solve before a successful factorisation".into()))?;
        if rhs.len() != self.n * cols {
            return Err(SimError::Solver(format!(
                "right-hand side of length {} for n = {} and {cols} columns",
                rhs.len(),
                self.n
            )));
        }
        if self.n > 0 {
            llt.solve_in_place_with_conj(
                Conj::No,
                MatMut::from_column_major_slice_mut(rhs, self.n, cols),
            );
        }
        Ok(())
    }

    /// `y = A x` for the symmetric matrix with lower-triangle `values` (`[nnz]`); `x`, `y`:
    /// `[n]`. A plain sequential product, for tests and references.
    pub fn mul(&self, values: &[f64], x: &[f64], y: &mut [f64]) {
        y.iter_mut().for_each(|v| *v = 0.0);
        for c in 0..self.n {
            let span = self.col_ptr[c]..self.col_ptr[c + 1];
            for (&r, &a) in self.row_idx[span.clone()].iter().zip(&values[span]) {
                y[r] += a * x[c];
                if r != c {
                    y[c] += a * x[r];
                }
            }
        }
    }

    /// The symmetric matrix with lower-triangle `values` as a dense row-major `[n * n]` array
    /// (tests and the reference solver; O(n^2) memory).
    pub fn to_dense(&self, values: &[f64]) -> Vec<f64> {
        let n = self.n;
        let mut a = vec![0.0; n * n];
        for c in 0..n {
            let span = self.col_ptr[c]..self.col_ptr[c + 1];
            for (&r, &v) in self.row_idx[span.clone()].iter().zip(&values[span]) {
                a[r * n + c] = v;
                a[c * n + r] = v;
            }
        }
        a
    }
}

/// The layout of a scalar `[n, n]` symmetric matrix with a diagonal entry for every row and
/// an off-diagonal entry for each listed pair, stored as a lower triangle (CSC): the
/// diagonal entry is the first of its column.
#[derive(Clone, Debug)]
pub struct ScalarPattern {
    /// `[n+1]` column starts.
    pub col_ptr: Vec<usize>,
    /// `[nnz]` rows.
    pub row_idx: Vec<usize>,
    /// `[P]` position of each pair's entry.
    pub off: Vec<u32>,
}

impl ScalarPattern {
    /// The layout for `n` rows and `pairs` (`[P]` distinct unordered pairs `(a, b)`, `a != b`,
    /// both `< n`).
    pub fn new(n: usize, pairs: &[(u32, u32)]) -> Result<Self> {
        let mut keys: Vec<(u32, u32, u32)> = Vec::with_capacity(n + pairs.len());
        for v in 0..n as u32 {
            keys.push((v, v, u32::MAX));
        }
        for (p, &(a, b)) in pairs.iter().enumerate() {
            if a == b || a as usize >= n || b as usize >= n {
                return Err(SimError::InvalidInput(format!(
                    "matrix pair ({a}, {b}) is invalid for {n} rows"
                )));
            }
            keys.push((a.min(b), a.max(b), p as u32));
        }
        keys.sort_unstable();
        if keys
            .windows(2)
            .any(|w| w[0].0 == w[1].0 && w[0].1 == w[1].1)
        {
            return Err(SimError::InvalidInput("duplicate matrix pair".into()));
        }
        let mut col_ptr = vec![0usize; n + 1];
        let mut row_idx = Vec::with_capacity(keys.len());
        let mut off = vec![0u32; pairs.len()];
        for (pos, &(c, r, p)) in keys.iter().enumerate() {
            col_ptr[c as usize + 1] += 1;
            row_idx.push(r as usize);
            if p != u32::MAX {
                off[p as usize] = pos as u32;
            }
        }
        for i in 0..n {
            col_ptr[i + 1] += col_ptr[i];
        }
        Ok(ScalarPattern {
            col_ptr,
            row_idx,
            off,
        })
    }

    /// Position of row `i`'s diagonal entry.
    #[inline]
    pub fn diag(&self, i: usize) -> usize {
        self.col_ptr[i]
    }

    /// Number of stored entries.
    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }
}
