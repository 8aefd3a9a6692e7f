//! The layer as a continuum (docs/model.md §8): a viscoelastic solid bonded to a rigid base,
//! rather than the paper's local (Winkler) law of independent springs. At the paper's own
//! parameters the contact is a few nanometres wide on a 100 nm layer, where the local law
//! overstates the area several times; this is the law that answers there.
//!
//! At rest and axisymmetric: [`static_contact`] (rings, exact to 0.1 %) and its table
//! [`static_area`] (the local-layer row of every answer). On the pixel grid: [`Influence`]
//! (the free FFT convolution of the layer's response), [`press`] (a sphere at rest, or the
//! symmetric step of a march) and [`roll`] (steady rolling, marched). The grid solver is
//! not yet an answer of the service: its area errs by about 1.3/n on n pixels a side
//! (first order, smooth, so two resolutions extrapolate it), and its error and domain are
//! not yet measured per answer (issue 23).

mod axisymmetric;
mod compliance;
mod grid;
mod pressed;
mod rolling;
mod table;

pub use axisymmetric::{static_contact, StaticContinuum};
pub use compliance::{contact_modulus, layer_correction, layer_factor, young_modulus};
pub use grid::Influence;
pub use pressed::{grid_for, press, sub_cell_area, GridContact, Pressing, Springs, Surface};
pub use rolling::{roll, RolledContact};
pub use table::{hertz_radius, static_area};
