//! The limits of an engine, as the service's settings give them.

use std::time::Duration;

#[derive(Clone, Debug, PartialEq)]
pub struct EngineConfig {
    /// Solver threads, and so jobs solved at once.
    pub pool_size: usize,
    /// How long a synchronous solve may take.
    pub solve_deadline: Duration,
    /// How long an asynchronous job may take from its submission.
    pub job_deadline: Duration,
    /// Asynchronous jobs that may wait for a solver thread.
    pub max_queued_jobs: usize,
    /// Memory for everything kept between requests (bytes, estimated; see `budget`).
    pub memory_budget: u64,
    /// Records of asynchronous jobs kept at most (the oldest finished are forgotten first).
    pub max_jobs: usize,
    /// How long an answer stays cached.
    pub cache_ttl: Duration,
    /// How long a finished job's record and result stay in memory for its client.
    pub job_retention: Duration,
    /// The database of saved analyses (which keeps results beyond the memory budget too): a
    /// file, or [`super::archive::IN_MEMORY`] (such results are then refused).
    pub database: String,
    /// How long finished jobs are kept in the history (the database, or the fleet's Redis).
    pub history_retention: Duration,
}
