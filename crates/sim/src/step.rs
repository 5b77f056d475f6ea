//! One time step of [`ClothSim`].
//!
//! A step of length `h`:
//! 1. **Contacts.** Every free vertex within thickness + margin of the body at the start of
//!    the step (closest point through the BVH) gets a `Contact`: the body's tangent plane
//!    at the end of the step, and an anchor, its start position carried by the motion of its
//!    body point (a barycentric attachment), so a fast body carries the cloth it touches
//!    instead of leaving it behind or passing through it.
//! 2. **Prediction** `y = x + d + h (v - u) / (1 + damping h) + h^2 g` (`d`: the body's
//!    displacement this step at the contact, `u`: the body velocity there last step; both
//!    zero away from the body).
//! 3. **Active contacts**: those predicted to press into the body or pressed at the end of
//!    the last step. Their weights join the system matrix, which is refactorised
//!    numerically when enough of them changed (a few late ones are pushed out after every
//!    iteration meanwhile; a few stale ones act as a zero-force proximal term).
//! 4. **Projective dynamics** iterations from `y` (see [`crate::pd`]), contacts and Coulomb
//!    friction inside the local step.
//! 5. **Velocities** `(x_new - x)/h`; then every vertex inside the body or closer than half
//!    the thickness is projected out along the surface normal (to half the thickness: the
//!    contact constraints keep resting cloth at the full thickness, and pushing farther
//!    each step would fight them and stretch the cloth), losing its inward velocity
//!    relative to the body, with Coulomb friction on the tangential part.

use geom::ClosestHit;
use glam::{DVec3, Vec3};
use rayon::prelude::*;

use crate::cloth::{ClothSim, StepInfo, MAX_SPEED};
use crate::collide::{BodyCollider, SurfaceHit, NO_FACE};
use crate::error::{Result, SimError};
use crate::pd::{Contact, PdProblem, MIN_PAR};

/// After the solve, vertices closer to the body than this fraction of the thickness are
/// projected out to it.
const PROJECT_FRACTION: f32 = 0.5;
/// Refactorise when more than this fraction of the free vertices became active contacts
/// missing from the factored matrix...
const REFACTOR_MISSING: usize = 200;
/// ...or when any did and the factor is this many steps old...
const REFACTOR_AGE: u32 = 4;
/// ...or when more than this fraction of the free vertices hold a stale contact weight.
const REFACTOR_STALE: usize = 50;
/// Every this many steps, every vertex away from the surface gets the exact inside test
/// (a vertex pressed deeper than the contact reach, as in an armpit closing on it, is
/// otherwise never seen again).
const FULL_INSIDE_CHECK: u64 = 20;

