//! The words of asynchronous jobs' records. A record holds no live handle: the cancel flag
//! and the progress count of a running job stay with the process that runs it.

use std::io;
use std::sync::Arc;
use std::time::{Duration, SystemTime};

use async_trait::async_trait;
use bytes::Bytes;
use serde::Serialize;
use utoipa::ToSchema;
use uuid::Uuid;

use crate::engine::cache::Solved;
use crate::engine::clock::age;
use crate::job::registry::KindName;
use crate::job::{JobError, Work};
use crate::render::Format;

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
    /// Every status, in the order of a job's life.
    pub const ALL: [JobStatus; 6] = [
        JobStatus::Queued,
        JobStatus::Running,
        JobStatus::Succeeded,
        JobStatus::Failed,
        JobStatus::Cancelled,
        JobStatus::Interrupted,
    ];

    pub fn parse(text: &str) -> Option<JobStatus> {
        JobStatus::ALL.into_iter().find(|s| s.as_str() == text)
    }

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
        !matches!(self, JobStatus::Queued | JobStatus::Running)
    }
}

/// A job's state, with its answer or error once it has one.
#[derive(Clone, Debug)]
pub enum JobState {
    Queued,
    Running,
    Succeeded(JobResult),
    /// Failed; a job that keeps partial work (a sweep past its deadline) keeps what it did.
    Failed {
        error: JobError,
        partial: Option<JobResult>,
    },
    Cancelled {
        partial: Option<JobResult>,
    },
    Interrupted,
}

impl JobState {
    /// Logs the job's end: an internal failure as an error with its cause (not shown to
    /// clients).
    pub fn log_end(&self, id: impl std::fmt::Display) {
        match self {
            JobState::Failed {
                error: error @ JobError::Internal(_),
                ..
            } => tracing::error!(%id, %error, "job failed inside the service"),
            _ => tracing::info!(%id, status = self.status().as_str(), "job finished"),
        }
    }

    pub fn status(&self) -> JobStatus {
        match self {
            JobState::Queued => JobStatus::Queued,
            JobState::Running => JobStatus::Running,
            JobState::Succeeded(_) => JobStatus::Succeeded,
            JobState::Failed { .. } => JobStatus::Failed,
            JobState::Cancelled { .. } => JobStatus::Cancelled,
            JobState::Interrupted => JobStatus::Interrupted,
        }
    }

    /// The state of a job read back from a store (its `error` is read for a failed job only).
    pub fn restored(
        status: JobStatus,
        result: Option<JobResult>,
        error: impl FnOnce() -> JobError,
    ) -> JobState {
        match status {
            JobStatus::Queued => JobState::Queued,
            JobStatus::Running => JobState::Running,
            JobStatus::Cancelled => JobState::Cancelled { partial: result },
            JobStatus::Interrupted => JobState::Interrupted,
            JobStatus::Failed => JobState::Failed {
                error: error(),
                partial: result,
            },
            JobStatus::Succeeded => match result {
                Some(result) => JobState::Succeeded(result),
                None => JobState::failed(JobError::Internal(
                    "the job's result was lost from the job store".to_string(),
                )),
            },
        }
    }

    pub fn failed(error: JobError) -> JobState {
        JobState::Failed {
            error,
            partial: None,
        }
    }

    /// The result, whole or partial, if the job has one.
    pub fn result(&self) -> Option<&JobResult> {
        match self {
            JobState::Succeeded(result) => Some(result),
            JobState::Failed { partial, .. } | JobState::Cancelled { partial } => partial.as_ref(),
            _ => None,
        }
    }

    pub fn with_result(self, result: JobResult) -> JobState {
        match self {
            JobState::Succeeded(_) => JobState::Succeeded(result),
            JobState::Failed { error, .. } => JobState::Failed {
                error,
                partial: Some(result),
            },
            JobState::Cancelled { .. } => JobState::Cancelled {
                partial: Some(result),
            },
            other => other,
        }
    }
}

