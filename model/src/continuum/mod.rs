//! The layer as a continuum (docs/model.md §8): a viscoelastic solid bonded to a rigid base,
//! rather than the paper's local (Winkler) law of independent springs. At the paper's own
//! parameters the contact is a few nanometres wide on a 100 nm layer, where the local law
//! overstates the area several times; this is the law that answers there.

mod axisymmetric;
mod compliance;
mod table;

pub use axisymmetric::{static_contact, StaticContinuum};
pub use compliance::{contact_modulus, layer_correction, layer_factor, young_modulus};
pub use table::{hertz_radius, static_area};