impl ClothSim {
    /// Advances the simulation by one time step `params().dt`, colliding with `collider` if
    /// given (the body moves linearly from where it was at the previous step to where the
    /// last [`BodyCollider::move_to`] put it; the collider then keeps that place as its
    /// start).
    ///
    /// Fails with [`SimError::Diverged`] (naming the vertex) when a position becomes
    /// non-finite or a speed exceeds [`MAX_SPEED`], and with [`SimError::Solver`] when a
    /// factorisation fails; the cloth state is then left as it was before the step.
    pub fn step(&mut self, collider: Option<&mut BodyCollider>) -> Result<StepInfo> {
        let n = self.x.len();
        let p = self.params;
        let h = p.dt as f64;
        let inv_h2 = 1.0 / (h * h);
        let drag = 1.0 / (1.0 + p.damping as f64 * h);
        let mut info = StepInfo::default();

        // 1. Contacts at the start of the step.
        let (thick, reach) = self.thickness_and_reach(collider.as_deref());
        let mut contacts: Vec<Option<Contact>> = vec![None; n];
        let mut near = vec![Near::FAR; n];
        if let Some(c) = collider.as_deref() {
            let mut far = std::mem::take(&mut self.far);
            find_contacts(
                self,
                c,
                reach,
                &mut contacts,
                &mut near,
                &mut far,
                FAR_SEARCH,
            );
            self.far = far;
            self.near_face
                .iter_mut()
                .zip(&near)
                .for_each(|(f, n)| *f = n.face);
        }
        info.contacts = contacts.iter().filter(|c| c.is_some()).count();

        // 2. Prediction.
        let g = p.gravity.as_dvec3();
        let y: Vec<DVec3> = (0..n)
            .map(|i| {
                if self.pinned[i] {
                    return self.pin_target[i].as_dvec3();
                }
                let (carry, u) = match &contacts[i] {
                    Some(c) => (c.carry, self.body_vel[i].as_dvec3()),
                    None => (DVec3::ZERO, DVec3::ZERO),
                };
                let vrel = (self.v[i].as_dvec3() - u) * drag;
                self.x[i].as_dvec3() + carry + h * vrel + h * h * g
            })
            .collect();

        // 3. Active contacts; refactorise when the set changed enough.
        let active: Vec<bool> = (0..n)
            .map(|i| match &contacts[i] {
                Some(c) => c.height(y[i]) < thick as f64 || self.last_force[i] > 0.0,
                None => false,
            })
            .collect();
        info.active_contacts = active.iter().filter(|&&a| a).count();
        let nf = self.free.len();
        let missing = (0..n).filter(|&i| active[i] && !self.factored[i]).count();
        let stale = (0..n).filter(|&i| !active[i] && self.factored[i]).count();
        let refactor = missing > nf / REFACTOR_MISSING
            || (missing > 0 && self.steps_since_refactor >= REFACTOR_AGE)
            || stale > nf / REFACTOR_STALE;
        if refactor && self.solver.is_some() {
            self.refactor(&active)?;
            info.refactored = true;
        } else {
            self.steps_since_refactor = self.steps_since_refactor.saturating_add(1);
        }

        // 4. Projective dynamics, starting from the prediction without gravity: at rest the
        // start is then the equilibrium itself, a fixed point of the iterations, so the rest
        // state does not depend on how far the iterations converge.
        let gh2 = h * h * g;
        let mut xs: Vec<DVec3> = (0..n)
            .map(|i| if self.pinned[i] { y[i] } else { y[i] - gh2 })
            .collect();
        if let Some(solver) = self.solver.as_ref() {
            let problem = PdProblem {
                cons: &self.cons,
                free: &self.free,
                pinned: &self.pinned,
                y: &y,
                inv_h2,
                contact_w: &self.contact_w,
                factored: &self.factored,
                contacts: &contacts,
                active: &active,
                thick: thick as f64,
                mu: p.friction as f64,
                split_solve: p.split_solve,
            };
            let change = problem.iterate(solver, p.iterations, p.chebyshev_rho as f64, &mut xs)?;
            info.iterations = p.iterations;
            info.last_change = change as f32;
        }

        // 5. Velocities and contact forces; friction for contacts the solve did not hold.
        let stick: Vec<Option<DVec3>> = (0..n)
            .map(|i| match (&contacts[i], active[i] && self.factored[i]) {
                (Some(c), true) if p.static_friction => {
                    c.sticks(xs[i], thick as f64, p.friction as f64)
                }
                _ => None,
            })
            .collect();
        let mut x1: Vec<Vec3> = xs.iter().map(|p| p.as_vec3()).collect();
        let mut v1: Vec<Vec3> = (0..n).map(|i| (x1[i] - self.x[i]) / p.dt).collect();
        let mut force = vec![0.0f64; n];
        for i in 0..n {
            let (Some(c), true) = (&contacts[i], active[i]) else {
                continue;
            };
            let depth = (thick as f64 - c.height(xs[i])).max(0.0);
            if self.factored[i] {
                force[i] = self.contact_w[i] * depth;
            } else {
                // Pushed out after each iteration: the force that stopped its prediction.
                force[i] = self.cons.mass[i] * inv_h2 * c.normal.dot(xs[i] - y[i]).max(0.0);
                let u = (c.carry / h).as_vec3();
                let dvn = (force[i] * h / self.cons.mass[i]) as f32;
                v1[i] = u + friction(v1[i] - u, c.normal.as_vec3(), p.friction * dvn);
            }
        }

        // 6. Collision projection. `found`: the closest points it found for the vertices
        // it did not move, which the next step's contacts reuse.
        let mut found: Vec<Option<ClosestHit>> = Vec::new();
        let mut found_state = 0;
        if let Some(c) = collider.as_deref() {
            let check = if self.steps_taken % FULL_INSIDE_CHECK == 0 {
                Check::Full
            } else {
                Check::Near
            };
            let (fixes, hits) =
                project_out(self, c, &x1, &near, reach, thick * PROJECT_FRACTION, check);
            info.projected = fixes.len();
            found = hits;
            for f in &fixes {
                found[f.i] = None;
            }
            found_state = c.cur_state();
            for Fix {
                i,
                target,
                out: nrm,
                ..
            } in fixes
            {
                let push = (target - x1[i]).length();
                x1[i] = target;
                let u = contacts[i].map_or(Vec3::ZERO, |c| (c.carry / h).as_vec3());
                let mut vrel = v1[i] - u;
                let vn = vrel.dot(nrm);
                let mut dvn = push / p.dt;
                if vn < 0.0 {
                    vrel -= vn * nrm;
                    dvn -= vn;
                }
                v1[i] = u + friction(vrel, nrm, p.friction * dvn);
            }
        }

        // 7. Pinned vertices; blow-up check; commit.
        for &i in &self.pin_list {
            let i = i as usize;
            x1[i] = self.pin_target[i];
            v1[i] = (x1[i] - self.x[i]) / p.dt;
        }
        let mut max_speed2 = 0.0f32;
        for i in 0..n {
            let s2 = v1[i].length_squared();
            if !x1[i].is_finite() || !s2.is_finite() || s2 > MAX_SPEED * MAX_SPEED {
                return Err(SimError::Diverged(format!(
                    "vertex {i} reached position {} with velocity {} (speed limit \
                     {MAX_SPEED} m/s)",
                    x1[i], v1[i]
                )));
            }
            max_speed2 = max_speed2.max(s2);
        }
        for (u, c) in self.body_vel.iter_mut().zip(&contacts) {
            *u = c.map_or(Vec3::ZERO, |c| (c.carry / h).as_vec3());
        }
        self.known = (found.iter().zip(&x1))
            .map(|(h, &at)| {
                h.map(|hit| KnownHit {
                    at,
                    state: found_state,
                    hit,
                })
            })
            .collect();
        self.x = x1;
        self.v = v1;
        self.last_force = force;
        self.stick = stick;
        self.steps_taken += 1;
        if let Some(c) = collider {
            c.commit();
        }
        info.kinetic_energy = self.kinetic_energy();
        info.max_speed = max_speed2.sqrt();
        Ok(info)
    }