/// The record of one asynchronous job.
#[derive(Clone, Debug)]
pub struct JobRecord {
    pub id: Uuid,
    /// The job's kind (its name on the wire, and what draws its answer).
    pub kind: KindName,
    pub work: Work,
    pub state: JobState,
    /// Work done when last written (a running job's own count is live where it runs).
    pub done: usize,
    /// The hash of the job's canonical input (its cache key): equal inputs, equal answers.
    pub input_hash: String,
    /// Who submitted it, if they said ([`Owner`]): the jobs listed to them.
    pub owner: Option<Owner>,
    /// When it was accepted (wall clock: it is shown, and compared across processes).
    pub submitted_at: SystemTime,
    pub finished_at: Option<SystemTime>,
    /// Bytes its answer may take, at most: room made at its acceptance, held for its retention.
    pub result_bytes: u64,
    /// Whether its end could not be saved for good (then memory alone keeps it, and says so).
    pub unsaved: bool,
}

impl JobRecord {
    /// A job just accepted.
    pub fn queued(id: Uuid, kind: KindName, work: Work, input_hash: &str) -> JobRecord {
        JobRecord {
            id,
            kind,
            work,
            state: JobState::Queued,
            done: 0,
            input_hash: input_hash.to_string(),
            owner: None,
            submitted_at: SystemTime::now(),
            finished_at: None,
            result_bytes: 0,
            unsaved: false,
        }
    }

    pub fn owned_by(self, owner: Option<Owner>) -> JobRecord {
        JobRecord { owner, ..self }
    }

    pub fn holding(self, result_bytes: u64) -> JobRecord {
        JobRecord {
            result_bytes,
            ..self
        }
    }

    pub fn expired(&self, retention: Duration, now: SystemTime) -> bool {
        self.finished_at.is_some_and(|t| age(t, now) >= retention)
    }

    /// Whether the record passes `listing`'s filters (its owner aside).
    pub fn listed_in(&self, listing: &Listing) -> bool {
        listing.kind.is_none_or(|kind| kind == self.kind)
            && listing
                .status
                .is_none_or(|status| status == self.state.status())
    }
}

/// Who submitted a job: an API key's tenant (`key:` and its name), or, without a key, the
/// SHA-256 of a token only its holder knows (the dashboard keeps a random one in the
/// browser's storage), so that the list of a holder's jobs is shown to that holder alone,
/// and the stored form cannot be replayed to list them. A token's hash is hexadecimal, so
/// it is never taken for a tenant.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Owner(String);

const TENANT: &str = "key:";

impl Owner {
    pub fn of_token(token: &str) -> Owner {
        use sha2::{Digest, Sha256};
        let digest = Sha256::digest(token.as_bytes());
        Owner(digest.iter().map(|b| format!("{b:02x}")).collect())
    }

    pub fn of_tenant(name: &str) -> Owner {
        Owner(format!("{TENANT}{name}"))
    }

    /// Whether the owner is an API key's tenant (whose jobs only its keys read).
    pub fn is_tenant(&self) -> bool {
        self.0.starts_with(TENANT)
    }

    pub fn stored(hash: String) -> Owner {
        Owner(hash)
    }

    /// The stored form: 64 hexadecimal digits, or `key:` and a tenant's name.
    pub fn as_str(&self) -> &str {
        &self.0
    }
}

/// Which of an owner's jobs to list: newest first, filtered, a page of them.
#[derive(Clone, Debug)]
pub struct Listing {
    pub owner: Owner,
    pub kind: Option<KindName>,
    pub status: Option<JobStatus>,
    /// Jobs skipped (the pages before).
    pub offset: usize,
    /// Jobs on the page at most.
    pub limit: usize,
}

#[derive(Clone, Debug, Default)]
pub struct Page {
    pub jobs: Vec<JobRecord>,
    /// The owner's jobs that pass the filters, on every page.
    pub total: usize,
}

