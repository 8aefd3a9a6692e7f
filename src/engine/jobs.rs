//! Asynchronous jobs: their state, progress and cancellation, kept for a retention time
//! after they finish so that clients can collect the result, then forgotten.

use std::collections::HashMap;
use std::sync::{Arc, Mutex, OnceLock};
use std::time::{Duration, Instant};

use serde::Serialize;
use tokio::sync::watch;
use tokio_util::sync::CancellationToken;
use utoipa::ToSchema;
use uuid::Uuid;

use super::cache::Solved;
use super::Control;
use crate::job::{JobError, JobKind};

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
}

impl JobStatus {
    pub fn as_str(self) -> &'static str {
        match self {
            JobStatus::Queued => "queued",
            JobStatus::Running => "running",
            JobStatus::Succeeded => "succeeded",
            JobStatus::Failed => "failed",
            JobStatus::Cancelled => "cancelled",
        }
    }

    pub fn is_finished(self) -> bool {
        matches!(
            self,
            JobStatus::Succeeded | JobStatus::Failed | JobStatus::Cancelled
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
}

impl JobState {
    pub fn status(&self) -> JobStatus {
        match self {
            JobState::Queued => JobStatus::Queued,
            JobState::Running => JobStatus::Running,
            JobState::Succeeded(_) => JobStatus::Succeeded,
            JobState::Failed(_) => JobStatus::Failed,
            JobState::Cancelled => JobStatus::Cancelled,
        }
    }
}

/// One asynchronous job.
#[derive(Debug)]
pub struct JobEntry {
    pub id: Uuid,
    pub kind: JobKind,
    /// Rolling solves the job takes.
    pub total: usize,
    control: Arc<Control>,
    /// Wakes a job still waiting for a permit when it is cancelled (the solver itself
    /// watches `control`).
    cancel: CancellationToken,
    state: watch::Sender<JobState>,
    finished_at: OnceLock<Instant>,
}

impl JobEntry {
    pub fn new(kind: JobKind, total: usize, control: Arc<Control>) -> Self {
        JobEntry {
            id: Uuid::new_v4(),
            kind,
            total,
            control,
            cancel: CancellationToken::new(),
            state: watch::Sender::new(JobState::Queued),
            finished_at: OnceLock::new(),
        }
    }

    pub fn control(&self) -> Arc<Control> {
        self.control.clone()
    }

    pub fn state(&self) -> JobState {
        self.state.borrow().clone()
    }

    /// Rolling solves done so far.
    pub fn done(&self) -> usize {
        match *self.state.borrow() {
            JobState::Succeeded(_) => self.total,
            _ => self.control.done(),
        }
    }

    /// A receiver that sees every change of state.
    pub fn subscribe(&self) -> watch::Receiver<JobState> {
        self.state.subscribe()
    }

    /// Asks the job to stop: at once if it is queued, at the solver's next check if it runs.
    pub fn cancel(&self) {
        self.cancel.cancel();
        self.control.cancel();
    }

    /// Resolves when [`JobEntry::cancel`] was called.
    pub async fn cancelled(&self) {
        self.cancel.cancelled().await;
    }

    pub(super) fn set_state(&self, state: JobState) {
        if state.status().is_finished() {
            self.finished_at.get_or_init(Instant::now);
        }
        self.state.send_replace(state);
    }

    fn expired(&self, retention: Duration, now: Instant) -> bool {
        self.finished_at
            .get()
            .is_some_and(|&t| now.duration_since(t) >= retention)
    }
}

/// The jobs of one service.
#[derive(Debug)]
pub struct JobStore {
    jobs: Mutex<HashMap<Uuid, Arc<JobEntry>>>,
    retention: Duration,
}

impl JobStore {
    /// A store that forgets a job `retention` after it finished.
    pub fn new(retention: Duration) -> Self {
        JobStore {
            jobs: Mutex::default(),
            retention,
        }
    }

    fn jobs(&self) -> std::sync::MutexGuard<'_, HashMap<Uuid, Arc<JobEntry>>> {
        self.jobs.lock().unwrap_or_else(|p| p.into_inner())
    }

    pub fn insert(&self, entry: JobEntry) -> Arc<JobEntry> {
        let entry = Arc::new(entry);
        self.jobs().insert(entry.id, entry.clone());
        entry
    }

    /// The job `id`, unless unknown or expired.
    pub fn get(&self, id: Uuid) -> Option<Arc<JobEntry>> {
        let mut jobs = self.jobs();
        let entry = jobs.get(&id)?;
        if entry.expired(self.retention, Instant::now()) {
            jobs.remove(&id);
            return None;
        }
        Some(entry.clone())
    }

    /// Forgets the expired jobs; returns how many.
    pub fn purge_expired(&self) -> usize {
        let now = Instant::now();
        let mut jobs = self.jobs();
        let before = jobs.len();
        jobs.retain(|_, e| !e.expired(self.retention, now));
        before - jobs.len()
    }

    /// The jobs in `status`.
    pub fn with_status(&self, status: JobStatus) -> Vec<Arc<JobEntry>> {
        self.jobs()
            .values()
            .filter(|e| e.state().status() == status)
            .cloned()
            .collect()
    }
}
