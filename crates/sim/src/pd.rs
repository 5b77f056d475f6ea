//! The projective dynamics iterations of one step (Bouaziz et al. 2014, in the mass-spring
//! form of Liu et al. 2013), with Chebyshev acceleration (Wang 2015).
//!
//! The step minimises over the free vertices
//!
//! ```text
//! 1/(2 h^2) sum_i m_i |x_i - y_i|^2  +  sum_c w_c/2 |x_a - x_b - p_c|^2  +  sum_i k_i/2 |x_i - q_i|^2
//! ```
//!
//! alternating a local step (`p_c`: the current vector `x_a - x_b` scaled to the rest length;
//! `q_i`: the contact target, see `Contact::target`) and a global step, a solve with the
//! constant matrix `M/h^2 + sum w_c S_c^T S_c + diag(k)` factorised once. Bending pairs enter
//! that matrix by their diagonal only and their off-diagonal part is taken from the current
//! iterate (a Jacobi splitting): bending weights are about a thousandth of the stretch
//! weights, so this costs no convergence and keeps the factor 4x cheaper to solve.

use glam::DVec3;
use rayon::prelude::*;

use crate::constraints::Constraints;
use crate::error::Result;
use crate::solver::SpdSolver;

/// Parallel loops over vertices use chunks of at least this many.
pub(crate) const MIN_PAR: usize = 256;

/// A body contact of one free vertex for the current step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Contact {
    /// Body displacement over the step at the contact point, metres.
    pub carry: DVec3,
    /// Contact plane at the end of the step: point and unit outward normal.
    pub point: DVec3,
    pub normal: DVec3,
    /// Where the vertex stays if it sticks: its start position carried by the body.
    pub anchor: DVec3,
}

impl Contact {
    /// Signed distance of `x` from the contact plane.
    #[inline]
    pub fn height(&self, x: DVec3) -> f64 {
        self.normal.dot(x - self.point)
    }

    /// The local step of a contact constraint at `x`: pushed out of the plane's thickness
    /// layer (`thick`) along the normal and, with friction `mu`, pulled toward the anchor in
    /// the tangent plane by at most `mu` times the push (Coulomb's cone: sticking inside it,
    /// sliding on its boundary).
    #[inline]
    pub fn target(&self, x: DVec3, thick: f64, mu: f64) -> DVec3 {
        let push = (thick - self.height(x)).max(0.0);
        let mut q = x + push * self.normal;
        if mu > 0.0 {
            let d = self.anchor - x;
            let dt = d - self.normal * self.normal.dot(d);
            let l = dt.length();
            let limit = mu * push;
            q += if l <= limit { dt } else { dt * (limit / l) };
        }
        q
    }

    /// The anchor, when `x` holds to it by static friction: its tangential distance from the
    /// anchor is inside Coulomb's cone of [`Contact::target`] (at most `mu` times the push
    /// out of the thickness layer, and the push is positive).
    pub fn sticks(&self, x: DVec3, thick: f64, mu: f64) -> Option<DVec3> {
        let push = (thick - self.height(x)).max(0.0);
        let d = self.anchor - x;
        let dt = d - self.normal * self.normal.dot(d);
        (mu > 0.0 && push > 0.0 && dt.length() <= mu * push).then_some(self.anchor)
    }

    /// `x` moved out of the thickness layer along the normal (no friction).
    #[inline]
    pub fn push_out(&self, x: DVec3, thick: f64) -> DVec3 {
        x + (thick - self.height(x)).max(0.0) * self.normal
    }
}

/// Everything one step's iterations read.
pub(crate) struct PdProblem<'a> {
    pub cons: &'a Constraints,
    /// Free vertices in system order.
    pub free: &'a [u32],
    /// `[N]` kinematic vertices.
    pub pinned: &'a [bool],
    /// `[N]` inertial prediction (pinned vertices: their end-of-step positions).
    pub y: &'a [DVec3],
    /// `1 / h^2`.
    pub inv_h2: f64,
    /// `[N]` contact weights, N/m.
    pub contact_w: &'a [f64],
    /// `[N]` whether the factored matrix holds the vertex's contact weight.
    pub factored: &'a [bool],
    /// `[N]` contacts found at the start of the step.
    pub contacts: &'a [Option<Contact>],
    /// `[N]` contacts whose constraint acts this step.
    pub active: &'a [bool],
    /// Collision thickness, metres.
    pub thick: f64,
    /// Friction coefficient.
    pub mu: f64,
    /// Solve x and y beside z on two threads ([`crate::ClothParams::split_solve`]).
    pub split_solve: bool,
}