impl Page {
    /// The page `listing` asks for, out of `matching` (newest first).
    pub fn of(matching: Vec<JobRecord>, listing: &Listing) -> Page {
        let total = matching.len();
        let jobs = matching
            .into_iter()
            .skip(listing.offset)
            .take(listing.limit)
            .collect();
        Page { jobs, total }
    }
}

/// Why a job store cannot take a job.
#[derive(Clone, Debug, PartialEq)]
pub enum Refusal {
    /// It holds as much as it may for jobs within their retention; room is made as they
    /// expire (the first in `retry_after`) or are deleted.
    Full { what: String, retry_after: Duration },
    /// Where it keeps jobs for good cannot be written now (a full disk, a database removed
    /// or damaged): the job is refused rather than accepted and lost.
    Unwritable { why: String },
    /// The job's result would not fit even in an empty store.
    TooLarge {
        needed: u64,
        /// Bytes the store can hold for one result.
        limit: u64,
    },
}

/// Where a result kept outside this process's memory is (Redis, the database).
#[async_trait]
pub trait ResultPlace: Send + Sync {
    /// The answer as JSON (`json`) or CSV (`csv`).
    async fn body(&self, field: &str) -> io::Result<Bytes>;
}

/// A finished job's result kept outside this process's memory: status reads never carry it;
/// a client asking for it gets the one form it asks for.
#[derive(Clone)]
pub struct StoredResult {
    pub key: String,
    pub kind: KindName,
    /// Whether the answer is whole (see [`Solved::complete`]).
    pub complete: bool,
    pub place: Arc<dyn ResultPlace>,
}

impl std::fmt::Debug for StoredResult {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("StoredResult")
            .field("key", &self.key)
            .field("complete", &self.complete)
            .finish()
    }
}

/// Where a job's result is: in memory, or stored.
#[derive(Clone, Debug)]
pub enum JobResult {
    Ready(Arc<Solved>),
    Stored(Arc<StoredResult>),
}

/// Why a job store cannot be read now, for the client (the log says more).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum Unreadable {
    #[error("the database of saved analyses cannot be read now (the log says why)")]
    Database,
    /// The fleet's Redis, and why.
    #[error("{0}")]
    Redis(String),
}

impl JobResult {
    pub fn complete(&self) -> bool {
        self.about().2
    }

    /// How stores name the result's completeness: `whole` or `partial`.
    pub fn form(&self) -> &'static str {
        if self.complete() {
            "whole"
        } else {
            "partial"
        }
    }

    /// The answer's JSON and CSV (a CSV is rendered off the async threads: tens of ms).
    pub async fn bodies(&self) -> io::Result<(Bytes, Bytes)> {
        match self {
            JobResult::Ready(solved) => {
                let rendering = solved.clone();
                let csv = crate::engine::heavy::run(move || rendering.body(Format::Csv))
                    .await
                    .map_err(io::Error::other)?
                    .map_err(|e| io::Error::other(e.to_string()))?;
                Ok((solved.json().clone(), csv))
            }
            JobResult::Stored(stored) => Ok((
                stored.place.body("json").await?,
                stored.place.body("csv").await?,
            )),
        }
    }

    pub fn kind(&self) -> KindName {
        self.about().1
    }

    pub fn key(&self) -> &str {
        self.about().0
    }

    /// The answer's cache key, its kind, and whether it is whole.
    fn about(&self) -> (&str, KindName, bool) {
        match self {
            JobResult::Ready(s) => (&s.key, s.kind, s.complete),
            JobResult::Stored(s) => (&s.key, s.kind, s.complete),
        }
    }

    /// Bytes held in memory (none for a result stored elsewhere).
    pub fn weight(&self) -> u64 {
        match self {
            JobResult::Ready(solved) => solved.weight(),
            JobResult::Stored(_) => 0,
        }
    }
}
