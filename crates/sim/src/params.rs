//! Material and integration parameters.

use glam::Vec3;

use crate::error::{Result, SimError};

/// Parameters of a [`crate::ClothSim`]. Units are SI; the defaults are tuned for cotton-like
/// cloth meshed at about 1 cm edges (the GarNet garments) hanging on a body.
///
/// Stiffnesses are moduli per unit area, so a material behaves about the same at any mesh
/// resolution: a distance constraint between vertices `a` and `b` with rest length `r` gets the
/// weight `w = k * A / r^2` (N/m), where `A` is its share of the surface (each vertex's area
/// split evenly between its constraints of that kind), and the energy
/// `1/2 w (|x_a - x_b| - r)^2 = 1/2 k A strain^2`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClothParams {
    /// Area density, kg/m^2 (cotton T-shirt jersey about 0.15).
    pub density: f32,
    /// Stretch modulus of the edge-distance constraints, N/m (energy per unit area per unit
    /// strain squared). Large values make the cloth near-inextensible and stay stable, but
    /// the solver's iterations then converge slowly for motions that rotate edges (draping,
    /// folding): at 3e4 a hanging cloth took many seconds to find its shape; the default 3e3
    /// keeps strains under 1% for a hanging garment and drapes promptly.
    pub stretch_stiffness: f32,
    /// Modulus of the bending constraints, N/m: distances between vertices two edges apart
    /// (NvCloth's model), scaled like the stretch weights. Much smaller than the stretch
    /// modulus: it resists folding, not stretching.
    pub bend_stiffness: f32,
    /// Velocity damping rate, 1/s: every step the velocity (relative to the body for vertices
    /// in contact) is divided by `1 + damping * dt`.
    pub damping: f32,
    /// Coulomb friction coefficient between cloth and body (dimensionless).
    pub friction: f32,
    /// Collision thickness, metres: contact constraints hold resting cloth this far outside
    /// the body, and after each step no vertex is closer than half of it (nor inside). A
    /// [`crate::BodyCollider`] has its own thickness; a step uses the larger of the two.
    pub thickness: f32,
    /// Extra distance beyond the thickness (metres) within which a cloth vertex counts as
    /// touching the body: it is carried along by the body's motion and may get a contact
    /// constraint in the solve.
    pub contact_margin: f32,
    /// Gravitational acceleration, m/s^2 (Y is up).
    pub gravity: Vec3,
    /// Time step, seconds.
    pub dt: f32,
    /// Local/global solver iterations per step (projective dynamics).
    pub iterations: u32,
    /// Chebyshev acceleration of the iterations: an estimate of their spectral radius in
    /// `[0, 1)` (Wang 2015); 0 turns it off. Too high a value makes the iterations oscillate.
    pub chebyshev_rho: f32,
    /// Whether a global step solves x and y on one thread while z is solved on another
    /// (`rayon::join`). The drape is the same to the bit either way: faer solves each
    /// column alone. Splitting makes a lone drape faster (`garnet bench sim`, medians: 1.27
    /// against 1.44 s at 2.5 cm), but it walks the factor twice, which costs more than it
    /// gains where other drapes keep every thread busy (the dataset's workers: 27.3 against
    /// 31.8 s of CPU for 18 drapes on two jobs; README "Simulator").
    pub split_solve: bool,
    /// Static friction that holds: a vertex that sticks to the body keeps its friction
    /// anchor from step to step (carried by the body) until it slides, instead of taking
    /// its new place as the next step's anchor. Without it the contact spring's stretch
    /// under a steady tangential load is given up every step, and cloth held by friction
    /// creeps.
    pub static_friction: bool,
}

impl Default for ClothParams {
    /// Cotton jersey (0.15 kg/m^2, stretch 3000 N/m, bend 2 N/m), damping 2/s, friction 0.4,
    /// thickness 4 mm + 4 mm contact margin, 60 steps per second with 8 Chebyshev-accelerated
    /// iterations: measured on a 10k-vertex tube shirt hanging on a capsule (strain p99 under
    /// 1.2% while hanging, at rest in a fraction of a second) and against the catenary.
    fn default() -> Self {
        ClothParams {
            density: 0.15,
            stretch_stiffness: 3000.0,
            bend_stiffness: 2.0,
            damping: 2.0,
            friction: 0.4,
            thickness: 0.004,
            contact_margin: 0.004,
            gravity: Vec3::new(0.0, -9.81, 0.0),
            dt: 1.0 / 60.0,
            iterations: 8,
            chebyshev_rho: 0.95,
            split_solve: true,
            static_friction: false,
        }
    }
}

impl ClothParams {
    /// Checks every field: finite, positive density and time step, non-negative stiffnesses,
    /// damping, friction, thickness and margin, at least one iteration. The message names the
    /// field.
    pub fn validate(&self) -> Result<()> {
        let positive = [("density", self.density), ("dt", self.dt)];
        for (name, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return Err(SimError::InvalidParams(format!(
                    "{name} must be positive and finite, got {v}"
                )));
            }
        }
        let non_negative = [
            ("stretch_stiffness", self.stretch_stiffness),
            ("bend_stiffness", self.bend_stiffness),
            ("damping", self.damping),
            ("friction", self.friction),
            ("thickness", self.thickness),
            ("contact_margin", self.contact_margin),
        ];
        for (name, v) in non_negative {
            if !(v.is_finite() && v >= 0.0) {
                return Err(SimError::InvalidParams(format!(
                    "{name} must be non-negative and finite, got {v}"
                )));
            }
        }
        if !self.gravity.is_finite() {
            return Err(SimError::InvalidParams(format!(
                "gravity must be finite, got {}",
                self.gravity
            )));
        }
        if !(self.chebyshev_rho.is_finite() && (0.0..1.0).contains(&self.chebyshev_rho)) {
            return Err(SimError::InvalidParams(format!(
                "chebyshev_rho must be in [0, 1), got {}",
                self.chebyshev_rho
            )));
        }
        if self.iterations == 0 {
            return Err(SimError::InvalidParams(
                "iterations must be at least 1".into(),
            ));
        }
        Ok(())
    }
}
