//! The error type of the simulator.

/// Everything that can go wrong in the simulator. No public function panics on bad input or
/// on a diverging simulation: it returns one of these instead, naming what failed.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// A mesh handed to the simulator does not validate (non-finite coordinate, index out of
    /// range, no faces).
    #[error("invalid mesh: {0}")]
    InvalidMesh(String),
    /// An argument is unusable (wrong length, index out of range, NaN parameter, ...).
    #[error("invalid input: {0}")]
    InvalidInput(String),
    /// A parameter of [`crate::ClothParams`] is out of its range.
    #[error("invalid parameter: {0}")]
    InvalidParams(String),
    /// A vertex position or velocity became non-finite or absurdly fast during a step; the
    /// message names the vertex and the step. The simulation state is left as it was before
    /// the step.
    #[error("simulation diverged: {0}")]
    Diverged(String),
    /// A finished drape failed a check (cloth left inside the body); it is not a result.
    #[error("drape rejected: {0}")]
    Rejected(String),
    /// The sparse Cholesky factorisation of the system matrix failed (it should be positive
    /// definite by construction, so this means degenerate input such as zero mass).
    #[error("linear solver: {0}")]
    Solver(String),
}

impl From<geom::GeomError> for SimError {
    fn from(e: geom::GeomError) -> Self {
        match e {
            geom::GeomError::InvalidMesh(m) => SimError::InvalidMesh(m),
            other => SimError::InvalidInput(other.to_string()),
        }
    }
}

/// Result alias of the crate.
pub type Result<T, E = SimError> = std::result::Result<T, E>;

/// Fails with [`SimError::InvalidInput`] naming the first non-finite point of `points`
/// (`what` says which array it is).
pub(crate) fn check_finite(what: &str, points: &[glam::Vec3]) -> Result<()> {
    match points.iter().position(|p| !p.is_finite()) {
        None => Ok(()),
        Some(i) => Err(SimError::InvalidInput(format!(
            "{what}: vertex {i} is not finite ({}, {}, {})",
            points[i].x, points[i].y, points[i].z
        ))),
    }
}