    /// The collision thickness of a step (the larger of the cloth's and the collider's) and
    /// the reach within which a vertex touches the body (thickness + contact margin), metres.
    fn thickness_and_reach(&self, collider: Option<&BodyCollider>) -> (f32, f32) {
        let thick = self
            .params
            .thickness
            .max(collider.map_or(0.0, |c| c.thickness()));
        (thick, thick + self.params.contact_margin)
    }

    /// Moves every free vertex inside the body, or closer to it than half the thickness, out
    /// of it as the projection after each step does, but with the exact inside test for every
    /// vertex (the steps run it every 20 steps) and without a time step:
    /// the moved vertices stop. A vertex still inside after that (caught where two body
    /// parts overlap, or under a fold of skin, where the closest surface leads no way out)
    /// goes the shortest way out of the body: along 32 directions, the nearest point where no
    /// body part encloses the ray any more ([`geom::Bvh::ray_exit`]). For the end of
    /// a simulation, so that no vertex is left inside. Returns how many vertices moved and
    /// how many of them went the shortest way out.
    pub fn project_out_of(&mut self, collider: &BodyCollider) -> (usize, usize) {
        self.exact_pass(collider, false)
    }

    /// Of the moves [`ClothSim::project_out_of`] would make, only the walks out of the body
    /// (vertices inside with no way out through their closest surface): during a
    /// simulation, so that cloth caught between body parts gets free without disturbing
    /// the cloth resting in contact. Returns how many vertices moved.
    pub fn walk_out_of(&mut self, collider: &BodyCollider) -> usize {
        self.exact_pass(collider, true).1
    }

