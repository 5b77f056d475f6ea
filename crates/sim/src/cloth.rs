//! The cloth simulation state and its public interface; the step itself is in the `step`
//! module.

use glam::{DVec3, Vec3};

use geom::TriMesh;

use crate::constraints::Constraints;
use crate::error::{check_finite, Result, SimError};
use crate::params::ClothParams;
use crate::solver::{ScalarPattern, SpdSolver};

/// Weight of a contact constraint relative to the vertex's inertia `m / h^2`. Strong enough
/// to carry the cloth hanging below a contact (a 1 cm vertex holding 100 times its own weight
/// sinks about 0.3 mm into the thickness layer at 60 steps per second), weak enough not to
/// freeze the cloth's tangential motion in the iterations (an isotropic weight acts
/// tangentially too).
pub(crate) const CONTACT_WEIGHT: f64 = 100.0;

/// Speeds above this (m/s) are taken as a blow-up.
pub const MAX_SPEED: f32 = 200.0;

/// What one [`ClothSim::step`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StepInfo {
    /// Kinetic energy after the step, joules.
    pub kinetic_energy: f32,
    /// Largest vertex speed after the step, m/s.
    pub max_speed: f32,
    /// Vertices touching the body at the start of the step (within thickness + margin).
    pub contacts: usize,
    /// Contact constraints acting in the solve (pressed or predicted to press).
    pub active_contacts: usize,
    /// Vertices pushed back out after the solve (closer to the body than half the thickness,
    /// or inside it).
    pub projected: usize,
    /// Solver iterations run.
    pub iterations: u32,
    /// Largest vertex move in the last solver iteration, metres (how far from converged).
    pub last_change: f32,
    /// Whether the system matrix was refactorised this step (the contact set changed).
    pub refactored: bool,
}

/// A cloth simulation: a triangle mesh of cloth with per-vertex state (positions,
/// velocities, pinned flags, contact memory) and its prefactored system. A clone carries
/// on exactly as the original would.
#[derive(Clone, Debug)]
pub struct ClothSim {
    pub(crate) params: ClothParams,
    pub(crate) faces: Vec<[u32; 3]>,
    pub(crate) cons: Constraints,
    /// `[N]` positions, metres.
    pub(crate) x: Vec<Vec3>,
    /// `[N]` velocities, m/s.
    pub(crate) v: Vec<Vec3>,
    /// `[N]` kinematic flags.
    pub(crate) pinned: Vec<bool>,
    pub(crate) pin_list: Vec<u32>,
    /// `[N]` where each pinned vertex will be at the end of the next step.
    pub(crate) pin_target: Vec<Vec3>,
    /// Free vertices in system order.
    pub(crate) free: Vec<u32>,
    /// Layout of the system matrix over the free vertices.
    pub(crate) pattern: ScalarPattern,
    /// Matrix values without contacts (`[nnz]`).
    pub(crate) base: Vec<f64>,
    pub(crate) solver: Option<SpdSolver>,
    /// `[N]` weight of a contact constraint at each vertex, N/m.
    pub(crate) contact_w: Vec<f64>,
    /// `[N]` whether the factored matrix holds the vertex's contact weight.
    pub(crate) factored: Vec<bool>,
    pub(crate) steps_since_refactor: u32,
    /// Steps taken since the simulation was made.
    pub(crate) steps_taken: u64,
    /// `[N]` normal contact force at the end of the last step, N (0: not pressed).
    pub(crate) last_force: Vec<f64>,
    /// `[N]` body velocity at the contact during the last step (zero when not in contact).
    pub(crate) body_vel: Vec<Vec3>,
    /// `[N]` the body face closest to each vertex at the start of the last step
    /// ([`crate::collide::NO_FACE`] when none was within its search): hints that make the
    /// next step's closest-point searches cheaper without changing their results.
    pub(crate) near_face: Vec<u32>,
    /// `[N]` closest body points the last step's projection found (or none).
    pub(crate) known: Vec<Option<crate::step::KnownHit>>,
    /// `[N]` lower bounds of the vertices' distances to the body (or none).
    pub(crate) far: Vec<Option<crate::step::FarBound>>,
    /// `[N]` with [`ClothParams::static_friction`]: where each vertex that stuck to the body
    /// in the last step is held (its friction anchor, metres; none for the others).
    pub(crate) stick: Vec<Option<glam::DVec3>>,
}

