//! A rigid sphere rolling at constant speed over the Kelvin layer: penetration, contact
//! region, area, centroid and centre of pressure, friction (docs/model.md §3, eqs. 2–5, 9–12).
//!
//! The solution is computed in units of the static half-width r₀ = √(2Rδ₀): there the
//! contact shape depends only on ξ = V T_σ / r₀ and κ (the similarity law), the load to
//! carry is P̂ = π/4, and no intermediate quantity can over- or underflow.
//!
//! By level, each file one job: [`problem`] is what is asked (wire-free inputs and options),
//! [`solution`] what is answered; [`answer`] assembles an answer in SI units from the contact
//! solved in units of r₀, whose load equation [`load`] solves by strip sums over the contact
//! region of [`section`].

mod answer;
mod load;
mod problem;
mod section;
mod solution;

pub(crate) use answer::solve_with;
pub use answer::{penetration_contact, solve};
pub use problem::{Rolling, SolveOptions, MAX_BOUNDARY_POINTS, MAX_PRESSURE_GRID};
pub use solution::{BoundaryPoint, PressureGrid, RollingSolution, Verification};