    /// [`ClothSim::project_out_of`], applying only the walks out with `walks_only`.
    fn exact_pass(&mut self, collider: &BodyCollider, walks_only: bool) -> (usize, usize) {
        let (thick, reach) = self.thickness_and_reach(Some(collider));
        // Unknown distances (0): every vertex is looked at.
        let near: Vec<Near> = (self.near_face.iter())
            .map(|&face| Near { dist: 0.0, face })
            .collect();
        let x = self.x.clone();
        let (mut fixes, _) = project_out(
            self,
            collider,
            &x,
            &near,
            reach,
            thick * PROJECT_FRACTION,
            Check::Exact,
        );
        if walks_only {
            fixes.retain(|f| f.walked_out);
        }
        for f in &fixes {
            self.x[f.i] = f.target;
            self.v[f.i] = Vec3::ZERO;
        }
        (fixes.len(), fixes.iter().filter(|f| f.walked_out).count())
    }
}

/// A vertex's closest body point found at the end of a step, which the next step's
/// contacts reuse instead of searching again (19% of the contact searches of
/// `garnet bench sim`'s drape; most of the rest are spared by [`FarBound`]s). Like the
/// search hints, these caches never change a result, so a failed step may leave them
/// updated.
#[derive(Clone, Copy, Debug)]
pub(crate) struct KnownHit {
    /// Where the vertex was.
    at: Vec3,
    /// The body state it was found on ([`BodyCollider::cur_state`]).
    state: u64,
    hit: ClosestHit,
}

/// A lower bound of a vertex's distance to the body, from a search wider than the contact
/// reach.
#[derive(Clone, Copy, Debug)]
pub(crate) struct FarBound {
    /// Where the vertex was.
    at: Vec3,
    /// The body state ([`BodyCollider::prev_state`]).
    state: u64,
    /// The distance is at least this, metres.
    lower: f32,
}

/// What the start of a step knows of a vertex's distance to the body.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Near {
    /// A lower bound of the distance, metres.
    dist: f32,
    /// The closest face when it was within the search ([`NO_FACE`] otherwise): a hint for
    /// the searches from the vertex's next places.
    face: u32,
}

impl Near {
    /// Nothing known: far away.
    const FAR: Near = Near {
        dist: f32::INFINITY,
        face: NO_FACE,
    };
}

/// Fills `contacts` (`[N]`) for the free vertices of `sim` within `reach` of the body at the
/// start of the step, and `near` (`[N]`) with every free vertex's closest face and a lower
/// bound of its distance to the body then (searched up to about twice the distance it can
/// travel this step).
fn find_contacts(
    sim: &ClothSim,
    c: &BodyCollider,
    reach: f32,
    contacts: &mut [Option<Contact>],
    near: &mut [Near],
    far: &mut [Option<FarBound>],
    far_search: f32,
) {
    let p = &sim.params;
    let max_disp = c.max_displacement();
    let (x, v, pinned) = (&sim.x, &sim.v, &sim.pinned);
    contacts
        .par_iter_mut()
        .zip(near.par_iter_mut())
        .zip(far.par_iter_mut())
        .enumerate()
        .with_min_len(MIN_PAR)
        .for_each(|(i, ((ct, nr), fb))| {
            if pinned[i] {
                return;
            }
            let travel = v[i].length() * p.dt + p.gravity.length() * p.dt * p.dt;
            let r = reach + 2.0 * (travel + max_disp);
            match closest_at_start(sim, c, i, (r, far_search), fb) {
                Some(hit) => {
                    *nr = Near {
                        dist: hit.distance,
                        face: hit.face,
                    };
                    if hit.distance <= reach {
                        let (pt, nrm) = c.plane_cur(hit.face, hit.bary);
                        let carry = c.displacement(hit.face, hit.bary);
                        let held =
                            sim.stick[i].filter(|a| a.distance(x[i].as_dvec3()) < STICK_REACH_M);
                        *ct = Some(Contact {
                            carry: carry.as_dvec3(),
                            point: pt.as_dvec3(),
                            normal: nrm.as_dvec3(),
                            anchor: held.unwrap_or(x[i].as_dvec3()) + carry.as_dvec3(),
                        });
                    }
                }
                None => nr.dist = r,
            }
        });
}

