//! Asynchronous jobs' records: what a client polling a job sees, kept for a retention time
//! after the job finishes. [`JobStore`] is the seam this process's store
//! ([`super::local`]) and the fleet's plug into.

pub mod memory;
pub mod record;

use async_trait::async_trait;
use uuid::Uuid;

pub use memory::MemoryJobStore;
pub use record::{
    JobRecord, JobResult, JobState, JobStatus, Listing, Owner, Page, Refusal, ResultPlace,
    StoredResult, Unreadable,
};

/// Where the records of asynchronous jobs are kept.
#[async_trait]
pub trait JobStore: Send + Sync {
    /// Records a job just accepted: room is made now for its `result_bytes`, so that the
    /// result is kept for its retention, or the job is refused before any work.
    async fn insert(&self, record: JobRecord) -> Result<(), Refusal>;
    /// The job `id`, unless unknown or expired.
    async fn get(&self, id: Uuid) -> Option<JobRecord>;
    /// Moves the job `id` to `state`; a finished state starts its retention.
    async fn update(&self, id: Uuid, state: JobState, done: usize);
    async fn remove(&self, id: Uuid);
    /// Forgets the jobs past their retention; returns how many.
    async fn purge_expired(&self) -> usize;
    /// The jobs of `listing`'s owner, newest first, filtered and paged.
    async fn list(&self, listing: &Listing) -> Result<Page, Unreadable>;
    /// The newest job that succeeded on the input whose hash is `input_hash`.
    async fn with_input(&self, input_hash: &str) -> Result<Option<JobRecord>, Unreadable>;

    /// Whether every process of the fleet shares the store (a job unknown to it is unknown
    /// to all).
    fn shared(&self) -> bool {
        false
    }

    /// Whether the store outlives the process (a database file, Redis): a job of an earlier
    /// run that it does not know was deleted or expired, not lost with that run.
    fn durable(&self) -> bool;

    /// Why it cannot keep new jobs now, if it cannot (`/readyz` says so).
    fn problem(&self) -> Option<String> {
        None
    }

    /// Saves for good what it could not save before (the process is about to end).
    async fn settle(&self) {}
}