impl ClothSim {
    /// A simulation of the cloth `rest` (vertices `[N]` metres, faces `[F]`): rest lengths,
    /// masses and constraint weights come from `rest`; initial positions are `rest`, initial
    /// velocities zero, nothing pinned. Fails on invalid parameters, a mesh without faces, a
    /// non-finite coordinate (naming the vertex), an index out of range or an edge of zero
    /// length.
    pub fn new(rest: &TriMesh, params: &ClothParams) -> Result<Self> {
        Self::with_stretch_scale(rest, params, &vec![1.0; rest.vertices.len()])
    }

    /// [`ClothSim::new`] with part of the cloth elastic: `scale` (`[N]`, positive) is each
    /// vertex's stretch modulus as a fraction of `params.stretch_stiffness`, an edge taking
    /// the smaller of its ends' (see [`Constraints::with_stretch_scale`]). Edges softer than
    /// the cloth are elastic: [`ClothSim::strains`] leaves them out and
    /// [`ClothSim::elastic_strains`] reports them.
    pub fn with_stretch_scale(rest: &TriMesh, params: &ClothParams, scale: &[f32]) -> Result<Self> {
        params.validate()?;
        check_finite("rest mesh", &rest.vertices)?;
        rest.validate()?;
        if rest.faces.is_empty() {
            return Err(SimError::InvalidMesh("cloth mesh has no faces".into()));
        }
        let n = rest.vertices.len();
        let cons = Constraints::with_stretch_scale(&rest.vertices, &rest.faces, params, scale)?;
        let h = params.dt as f64;
        let contact_w = cons
            .mass
            .iter()
            .map(|&m| CONTACT_WEIGHT * m / (h * h))
            .collect();
        let mut sim = ClothSim {
            params: *params,
            faces: rest.faces.clone(),
            cons,
            x: rest.vertices.clone(),
            v: vec![Vec3::ZERO; n],
            pinned: vec![false; n],
            pin_list: Vec::new(),
            pin_target: rest.vertices.clone(),
            free: Vec::new(),
            pattern: ScalarPattern::new(0, &[])?,
            base: Vec::new(),
            solver: None,
            contact_w,
            factored: vec![false; n],
            steps_since_refactor: 0,
            steps_taken: 0,
            last_force: vec![0.0; n],
            body_vel: vec![Vec3::ZERO; n],
            near_face: vec![crate::collide::NO_FACE; n],
            known: Vec::new(),
            far: vec![None; n],
            stick: vec![None; n],
        };
        sim.build_system()?;
        Ok(sim)
    }