/// A held friction anchor farther than this from its vertex (metres) is let go: the
/// vertex was moved (projected or walked out of the body) since it stuck.
const STICK_REACH_M: f64 = 0.004;

/// Searches reach at least this far (metres) while the body holds still, so that a vertex
/// away from it gets a lower bound of its distance ([`FarBound`]) and is not searched
/// again until it has come closer by the difference (8% of the bench drape's time).
const FAR_SEARCH: f32 = 0.03;

/// The closest point within `r` of free vertex `i` of `sim` on the body at the start of the
/// step, as [`BodyCollider::closest_prev`] gives it, without searching where that answer
/// is already known: the last step's projection found it from the same place on the same
/// body ([`KnownHit`]), or the vertex is farther than `r` by its lower bound `far`, which
/// this keeps up to date (searching up to `far_search` metres while the body holds still).
fn closest_at_start(
    sim: &ClothSim,
    c: &BodyCollider,
    i: usize,
    (r, far_search): (f32, f32),
    far: &mut Option<FarBound>,
) -> Option<ClosestHit> {
    let (x, state) = (sim.x[i], c.prev_state());
    // Found within the reach (no farther than `r`): the search would find it again.
    if let Some(k) = sim.known.get(i).copied().flatten() {
        if k.at == x && k.state == state && k.hit.distance <= r {
            return Some(k.hit);
        }
    }
    if let Some(f) = *far {
        if f.state == state && f.lower - f.at.distance(x) > r + 1e-6 {
            return None;
        }
    }
    // A wider search (while the body holds still) finds the same point when it is within
    // `r` (the first closest face in the search order, which no bound prunes) and
    // otherwise bounds the distance.
    let still = c.max_displacement() == 0.0;
    let wide = if still { r.max(far_search) } else { r };
    let hit = c.closest_prev(x, wide, sim.near_face[i]);
    *far = match hit {
        Some(h) if h.distance <= r => None,
        _ if !still => None,
        _ => Some(FarBound {
            at: x,
            state,
            lower: hit.map_or(wide, |h| h.distance),
        }),
    };
    hit.filter(|h| h.distance <= r)
}

/// How thoroughly [`project_out`] looks for vertices inside the body.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Check {
    /// Vertices with no surface within the reach are outside unless they may have travelled
    /// farther than their start distance, when the winding test decides.
    Near,
    /// The winding test decides for every vertex with no surface within the reach.
    Full,
    /// As `Full`, and every vertex's final place is checked by the winding test: one still
    /// inside goes the shortest way out instead.
    Exact,
}

/// A vertex moved out of the body by [`project_out`].
struct Fix {
    /// The vertex.
    i: usize,
    /// Where it goes, metres.
    target: Vec3,
    /// Unit direction it was moved out along.
    out: Vec3,
    /// Whether it went the shortest way out of the body ([`BodyCollider::exit_point`]).
    walked_out: bool,
}

