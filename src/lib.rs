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

/// The allocator of every process of the service (and of its tests and benchmarks, which so
/// measure what runs): mimalloc. glibc's, under a cache that keeps replacing answers of a
/// few kB, spent a third of an uncached request searching its fragmented free lists (in
/// process 52 µs a request, 31 µs with mimalloc). Without transparent huge pages: zeroing
/// them cost a short `thirdbody solve` 0.5 ms. (mimalloc's v2 line returned freed pages
/// after 10 ms: a 10,000-point sweep in fleet mode took 71 ms instead of 30.) BENCHMARKS.md,
/// issue 25.
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;
