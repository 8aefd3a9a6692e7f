//! thirdbody: real contact area and friction of hard particles rolling between two surfaces,
//! one coated with a viscoelastic (Kelvin) layer.
//!
//! Data flows one way: a job arrives as JSON ([`job`]), is validated into model inputs,
//! dispatched by the [`engine`], solved by the [`model`] (pure numerics), and its answer
//! leaves through the [`render`] layer (JSON, CSV). [`http`] is the same path as a web
//! service.

pub mod check;
pub mod engine;
pub mod http;
pub mod job;
pub use thirdbody_model as model;
pub mod render;