impl PdProblem<'_> {
    /// The local steps gathered into the global step's right-hand side for the free vertices
    /// (`out`: `[nf]`, system order) at the iterate `xs` (`[N]`, all vertices).
    pub fn rhs(&self, xs: &[DVec3], out: &mut [DVec3]) {
        let cons = self.cons;
        out.par_iter_mut()
            .zip(self.free.par_iter())
            .with_min_len(MIN_PAR)
            .for_each(|(r, &vi)| {
                let i = vi as usize;
                let xi = xs[i];
                let mut acc = cons.mass[i] * self.inv_h2 * self.y[i];
                for c in cons.at(i) {
                    let xb = xs[c.other as usize];
                    let d = xi - xb;
                    let l = d.length();
                    let w = c.weight as f64;
                    if l > 1e-12 {
                        acc += d * (w * c.rest as f64 / l);
                    }
                    // Pinned neighbours and bending pairs are not in the matrix's
                    // off-diagonal: their coupling comes from the iterate.
                    if c.bend || self.pinned[c.other as usize] {
                        acc += w * xb;
                    }
                }
                if self.factored[i] {
                    let q = match (&self.contacts[i], self.active[i]) {
                        (Some(c), true) => c.target(xi, self.thick, self.mu),
                        _ => xi,
                    };
                    acc += self.contact_w[i] * q;
                }
                *r = acc;
            });
    }

    /// Runs `iterations` local/global iterations from `xs` (`[N]`, updated in place; pinned
    /// entries are read only), with Chebyshev acceleration for spectral radius estimate `rho`
    /// (0 disables it). Active contacts missing from the factored matrix are pushed out of
    /// their plane after every global step. Returns the largest vertex move of the last
    /// iteration (metres).
    pub fn iterate(
        &self,
        solver: &SpdSolver,
        iterations: u32,
        rho: f64,
        xs: &mut [DVec3],
    ) -> Result<f64> {
        /// Under-relaxation of the accelerated update (Wang 2015 suggests 0.9).
        const GAMMA: f64 = 0.9;
        /// Plain iterations before the acceleration starts.
        const DELAY: u32 = 2;
        let nf = self.free.len();
        let mut rhs = vec![DVec3::ZERO; nf];
        let mut buf = vec![0.0f64; nf * 3];
        let mut prev: Vec<DVec3> = self.free.iter().map(|&v| xs[v as usize]).collect();
        let mut omega = 1.0;
        let mut change = 0.0f64;
        for it in 0..iterations {
            self.rhs(xs, &mut rhs);
            {
                let (bx, rest) = buf.split_at_mut(nf);
                let (by, bz) = rest.split_at_mut(nf);
                bx.par_iter_mut()
                    .zip(by.par_iter_mut())
                    .zip(bz.par_iter_mut())
                    .zip(rhs.par_iter())
                    .with_min_len(4 * MIN_PAR)
                    .for_each(|(((x, y), z), r)| {
                        *x = r.x;
                        *y = r.y;
                        *z = r.z;
                    });
            }
            if self.split_solve {
                let (xy, z) = buf.split_at_mut(2 * nf);
                let (a, b) = rayon::join(
                    || solver.solve_in_place(xy, 2),
                    || solver.solve_in_place(z, 1),
                );
                a?;
                b?;
            } else {
                solver.solve_in_place(&mut buf, 3)?;
            }
            if rho > 0.0 {
                omega = match it {
                    _ if it < DELAY => 1.0,
                    _ if it == DELAY => 2.0 / (2.0 - rho * rho),
                    _ => 4.0 / (4.0 - rho * rho * omega),
                };
            }
            change = 0.0;
            for (k, &v) in self.free.iter().enumerate() {
                let i = v as usize;
                let cur = xs[i];
                let mut xn = DVec3::new(buf[k], buf[nf + k], buf[2 * nf + k]);
                if omega != 1.0 {
                    xn = omega * (GAMMA * (xn - cur) + cur - prev[k]) + prev[k];
                }
                if self.active[i] && !self.factored[i] {
                    if let Some(c) = &self.contacts[i] {
                        xn = c.push_out(xn, self.thick);
                    }
                }
                change = change.max(xn.distance_squared(cur));
                prev[k] = cur;
                xs[i] = xn;
            }
        }
        Ok(change.sqrt())
    }
}
