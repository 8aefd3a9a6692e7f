//! The physics core: a rigid sphere rolling over a Kelvin layer bonded to a rigid base
//! (docs/model.md §1–3, §5, §6). Pure numerics over plain structs in SI units: no I/O, no async,
//! no serde. Everything else in the crate calls into this module.

pub mod continuum;
pub mod counterface;
mod error;
pub mod figures;
pub mod fit;
mod layer;
pub mod limits;
pub mod motion;
pub mod quadrature;
pub mod rolling;
mod roots;
pub mod similarity;
mod special;
pub mod spectrum;
mod stop;
pub mod strip;
pub mod tables;
pub mod text;
pub mod three_body;
pub mod validity;

pub use error::{ModelError, OptionError, SolveOption};
pub use layer::{Layer, Parameter, ParameterError};
pub use quadrature::Quadrature;
pub use rolling::{solve, Rolling, RollingSolution, SolveOptions};
pub use stop::Stop;

/// Version of the model's numbers: part of every cache key, bumped whenever a result changes.
pub const MODEL_VERSION: &str = "1.6.0";