/// The free vertices of `x1` (`[N]`) inside the body or closer to it than `to` (metres) at the
/// end of the step, each with where it goes (`to` outside the surface) and the outward
/// direction, found as thoroughly as `check` says (`near`: `[N]` what the start of the step
/// knew). Also `[N]` the closest body point within `reach` of each vertex where the
/// projection looked for it and found one.
fn project_out(
    sim: &ClothSim,
    c: &BodyCollider,
    x1: &[Vec3],
    near: &[Near],
    reach: f32,
    to: f32,
    check: Check,
) -> (Vec<Fix>, Vec<Option<ClosestHit>>) {
    let proj = Projection {
        c,
        reach,
        to,
        max_disp: c.max_displacement(),
        full: check != Check::Near,
    };
    let (x0, pinned) = (&sim.x, &sim.pinned);
    let mut found = vec![None; x1.len()];
    let fixes = (found.par_iter_mut().enumerate())
        .with_min_len(MIN_PAR)
        .filter_map(|(i, found)| {
            if pinned[i] {
                return None;
            }
            let xi = x1[i];
            let verdict = proj.vertex(xi, x0[i], near[i], found);
            let fix = match verdict {
                Verdict::Move(target, out) => Some((target, out)),
                Verdict::Clear | Verdict::Outside => None,
            };
            // The exact pass checks the final place by the winding test, unless the
            // projection already found it outside that way.
            if check == Check::Exact
                && verdict != Verdict::Outside
                && c.contains_cur(fix.map_or(xi, |f| f.0))
            {
                if let Some((target, out)) = c.exit_point(xi, to) {
                    return Some(Fix {
                        i,
                        target,
                        out,
                        walked_out: true,
                    });
                }
            }
            fix.map(|(target, out)| Fix {
                i,
                target,
                out,
                walked_out: false,
            })
        })
        .collect();
    (fixes, found)
}

/// What the projection decided for one vertex.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Verdict {
    /// Clear of the body by its closest surface (or not looked at: too far to reach it).
    Clear,
    /// Outside the body by the winding test.
    Outside,
    /// Goes to this place, moved out along this unit direction.
    Move(Vec3, Vec3),
}

/// What the projection of one vertex reads.
struct Projection<'a> {
    c: &'a BodyCollider,
    /// Thickness + contact margin, metres.
    reach: f32,
    /// Distance outside the surface a projected vertex goes to, metres.
    to: f32,
    /// The body's largest displacement this step, metres.
    max_disp: f32,
    /// The winding test decides for every vertex with no surface within `reach`.
    full: bool,
}

impl Projection<'_> {
    /// Where a vertex at `xi` that started the step at `x0`, at least `near.dist` metres
    /// from the body, goes and the outward direction, or why it stays; `found`: the
    /// closest body point within the reach, when it searched for one and found it.
    fn vertex(&self, xi: Vec3, x0: Vec3, near: Near, found: &mut Option<ClosestHit>) -> Verdict {
        let dist0 = near.dist;
        let (c, reach, full) = (self.c, self.reach, self.full);
        let travel = (xi - x0).length() + self.max_disp;
        // Far from the body at the start and not moved enough to reach it: no query
        // (the distance at the end is at least the start distance minus the travel).
        if !full && dist0 - travel > reach {
            return Verdict::Clear;
        }
        let hit = match c.surface_within(xi, reach, near.face) {
            Some(hit) => {
                *found = Some(hit.closest());
                hit
            }
            None => {
                if !full && travel < dist0 {
                    return Verdict::Clear;
                }
                if !c.contains_cur(xi) {
                    return Verdict::Outside;
                }
                match c.surface_any(xi) {
                    Some(hit) => hit,
                    None => return Verdict::Clear,
                }
            }
        };
        if hit.signed >= self.to {
            return Verdict::Clear;
        }
        // Under the closest surface yet outside the body: a fold of the skin (a posed
        // crease passing through itself). Pushing out of that surface would push the
        // vertex into the fold's other side; the winding test is the judge. It costs
        // three ray casts, so only the full checks ask it (one per step cost 7-15% of
        // the 1 cm T-shirt's drape time); the exact pass at the end is one of them.
        if full && hit.signed < 0.0 && !c.contains_cur(xi) {
            return Verdict::Outside;
        }
        let (target, out) = clear_of_overlaps(c, hit, reach, self.to);
        Verdict::Move(target, out)
    }
}

/// Most projections of one vertex in a step: where two body parts overlap (an arm
/// sunk into the chest), the point moved out of the closest surface can land inside the
/// other part; projecting again onto whichever surface is then closest walks it out of
/// both, as alternating projections onto two half-spaces reach their intersection.
const MAX_PROJECTIONS: usize = 4;

