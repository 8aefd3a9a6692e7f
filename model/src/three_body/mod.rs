//! The three-body system (docs/model.md §4): a population of hard particles, Gaussian in diameter,
//! squeezed between a rigid-backed upper surface and the viscoelastic layer, with optional
//! asperity contact; its real contact area, load and friction coefficient with and without
//! rolling, at a given separation, total load or mean particle load.
//!
//! By level: [`system`] is what is asked (the system, its operating point and the solve's
//! options), [`state`] what is answered; [`solver`] evaluates the system at a separation and
//! finds the operating point's, from the particle contacts of `contact` and `asperities`
//! over the sizes of `distribution`, with the continuum layer's contacts from [`curves`].

mod asperities;
mod contact;
mod curves;
mod distribution;
mod solver;
mod state;
mod system;
mod traction;

pub use crate::counterface::{UpperContact, UpperLaw, UpperSurface};
pub use asperities::{Asperities, Zmc};
pub use contact::{squeeze, LayerLaw, Squeeze};
pub use curves::LayerCurves;
pub use distribution::Diameters;
pub use solver::{solve, solve_with};
pub use state::{
    Areas, ContactState, Loads, ModeChange, SystemMotion, ThreeBodySolution, ThreeBodyVerification,
};
pub use system::{
    LayerContact, OperatingKind, OperatingPoint, Particle, ThreeBody, ThreeBodyOptions,
    DEFAULT_DIAMETER_NODES, MAX_DIAMETER_NODES,
};
