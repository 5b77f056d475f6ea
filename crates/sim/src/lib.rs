//! garnet's cloth simulator (see DESIGN.md section 6).
//!
//! [`ClothSim`] simulates a triangle mesh of cloth: per-vertex masses from an area density,
//! stretch as edge-distance constraints, bending as distances between vertices two edges
//! apart (NvCloth's model), gravity, damping, and Coulomb friction against a moving closed
//! body ([`BodyCollider`]).
//!
//! Each step is implicit Euler solved by projective dynamics ([`pd`]): a global solve per
//! iteration with one sparse Cholesky factorisation ([`solver`], faer) of a matrix that only
//! changes when pins or the set of contacts change (then refactorised numerically, same
//! pattern), Chebyshev-accelerated. Contacts with the body are constraints inside that
//! solve (a push out of the body's tangent plane plus Coulomb friction toward a
//! body-carried anchor); a projection after the solve keeps every vertex out of the body
//! ([`step`]). [`reference`](mod@reference) holds plain versions of the optimised kernels for tests;
//! [`shapes`] builds procedural test scenes (capsule body, tube shirt).
//!
//! Units: metres, seconds, kilograms; Y up; gravity -Y.

#![warn(missing_docs)]

pub mod cloth;
pub mod collide;
pub mod constraints;
pub mod drape;
pub mod error;
pub mod morph;
pub mod params;
pub mod pd;
pub mod reference;
pub mod shapes;
pub mod solver;
pub mod stats;
pub mod step;
pub mod waistband;

pub use cloth::{ClothSim, StepInfo, MAX_SPEED};
pub use collide::BodyCollider;
pub use error::{Result, SimError};
pub use params::ClothParams;
