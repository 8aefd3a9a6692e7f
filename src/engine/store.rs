//! Asynchronous jobs' records: what a client polling a job sees, kept for a retention time
//! after the job finishes, then forgotten. [`JobStore`] is the seam a shared store plugs
//! into; [`MemoryJobStore`] is the default. A record holds no live handle: the cancel flag
//! and the progress count of a running job stay with the process that runs it.

use std::collections::HashMap;
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use async_trait::async_trait;
use serde::Serialize;
use utoipa::ToSchema;
use uuid::Uuid;

use super::cache::Solved;
use crate::job::{JobError, Work};

/// Where a job is in its life.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum JobStatus {
    /// Waiting for a solver thread.
    Queued,
    Running,
    Succeeded,
    Failed,
    Cancelled,
    /// Stopped unfinished because the service shut down (it ran out of its drain time).
    Interrupted,
}

impl JobStatus {
    pub fn as_str(self) -> &'static str {
        match self {
            JobStatus::Queued => "queued",
            JobStatus::Running => "running",
            JobStatus::Succeeded => "succeeded",
            JobStatus::Failed => "failed",
            JobStatus::Cancelled => "cancelled",
            JobStatus::Interrupted => "interrupted",
        }
    }

    pub fn is_finished(self) -> bool {
        matches!(
            self,
            JobStatus::Succeeded
                | JobStatus::Failed
                | JobStatus::Cancelled
                | JobStatus::Interrupted
        )
    }
}

/// A job's state, with its answer or error once it has one.
#[derive(Clone, Debug)]
pub enum JobState {
    Queued,
    Running,
    Succeeded(Arc<Solved>),
    Failed(JobError),
    Cancelled,
    Interrupted,
}

impl JobState {
    pub fn status(&self) -> JobStatus {
        match self {
            JobState::Queued => JobStatus::Queued,
            JobState::Running => JobStatus::Running,
            JobState::Succeeded(_) => JobStatus::Succeeded,
            JobState::Failed(_) => JobStatus::Failed,
            JobState::Cancelled => JobStatus::Cancelled,
            JobState::Interrupted => JobStatus::Interrupted,
        }
    }
}

/// The record of one asynchronous job.
#[derive(Clone, Debug)]
pub struct JobRecord {
    pub id: Uuid,
    /// The job's kind, by its name on the wire.
    pub kind: &'static str,
    /// The work the job takes.
    pub work: Work,
    pub state: JobState,
    /// Work done when the record was last written (a running job's own count is live in
    /// the process that runs it).
    pub done: usize,
    /// When it finished, once it has.
    pub finished_at: Option<Instant>,
}

impl JobRecord {
    /// A job just accepted, whose id is `id`.
    pub fn queued(id: Uuid, kind: &'static str, work: Work) -> JobRecord {
        JobRecord {
            id,
            kind,
            work,
            state: JobState::Queued,
            done: 0,
            finished_at: None,
        }
    }

    fn expired(&self, retention: Duration, now: Instant) -> bool {
        self.finished_at
            .is_some_and(|t| now.duration_since(t) >= retention)
    }
}

/// Where the records of asynchronous jobs are kept.
#[async_trait]
pub trait JobStore: Send + Sync {
    async fn insert(&self, record: JobRecord);
    /// The job `id`, unless unknown or expired.
    async fn get(&self, id: Uuid) -> Option<JobRecord>;
    /// Moves the job `id` to `state` with `done` units of work done; a finished state
    /// starts its retention.
    async fn update(&self, id: Uuid, state: JobState, done: usize);
    /// Forgets the jobs past their retention; returns how many.
    async fn purge_expired(&self) -> usize;
}

/// The records of one process's jobs.
#[derive(Debug)]
pub struct MemoryJobStore {
    jobs: Mutex<HashMap<Uuid, JobRecord>>,
    retention: Duration,
}

impl MemoryJobStore {
    /// A store that forgets a job `retention` after it finished.
    pub fn new(retention: Duration) -> Self {
        MemoryJobStore {
            jobs: Mutex::default(),
            retention,
        }
    }

    fn jobs(&self) -> MutexGuard<'_, HashMap<Uuid, JobRecord>> {
        self.jobs.lock().unwrap_or_else(|p| p.into_inner())
    }
}

#[async_trait]
impl JobStore for MemoryJobStore {
    async fn insert(&self, record: JobRecord) {
        self.jobs().insert(record.id, record);
    }

    async fn get(&self, id: Uuid) -> Option<JobRecord> {
        let mut jobs = self.jobs();
        let record = jobs.get(&id)?;
        if record.expired(self.retention, Instant::now()) {
            jobs.remove(&id);
            return None;
        }
        Some(record.clone())
    }

    async fn update(&self, id: Uuid, state: JobState, done: usize) {
        if let Some(record) = self.jobs().get_mut(&id) {
            if state.status().is_finished() {
                record.finished_at.get_or_insert_with(Instant::now);
            }
            record.state = state;
            record.done = done;
        }
    }

    async fn purge_expired(&self) -> usize {
        let now = Instant::now();
        let mut jobs = self.jobs();
        let before = jobs.len();
        jobs.retain(|_, r| !r.expired(self.retention, now));
        before - jobs.len()
    }
}
