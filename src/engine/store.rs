//! Asynchronous jobs' records: what a client polling a job sees, kept for a retention time
//! after the job finishes, then forgotten. [`JobStore`] is the seam a shared store plugs
//! into; [`MemoryJobStore`] is the default. A record holds no live handle: the cancel flag
//! and the progress count of a running job stay with the process that runs it.

use std::collections::{HashMap, VecDeque};
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
    /// Succeeded, but its result was dropped to keep within the memory budget: the answer
    /// may still be in the cache under `key`.
    Dropped {
        key: String,
    },
}

impl JobState {
    pub fn status(&self) -> JobStatus {
        match self {
            JobState::Queued => JobStatus::Queued,
            JobState::Running => JobStatus::Running,
            JobState::Succeeded(_) | JobState::Dropped { .. } => JobStatus::Succeeded,
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
    /// Forgets the job `id`.
    async fn remove(&self, id: Uuid);
    /// Forgets the jobs past their retention; returns how many.
    async fn purge_expired(&self) -> usize;

    /// Whether every process of the fleet shares the store (so any of them answers for any
    /// job, and a job unknown to it is unknown to all).
    fn shared(&self) -> bool {
        false
    }
}

/// The records of one process's jobs, at most `max_jobs` of them (the oldest finished are
/// forgotten first) holding at most `result_bytes` of results (the oldest results are dropped
/// first: their records stay and say so).
#[derive(Debug)]
pub struct MemoryJobStore {
    records: Mutex<Records>,
    retention: Duration,
    max_jobs: usize,
    result_bytes: u64,
}

#[derive(Debug, Default)]
struct Records {
    jobs: HashMap<Uuid, JobRecord>,
    /// Finished jobs, oldest first (ids may have been forgotten since).
    finished: VecDeque<Uuid>,
    /// Bytes of the results held.
    held: u64,
}

impl Records {
    fn result_weight(record: &JobRecord) -> u64 {
        match &record.state {
            JobState::Succeeded(solved) => solved.weight(),
            _ => 0,
        }
    }

    fn forget(&mut self, id: &Uuid) {
        if let Some(record) = self.jobs.remove(id) {
            self.held -= Records::result_weight(&record);
        }
    }

    /// Forgets the oldest finished job; false if there is none.
    fn forget_oldest(&mut self) -> bool {
        while let Some(id) = self.finished.pop_front() {
            if self.jobs.contains_key(&id) {
                self.forget(&id);
                return true;
            }
        }
        false
    }

    /// Drops the results of the oldest finished jobs until at most `limit` bytes are held.
    fn drop_results(&mut self, limit: u64) {
        let mut oldest = self.finished.iter();
        while self.held > limit {
            let Some(record) = oldest.next().and_then(|id| self.jobs.get_mut(id)) else {
                if oldest.len() == 0 {
                    break;
                }
                continue;
            };
            if let JobState::Succeeded(solved) = &record.state {
                self.held -= solved.weight();
                record.state = JobState::Dropped {
                    key: solved.key.clone(),
                };
            }
        }
    }
}

impl MemoryJobStore {
    /// A store that forgets a job `retention` after it finished, keeps at most `max_jobs`
    /// records and `result_bytes` of their results.
    pub fn new(retention: Duration, max_jobs: usize, result_bytes: u64) -> Self {
        MemoryJobStore {
            records: Mutex::default(),
            retention,
            max_jobs: max_jobs.max(1),
            result_bytes,
        }
    }

    fn records(&self) -> MutexGuard<'_, Records> {
        self.records.lock().unwrap_or_else(|p| p.into_inner())
    }
}

#[async_trait]
impl JobStore for MemoryJobStore {
    async fn insert(&self, record: JobRecord) {
        let mut records = self.records();
        while records.jobs.len() >= self.max_jobs && records.forget_oldest() {}
        records.jobs.insert(record.id, record);
    }

    async fn get(&self, id: Uuid) -> Option<JobRecord> {
        let mut records = self.records();
        let record = records.jobs.get(&id)?;
        if record.expired(self.retention, Instant::now()) {
            records.forget(&id);
            return None;
        }
        Some(record.clone())
    }

    async fn update(&self, id: Uuid, state: JobState, done: usize) {
        let mut records = self.records();
        let added = match &state {
            JobState::Succeeded(solved) => solved.weight(),
            _ => 0,
        };
        let Some(record) = records.jobs.get_mut(&id) else {
            return;
        };
        let finished = state.status().is_finished() && record.finished_at.is_none();
        if finished {
            record.finished_at = Some(Instant::now());
        }
        record.state = state;
        record.done = done;
        if finished {
            records.finished.push_back(id);
        }
        records.held += added;
        records.drop_results(self.result_bytes);
    }

    async fn remove(&self, id: Uuid) {
        self.records().forget(&id);
    }

    async fn purge_expired(&self) -> usize {
        let now = Instant::now();
        let mut records = self.records();
        let expired: Vec<Uuid> = records
            .jobs
            .values()
            .filter(|r| r.expired(self.retention, now))
            .map(|r| r.id)
            .collect();
        for id in &expired {
            records.forget(id);
        }
        let Records { jobs, finished, .. } = &mut *records;
        finished.retain(|id| jobs.contains_key(id));
        expired.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::{Answer, Cell, Column, Output, Table, Units};
    use serde::Serialize;

    #[derive(Debug, PartialEq, Serialize)]
    struct Blob {
        text: String,
    }

    impl Output for Blob {
        const UNITS: Units = &[];
        fn table(&self) -> Table {
            Table::new(&[Column::text("text", |b: &Blob| b.text.clone())], [self])
        }
    }

    fn solved(key: &str, bytes: usize) -> Arc<Solved> {
        let blob = Blob {
            text: "x".repeat(bytes),
        };
        Arc::new(Solved::new(key.to_string(), "rolling", Answer::new(blob)).unwrap())
    }

    #[tokio::test]
    async fn the_oldest_results_are_dropped_first_and_their_records_say_so() {
        let one = solved("a", 1000).weight();
        let store = MemoryJobStore::new(Duration::from_secs(60), 100, 2 * one + one / 2);
        let mut ids = Vec::new();
        for key in ["a", "b", "c"] {
            let record = JobRecord::queued(Uuid::new_v4(), "rolling", Work::Known(1));
            ids.push(record.id);
            store.insert(record).await;
            store
                .update(
                    ids[ids.len() - 1],
                    JobState::Succeeded(solved(key, 1000)),
                    1,
                )
                .await;
        }
        let first = store.get(ids[0]).await.unwrap();
        assert!(matches!(first.state, JobState::Dropped { ref key } if key == "a"));
        assert_eq!(first.state.status(), JobStatus::Succeeded);
        for id in &ids[1..] {
            assert!(matches!(
                store.get(*id).await.unwrap().state,
                JobState::Succeeded(_)
            ));
        }
    }

    #[tokio::test]
    async fn at_most_max_jobs_records_are_kept_the_oldest_finished_forgotten() {
        let store = MemoryJobStore::new(Duration::from_secs(60), 3, 1 << 20);
        let mut ids = Vec::new();
        for _ in 0..5 {
            let record = JobRecord::queued(Uuid::new_v4(), "rolling", Work::Known(1));
            ids.push(record.id);
            store.insert(record).await;
            store
                .update(ids[ids.len() - 1], JobState::Cancelled, 0)
                .await;
        }
        assert!(store.get(ids[0]).await.is_none() && store.get(ids[1]).await.is_none());
        for id in &ids[2..] {
            assert!(store.get(*id).await.is_some());
        }
        let _ = Cell::Count(0);
    }
}
