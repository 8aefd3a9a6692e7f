use std::time::Duration;

use super::backlog::Backlogged;
use super::store::{Refusal, Unreadable};
use crate::job::JobError;

/// Why the engine did not answer.
#[derive(Clone, Debug, PartialEq)]
pub enum EngineError {
    /// The job's own error (invalid, failed, past its deadline...).
    Job(JobError),
    /// No solver thread free (synchronous), or the job queue is full (asynchronous).
    Overloaded,
    /// The service is shutting down and takes no new work.
    Draining,
    /// The shared job store cannot be reached (why): asynchronous work is refused rather
    /// than accepted and possibly lost.
    Unavailable(String),
    /// The work accepted before an asynchronous job and its own would not end within its
    /// deadline ([`super::backlog`]).
    Backlogged(Backlogged),
    /// The job store cannot hold the job's result now (what is full, and when room is
    /// next made): the job is refused before any work rather than its result dropped after.
    ResultsFull { what: String, retry_after: Duration },
    /// The job's result would not fit in the job store even if it were empty.
    ResultTooLarge { needed: u64, limit: u64 },
}

impl From<Refusal> for EngineError {
    fn from(refusal: Refusal) -> Self {
        match refusal {
            Refusal::Full { what, retry_after } => EngineError::ResultsFull { what, retry_after },
            Refusal::TooLarge { needed, limit } => EngineError::ResultTooLarge { needed, limit },
            Refusal::Unwritable { why } => EngineError::Unavailable(why),
        }
    }
}

impl From<JobError> for EngineError {
    fn from(e: JobError) -> Self {
        EngineError::Job(e)
    }
}

impl From<Unreadable> for EngineError {
    fn from(e: Unreadable) -> Self {
        EngineError::Unavailable(e.to_string())
    }
}
