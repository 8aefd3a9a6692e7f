//! Jobs: the JSON clients send, validated into model inputs, with their canonical form and
//! the cache key derived from it; and what each kind of job computes.
//!
//! A job kind is one module behind one trait ([`Kind`]): [`rolling`], [`three_body`],
//! [`sweep`], [`figure`], [`fit`], registered by name in [`registry`]. The pieces their inputs share
//! (quantities with units, the layer, the quadrature, the field checker) are in [`input`].
//! The same types serve `thirdbody solve` and the HTTP API. Every input field is optional
//! and defaults to docs/model.md §5; validation reports every bad field at once, each with its
//! value and the allowed range.

mod control;
mod error;
pub mod figure;
pub mod fit;
pub mod input;
mod kind;
pub mod meta;
pub mod parts;
pub mod picture;
pub mod points;
pub mod registry;
pub mod rolling;
pub mod sweep;
pub mod three_body;
pub mod validity;
mod wire;

pub use control::{Control, Kept, Memo, OnRefusal, Swept};
pub use error::{echoed, FieldError, JobError};
pub use figure::FigureJob;
pub use fit::FitJob;
pub use input::Quantity;
pub use kind::{
    input_hash_of, scoped_key, tenant_of, Cost, Job, Keyed, Kind, Unfinished, Validated, Work,
};
pub use meta::{
    InputWarning, Meta, Reference, References, Software, REFERENCES, ROLLING_REFERENCES, SOFTWARE,
};
pub use rolling::RollingJob;
pub use sweep::SweepJob;
pub use three_body::ThreeBodyJob;

/// Limits on the size of a job, beyond the model's own ranges.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limits {
    /// Largest number of points in a sweep (the product of its lists).
    pub max_sweep_points: usize,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_sweep_points: 10_000,
        }
    }
}
