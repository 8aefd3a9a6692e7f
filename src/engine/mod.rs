//! Runs validated jobs. The command line calls [`run`] directly. The HTTP service goes
//! through an [`Engine`]: admission on a pool of permits sized to the cores ([`pool`]), a
//! result cache ([`cache`]) in front of which identical misses share one solve, and a store
//! of asynchronous jobs ([`store`]); the cache and the store are traits, so that a shared
//! backend (the [`fleet`]'s) can take the place of the in-process ones.

pub mod admission;
pub mod archive;
mod backlog;
mod bounded;
mod budget;
pub mod cache;
pub mod clock;
mod coalesce;
mod config;
mod doorkeeper;
mod error;
pub mod fleet;
pub mod heavy;
mod ids;
pub mod lifecycle;
mod local;
mod memo;
pub mod metrics;
pub mod pool;
pub mod quota;
mod service;
mod solver;
mod storage;
pub mod store;

pub use backlog::Backlogged;
pub use config::EngineConfig;
pub use error::EngineError;
pub use ids::Unknown;
pub use service::Engine;
pub use solver::{CacheStatus, CacheUse, Solver};
pub use storage::Storage;

use std::sync::{Mutex, MutexGuard, PoisonError};

use crate::job::{Control, Job, JobError};
use crate::render::Answer;

/// Locks `mutex`, even if a holder panicked: every holder leaves what it guards whole, and
/// one failed request must not wedge the engine.
pub(crate) fn lock<T>(mutex: &Mutex<T>) -> MutexGuard<'_, T> {
    mutex.lock().unwrap_or_else(PoisonError::into_inner)
}

/// Runs `job` to its answer, or until `control` stops it.
pub fn run(job: &Job, control: &Control) -> Result<Answer, JobError> {
    job.run(job.meta(), control)
}