/// A vertex moved `to` metres outside the surface of `hit` (the closest to it) and then,
/// while that lands it inside the body (under the surface then closest, within `reach`,
/// and inside by the winding test), outside that surface too:
/// `(target, outward direction of the last projection)`.
fn clear_of_overlaps(c: &BodyCollider, hit: SurfaceHit, reach: f32, to: f32) -> (Vec3, Vec3) {
    let mut target = hit.point + hit.out * to;
    let (mut out, mut face) = (hit.out, hit.face);
    for _ in 1..MAX_PROJECTIONS {
        match c.surface_within(target, reach, face) {
            Some(h) if h.signed < 0.0 && c.contains_cur(target) => {
                target = h.point + h.out * to;
                (out, face) = (h.out, h.face);
            }
            _ => break,
        }
    }
    (target, out)
}

/// Coulomb friction: reduces the tangential part of `vrel` (relative to the surface with unit
/// normal `n`) by `limit` (m/s), stopping it when smaller; the normal part is kept.
#[inline]
fn friction(vrel: Vec3, n: Vec3, limit: f32) -> Vec3 {
    let vn = vrel.dot(n);
    let vt = vrel - vn * n;
    let s = vt.length();
    let limit = limit.max(0.0);
    let scale = if s > limit { 1.0 - limit / s } else { 0.0 };
    vn * n + vt * scale
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ClothParams;
    use geom::TriMesh;

    /// `find_contacts` for `sim` with the hits and bounds it remembers, and with a plain
    /// search within the contact radius for every vertex: `(contacts, near)` of each.
    fn both_ways(
        sim: &mut ClothSim,
        body: &BodyCollider,
    ) -> [(Vec<Option<Contact>>, Vec<Near>); 2] {
        let n = sim.x.len();
        let (_, reach) = sim.thickness_and_reach(Some(body));
        let mut far = sim.far.clone();
        let run = |sim: &ClothSim, far: &mut [Option<FarBound>], far_search| {
            let mut contacts = vec![None; n];
            let mut near = vec![Near::FAR; n];
            find_contacts(sim, body, reach, &mut contacts, &mut near, far, far_search);
            (contacts, near)
        };
        let remembered = run(sim, &mut far, FAR_SEARCH);
        let known = std::mem::take(&mut sim.known);
        let fresh = run(sim, &mut vec![None; n], 0.0);
        sim.known = known;
        [remembered, fresh]
    }

    #[test]
    fn remembered_hits_and_bounds_give_what_the_search_gives() {
        let radius = 0.2;
        let (cloth, sphere) = crate::shapes::cloth_over_sphere(radius, 0.03);
        let params = ClothParams::default();
        let mut sim = ClothSim::new(&cloth, &params).unwrap();
        let mut body = BodyCollider::new(&sphere, params.thickness).unwrap();
        let (mut known, mut bounded) = (0, 0);
        for step in 0..100 {
            // The body holds still, moves for ten steps, and holds still again; then the
            // cloth is moved by hand, and then another body takes over.
            if (40..50).contains(&step) {
                let moved: Vec<Vec3> = (body.vertices().iter())
                    .map(|v| *v + Vec3::new(0.002, 0.001, 0.0))
                    .collect();
                body.move_to(&moved).unwrap();
            }
            if step == 70 {
                let lifted: Vec<Vec3> = (sim.positions().iter())
                    .map(|v| *v + Vec3::Y * 0.003)
                    .collect();
                sim.set_positions(&lifted).unwrap();
            }
            if step == 80 {
                body = BodyCollider::new(&TriMesh::icosphere(3, radius + 0.004), 0.004).unwrap();
            }
            let [remembered, fresh] = both_ways(&mut sim, &body);
            assert!(remembered == fresh, "step {step}");
            known += sim.known.iter().flatten().count();
            bounded += sim.far.iter().flatten().count();
            sim.step(Some(&mut body)).unwrap();
        }
        // Both shortcuts were taken (and checked) many times.
        assert!(known > 5_000 && bounded > 20_000, "{known} {bounded}");
    }
}