    /// (Re)builds the free-vertex numbering and factorises the system matrix without
    /// contacts: `M/h^2 + sum w_c S_c^T S_c` with the off-diagonal entries of the stretch
    /// edges between free vertices only (see [`crate::pd`]).
    fn build_system(&mut self) -> Result<()> {
        let n = self.x.len();
        let free: Vec<u32> = (0..n as u32)
            .filter(|&i| !self.pinned[i as usize])
            .collect();
        let mut fidx = vec![u32::MAX; n];
        for (k, &i) in free.iter().enumerate() {
            fidx[i as usize] = k as u32;
        }
        let h = self.params.dt as f64;
        let mut diag: Vec<f64> = free
            .iter()
            .map(|&i| self.cons.mass[i as usize] / (h * h))
            .collect();
        let mut pairs = Vec::new();
        let mut pair_w = Vec::new();
        for (c, (&[a, b], &w)) in self.cons.pairs.iter().zip(&self.cons.weight).enumerate() {
            let (fa, fb) = (fidx[a as usize], fidx[b as usize]);
            if fa != u32::MAX {
                diag[fa as usize] += w;
            }
            if fb != u32::MAX {
                diag[fb as usize] += w;
            }
            if c < self.cons.n_stretch && fa != u32::MAX && fb != u32::MAX {
                pairs.push((fa, fb));
                pair_w.push(w);
            }
        }
        let pattern = ScalarPattern::new(free.len(), &pairs)?;
        let mut base = vec![0.0; pattern.nnz()];
        for (k, &d) in diag.iter().enumerate() {
            base[pattern.diag(k)] = d;
        }
        for (p, &w) in pair_w.iter().enumerate() {
            base[pattern.off[p] as usize] -= w;
        }
        let solver = if free.is_empty() {
            None
        } else {
            let mut s =
                SpdSolver::new(free.len(), pattern.col_ptr.clone(), pattern.row_idx.clone())?;
            s.factor(&base)?;
            Some(s)
        };
        self.free = free;
        self.pattern = pattern;
        self.base = base;
        self.solver = solver;
        self.factored.fill(false);
        self.steps_since_refactor = 0;
        Ok(())
    }

    /// Refactorises the system with the contact weights of the vertices flagged in `set`
    /// (`[N]`). On failure keeps the factor without contacts and returns the error.
    pub(crate) fn refactor(&mut self, set: &[bool]) -> Result<()> {
        let Some(solver) = self.solver.as_mut() else {
            return Ok(());
        };
        let mut values = self.base.clone();
        for (k, &v) in self.free.iter().enumerate() {
            if set[v as usize] {
                values[self.pattern.diag(k)] += self.contact_w[v as usize];
            }
        }
        self.steps_since_refactor = 0;
        if let Err(e) = solver.factor(&values) {
            self.factored.fill(false);
            solver.factor(&self.base)?;
            return Err(e);
        }
        self.factored.copy_from_slice(set);
        Ok(())
    }

    /// Current positions `[N]`, metres.
    pub fn positions(&self) -> &[Vec3] {
        &self.x
    }

    /// Current velocities `[N]`, m/s.
    pub fn velocities(&self) -> &[Vec3] {
        &self.v
    }

    /// The cloth's faces `[F]` (as given to [`ClothSim::new`]).
    pub fn faces(&self) -> &[[u32; 3]] {
        &self.faces
    }

    /// The parameters the simulation was built with.
    pub fn params(&self) -> &ClothParams {
        &self.params
    }

    /// Vertex masses `[N]`, kg.
    pub fn masses(&self) -> &[f64] {
        &self.cons.mass
    }

    /// The edges `[E]` (`a < b`, sorted as [`geom::adjacency::edges`]) of the cloth, elastic
    /// ones included.
    pub fn edges(&self) -> &[[u32; 2]] {
        &self.cons.pairs[..self.cons.n_stretch]
    }

    /// `[E]` whether each edge (order of [`ClothSim::edges`]) is elastic: softer than the
    /// cloth.
    pub fn elastic_edges(&self) -> Vec<bool> {
        (0..self.cons.n_stretch)
            .map(|c| self.cons.is_elastic(c))
            .collect()
    }

    /// The pinned (kinematic) vertices, ascending.
    pub fn pinned(&self) -> &[u32] {
        &self.pin_list
    }

    /// Teleports the cloth to `p` (`[N]`, metres) and zeroes the velocities and the contact
    /// memory; pinned vertices stay pinned, at their new positions. Fails on a length mismatch
    /// or a non-finite coordinate (naming the vertex), leaving the state unchanged.
    pub fn set_positions(&mut self, p: &[Vec3]) -> Result<()> {
        if p.len() != self.x.len() {
            return Err(SimError::InvalidInput(format!(
                "cloth has {} vertices, set_positions got {}",
                self.x.len(),
                p.len()
            )));
        }
        check_finite("set_positions", p)?;
        self.x.copy_from_slice(p);
        self.pin_target.copy_from_slice(p);
        self.v.fill(Vec3::ZERO);
        self.last_force.fill(0.0);
        self.body_vel.fill(Vec3::ZERO);
        self.stick.fill(None);
        Ok(())
    }

