//! The layer as a continuum (docs/model.md §8): a viscoelastic solid bonded to a rigid base,
//! rather than the paper's local (Winkler) law of independent springs. At the paper's own
//! parameters the contact is a few nanometres wide on a 100 nm layer, where the local law
//! overstates the area several times; this is the law that answers there.
//!
//! At rest and axisymmetric: [`static_contact`] (rings, exact to 0.1 %) and its table
//! [`static_area`] (the local-layer row of every answer). Before any work: [`plan`] (the
//! route, the grids, the memory and cost of an answer, or why it is refused). On the pixel grid: [`Influence`]
//! (the free FFT convolution of the layer's response), [`press`] (a sphere at rest, or the
//! symmetric step of a march) and [`roll`] (steady rolling, marched), and [`solve`], the
//! rolling answer with its error from two grids and two domains.

mod answer;
mod axisymmetric;
mod compliance;
mod curve;
mod grid;
mod plan;
mod pressed;
mod rolling;
mod shape;
mod table;
mod thin;

pub use answer::{
    area_floor, solve, solve_at, ContinuumVerification, GridUsed, QuantityErrors, AREA_SCATTER,
    EDGE_BIAS,
};
pub use axisymmetric::{static_contact, StaticContinuum};
pub use compliance::{
    constrained_modulus, contact_modulus, layer_correction, layer_factor, young_modulus,
};
pub use curve::PenetrationCurve;
pub use grid::{Grid, Influence};
pub use plan::{
    plan, Domain, Fineness, Marches, Plan, Route, TooFine, MAX_PIXELS, PER_RADIUS, THIN,
    THIN_POISSON,
};
pub use pressed::{area_between, press, row_edges, GridContact, Pressing, Springs, Surface};
pub use rolling::{roll, Rolled, RolledContact};
pub use table::{hertz_radius, static_area};
pub use thin::thin_error;