    /// Makes the vertices `pinned` (indices `< N`, any order, duplicates allowed) kinematic:
    /// they stay where they are (or go where [`ClothSim::move_pinned`] sends them) and are not
    /// simulated; every other vertex becomes free. Rebuilds and refactorises the system
    /// (tens of milliseconds for 10k vertices). Fails on an index out of range, leaving the
    /// state unchanged.
    pub fn set_pinned(&mut self, pinned: &[u32]) -> Result<()> {
        let n = self.x.len();
        if let Some(&bad) = pinned.iter().find(|&&i| i as usize >= n) {
            return Err(SimError::InvalidInput(format!(
                "pinned vertex {bad} is out of range ({n} vertices)"
            )));
        }
        let old = self.pinned.clone();
        self.pinned.fill(false);
        for &i in pinned {
            self.pinned[i as usize] = true;
        }
        if let Err(e) = self.build_system() {
            self.pinned = old;
            self.build_system()?;
            return Err(e);
        }
        self.pin_list = (0..n as u32).filter(|&i| self.pinned[i as usize]).collect();
        for &i in &self.pin_list {
            self.pin_target[i as usize] = self.x[i as usize];
            self.v[i as usize] = Vec3::ZERO;
        }
        Ok(())
    }

    /// Sets where the pinned vertices will be at the end of the next step: `targets` is `[P]`
    /// positions (metres) in the order of [`ClothSim::pinned`]. They move linearly during the
    /// step. Fails on a length mismatch or a non-finite coordinate.
    pub fn move_pinned(&mut self, targets: &[Vec3]) -> Result<()> {
        if targets.len() != self.pin_list.len() {
            return Err(SimError::InvalidInput(format!(
                "{} pinned vertices, move_pinned got {} targets",
                self.pin_list.len(),
                targets.len()
            )));
        }
        check_finite("move_pinned", targets)?;
        for (&i, &t) in self.pin_list.iter().zip(targets) {
            self.pin_target[i as usize] = t;
        }
        Ok(())
    }

    /// Kinetic energy `sum 1/2 m |v|^2`, joules.
    pub fn kinetic_energy(&self) -> f32 {
        self.cons
            .mass
            .iter()
            .zip(&self.v)
            .map(|(&m, v)| 0.5 * m * v.length_squared() as f64)
            .sum::<f64>() as f32
    }

    /// Elastic energy of the stretch and bending constraints at the current positions,
    /// `sum 1/2 w (|x_a - x_b| - r)^2`, joules.
    pub fn elastic_energy(&self) -> f32 {
        let x: Vec<DVec3> = self.x.iter().map(|p| p.as_dvec3()).collect();
        self.cons.energy(&x) as f32
    }

    /// Strains of the cloth's edges that are not elastic (in the order of
    /// [`ClothSim::edges`], elastic ones skipped): current length / rest length - 1. All
    /// `[E]` edges when nothing is elastic.
    pub fn strains(&self) -> Vec<f32> {
        self.split_strains(false)
    }

    /// Strains of the elastic edges (order of [`ClothSim::edges`]), each against its own
    /// rest length: how far the elastic is stretched.
    pub fn elastic_strains(&self) -> Vec<f32> {
        self.split_strains(true)
    }

    fn split_strains(&self, elastic: bool) -> Vec<f32> {
        let strains = self.cons.strains(&self.x).into_iter().enumerate();
        strains
            .filter(|&(c, _)| self.cons.is_elastic(c) == elastic)
            .map(|(_, e)| e)
            .collect()
    }

    /// Vertex strains `[N]`: the largest strain of each vertex's cloth edges, elastic ones
    /// left out (0 without such edges).
    pub fn vertex_strains(&self) -> Vec<f32> {
        self.cons.vertex_strains(&self.x)
    }
}
