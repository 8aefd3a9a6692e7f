//! Asynchronous jobs' records: what a client polling a job sees, kept for a retention time
//! after the job finishes, then forgotten. [`JobStore`] is the seam a shared store plugs
//! into; [`MemoryJobStore`] is the default. A record holds no live handle: the cancel flag
//! and the progress count of a running job stay with the process that runs it.

use std::collections::{HashMap, VecDeque};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Duration, SystemTime};

use async_trait::async_trait;
use serde::Serialize;
use utoipa::ToSchema;
use uuid::Uuid;

use super::spill::{JobResult, SpillDir};
use crate::job::registry::KindName;
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
    /// Every status, in the order of a job's life (for parsing and for errors naming them).
    pub const ALL: [JobStatus; 6] = [
        JobStatus::Queued,
        JobStatus::Running,
        JobStatus::Succeeded,
        JobStatus::Failed,
        JobStatus::Cancelled,
        JobStatus::Interrupted,
    ];

    /// The status named `text` (as [`JobStatus::as_str`] writes it).
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
    Succeeded(JobResult),
    /// Failed; a job that keeps partial work (a sweep past its deadline) keeps what it
    /// finished.
    Failed {
        error: JobError,
        partial: Option<JobResult>,
    },
    /// Cancelled; with what it finished, for a job that keeps partial work.
    Cancelled {
        partial: Option<JobResult>,
    },
    Interrupted,
}

impl JobState {
    /// Logs that the job ended in this state: an internal failure as an error with its
    /// cause, which its clients are not shown.
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

    /// The state of a job read back from a store as its `status`, its `result` if one was
    /// stored, and its `error` (read only for a failed job).
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

    /// A failure that kept nothing.
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

    /// The same state with its result replaced by `result`.
    fn with_result(self, result: JobResult) -> JobState {
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
    /// The work the job takes.
    pub work: Work,
    pub state: JobState,
    /// Work done when the record was last written (a running job's own count is live in
    /// the process that runs it).
    pub done: usize,
    /// The hash of the job's canonical input (its cache key): equal inputs, equal answers.
    pub input_hash: String,
    /// Who submitted it, if they said ([`Owner`]): the jobs listed to them.
    pub owner: Option<Owner>,
    /// When it was accepted (wall clock: it is shown, and compared across processes).
    pub submitted_at: SystemTime,
    /// When it finished, once it has.
    pub finished_at: Option<SystemTime>,
    /// Bytes its answer may take, at most: the room made for it when it was accepted, held
    /// for its retention (what a tenant's `--quota-result-bytes` counts).
    pub result_bytes: u64,
    /// Whether its end could not be saved where the store keeps jobs for good (a database
    /// that cannot be written): it is then kept in memory only, and says so.
    pub unsaved: bool,
}

impl JobRecord {
    /// A job just accepted, whose id is `id`, on the input whose hash is `input_hash`.
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

    /// The same record, owned by `owner`.
    pub fn owned_by(self, owner: Option<Owner>) -> JobRecord {
        JobRecord { owner, ..self }
    }

    /// The same record, its answer taking at most `result_bytes`.
    pub fn holding(self, result_bytes: u64) -> JobRecord {
        JobRecord {
            result_bytes,
            ..self
        }
    }

    fn expired(&self, retention: Duration, now: SystemTime) -> bool {
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

/// `time` in milliseconds since the Unix epoch: how times are stored and shared.
pub fn unix_millis(time: SystemTime) -> u64 {
    let since = time
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap_or_default();
    u64::try_from(since.as_millis()).unwrap_or(u64::MAX)
}

/// The time `unix_ms` milliseconds after the Unix epoch.
pub fn from_unix_millis(unix_ms: u64) -> SystemTime {
    std::time::UNIX_EPOCH + Duration::from_millis(unix_ms)
}

/// How long before `now` the time `then` was (none if it is not before).
pub fn age(then: SystemTime, now: SystemTime) -> Duration {
    now.duration_since(then).unwrap_or_default()
}

/// Who submitted a job: an API key's tenant (`key:` and its name), or, without a key, the
/// SHA-256 of a token only its holder knows (the dashboard keeps a random one in the
/// browser's storage), so that the list of a holder's jobs is shown to that holder alone,
/// and the stored form cannot be replayed to list them. A token's hash is hexadecimal, so
/// it is never taken for a tenant.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Owner(String);

/// The prefix of a tenant's stored form.
const TENANT: &str = "key:";

impl Owner {
    /// The owner holding `token` (checked by the caller).
    pub fn of_token(token: &str) -> Owner {
        use sha2::{Digest, Sha256};
        let digest = Sha256::digest(token.as_bytes());
        Owner(digest.iter().map(|b| format!("{b:02x}")).collect())
    }

    /// The tenant of the API keys named `name`.
    pub fn of_tenant(name: &str) -> Owner {
        Owner(format!("{TENANT}{name}"))
    }

    /// Whether the owner is an API key's tenant (whose jobs only its keys read).
    pub fn is_tenant(&self) -> bool {
        self.0.starts_with(TENANT)
    }

    /// An owner as stored.
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

/// A page of an owner's jobs.
#[derive(Clone, Debug, Default)]
pub struct Page {
    pub jobs: Vec<JobRecord>,
    /// The owner's jobs that pass the filters, on every page.
    pub total: usize,
}

impl Page {
    /// The page `listing` asks for, out of `matching` (every job passing its filters,
    /// newest first).
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
    Full {
        /// What is full, in words, with the numbers.
        what: String,
        retry_after: Duration,
    },
    /// Where it keeps jobs for good cannot be written now (a full disk, a database removed
    /// or damaged): the job is refused rather than accepted and lost.
    Unwritable { why: String },
    /// The job's result would not fit even in an empty store.
    TooLarge {
        /// Bytes the result may take.
        needed: u64,
        /// Bytes the store can hold for one result.
        limit: u64,
    },
}

/// Where the records of asynchronous jobs are kept.
#[async_trait]
pub trait JobStore: Send + Sync {
    /// Records a job just accepted, whose result will take at most its `result_bytes`: room
    /// is made for it now, so that the result is kept for its retention once the work is
    /// done, or the job is refused before any work.
    async fn insert(&self, record: JobRecord) -> Result<(), Refusal>;
    /// The job `id`, unless unknown or expired.
    async fn get(&self, id: Uuid) -> Option<JobRecord>;
    /// Moves the job `id` to `state` with `done` units of work done; a finished state
    /// starts its retention.
    async fn update(&self, id: Uuid, state: JobState, done: usize);
    /// Forgets the job `id`.
    async fn remove(&self, id: Uuid);
    /// Forgets the jobs past their retention; returns how many.
    async fn purge_expired(&self) -> usize;
    /// The jobs of `listing`'s owner, newest first, filtered and paged; an error says why
    /// the store cannot be read.
    async fn list(&self, listing: &Listing) -> Result<Page, String>;
    /// The newest job that succeeded on the input whose hash is `input_hash`; an error says
    /// why the store cannot be read.
    async fn with_input(&self, input_hash: &str) -> Result<Option<JobRecord>, String>;

    /// Whether every process of the fleet shares the store (so any of them answers for any
    /// job, and a job unknown to it is unknown to all).
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

/// Where a job's result will be kept.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Place {
    Memory,
    Disk,
}

/// Room made for a result not in yet.
#[derive(Clone, Copy, Debug)]
struct Reservation {
    bytes: u64,
    place: Place,
}

/// The records of one process's jobs, at most `max_jobs` of them, with the results of those
/// within their retention: in memory up to `result_bytes`, and beyond it on disk (up to the
/// spill directory's limit). Room for a result is made when its job is accepted; a job for
/// whose result there is no room is refused then, never after its work.
#[derive(Debug)]
pub struct MemoryJobStore {
    records: Mutex<Records>,
    retention: Duration,
    max_jobs: usize,
    result_bytes: u64,
    spill: Option<Arc<SpillDir>>,
}

#[derive(Debug, Default)]
struct Records {
    jobs: HashMap<Uuid, JobRecord>,
    /// Room made for the results of jobs not finished yet.
    reserved: HashMap<Uuid, Reservation>,
    /// Finished jobs, oldest first (ids may have been forgotten since).
    finished: VecDeque<Uuid>,
    /// Bytes held and made room for, in memory and on disk.
    memory: u64,
    disk: u64,
}

impl Records {
    fn bytes(&mut self, place: Place) -> &mut u64 {
        match place {
            Place::Memory => &mut self.memory,
            Place::Disk => &mut self.disk,
        }
    }

    fn forget(&mut self, id: &Uuid) {
        if let Some(record) = self.jobs.remove(id) {
            if let Some(result) = record.state.result() {
                let held = self.bytes(place_of(result));
                *held = held.saturating_sub(result.weight());
            }
        }
        if let Some(r) = self.reserved.remove(id) {
            let held = self.bytes(r.place);
            *held = held.saturating_sub(r.bytes);
        }
    }

    /// Forgets the jobs past their retention.
    fn purge(&mut self, retention: Duration, now: SystemTime) -> usize {
        let expired: Vec<Uuid> = self
            .jobs
            .values()
            .filter(|r| r.expired(retention, now))
            .map(|r| r.id)
            .collect();
        for id in &expired {
            self.forget(id);
        }
        let Records { jobs, finished, .. } = self;
        finished.retain(|id| jobs.contains_key(id));
        expired.len()
    }

    /// How long until the oldest finished job expires (and makes room), at most
    /// `retention`.
    fn next_expiry(&self, retention: Duration, now: SystemTime) -> Duration {
        self.finished
            .iter()
            .filter_map(|id| self.jobs.get(id)?.finished_at)
            .map(|t| retention.saturating_sub(age(t, now)))
            .min()
            .unwrap_or(retention)
    }
}

impl MemoryJobStore {
    /// A store that forgets a job `retention` after it finished, keeps at most `max_jobs`
    /// records and `result_bytes` of their results in memory, and spills results beyond
    /// that to `spill`, if given.
    pub fn new(
        retention: Duration,
        max_jobs: usize,
        result_bytes: u64,
        spill: Option<SpillDir>,
    ) -> Self {
        MemoryJobStore {
            records: Mutex::default(),
            retention,
            max_jobs: max_jobs.max(1),
            result_bytes,
            spill: spill.map(Arc::new),
        }
    }

    fn records(&self) -> MutexGuard<'_, Records> {
        self.records.lock().unwrap_or_else(|p| p.into_inner())
    }

    fn spill_limit(&self) -> u64 {
        self.spill.as_ref().map_or(0, |s| s.limit)
    }

    /// Room for a result of `bytes` in `records`: in memory if it fits there, else on disk.
    fn room(&self, records: &Records, bytes: u64) -> Result<Place, Refusal> {
        if records.memory.saturating_add(bytes) <= self.result_bytes {
            return Ok(Place::Memory);
        }
        if records.disk.saturating_add(bytes) <= self.spill_limit() {
            return Ok(Place::Disk);
        }
        let limit = self.result_bytes.max(self.spill_limit());
        if bytes > limit {
            return Err(Refusal::TooLarge {
                needed: bytes,
                limit,
            });
        }
        Err(Refusal::Full {
            what: format!(
                "the results of finished jobs within their retention ({}) take {} of {} in                  memory and {} of {} on disk, and this job's result may take up to {}",
                humantime::format_duration(self.retention),
                megabytes(records.memory),
                megabytes(self.result_bytes),
                megabytes(records.disk),
                megabytes(self.spill_limit()),
                megabytes(bytes),
            ),
            retry_after: records.next_expiry(self.retention, SystemTime::now()),
        })
    }

    /// Keeps `state`'s result where room was made for it (`place`): spilled to disk, written
    /// off the async threads. A result that cannot be written stays in memory, over the
    /// budget rather than lost.
    async fn keep(&self, id: Uuid, state: JobState, place: Place) -> JobState {
        let (Some(spill), Place::Disk, Some(JobResult::Ready(solved))) =
            (&self.spill, place, state.result().cloned())
        else {
            return state;
        };
        let spill = spill.clone();
        let written = super::heavy::run(move || spill.write(id, &solved))
            .await
            .unwrap_or_else(|e| Err(std::io::Error::other(e)));
        match written {
            Ok(spilled) => state.with_result(JobResult::Spilled(Arc::new(spilled))),
            Err(e) => {
                tracing::error!(error = %e, %id, "a result could not be spilled to disk");
                state
            }
        }
    }
}

/// Where a result is held (a result in Redis weighs nothing here: it is counted in memory).
fn place_of(result: &JobResult) -> Place {
    match result {
        JobResult::Ready(_) | JobResult::Stored(_) => Place::Memory,
        JobResult::Spilled(_) => Place::Disk,
    }
}

/// `n` bytes in MB, for people.
fn megabytes(n: u64) -> String {
    format!("{:.1} MB", n as f64 / 1e6)
}

/// The in-memory half of [`super::local::LocalJobStore`]: the [`JobStore`] calls that it
/// answers alone.
impl MemoryJobStore {
    pub async fn insert(&self, record: JobRecord) -> Result<(), Refusal> {
        let result_bytes = record.result_bytes;
        let now = SystemTime::now();
        let mut records = self.records();
        records.purge(self.retention, now);
        if records.jobs.len() >= self.max_jobs {
            return Err(Refusal::Full {
                what: format!(
                    "it keeps {} jobs, the most it may, for their retention ({})",
                    records.jobs.len(),
                    humantime::format_duration(self.retention)
                ),
                retry_after: records.next_expiry(self.retention, now),
            });
        }
        let place = self.room(&records, result_bytes)?;
        *records.bytes(place) += result_bytes;
        records.reserved.insert(
            record.id,
            Reservation {
                bytes: result_bytes,
                place,
            },
        );
        records.jobs.insert(record.id, record);
        Ok(())
    }

    pub async fn get(&self, id: Uuid) -> Option<JobRecord> {
        let mut records = self.records();
        let record = records.jobs.get(&id)?;
        if record.expired(self.retention, SystemTime::now()) {
            records.forget(&id);
            return None;
        }
        Some(record.clone())
    }

    /// Moves job `id` to `state`; returns the state as kept (a result spilled to disk is
    /// the file's) and, once finished, when it finished (now, if memory forgot the job).
    pub async fn update(
        &self,
        id: Uuid,
        state: JobState,
        done: usize,
    ) -> (JobState, Option<SystemTime>) {
        let finishing = state.status().is_finished();
        // The room made for the result, taken once: by the update that finishes the job.
        let reservation = if finishing {
            self.records().reserved.remove(&id)
        } else {
            None
        };
        let state = match reservation {
            Some(r) => self.keep(id, state, r.place).await,
            None => state,
        };
        let mut records = self.records();
        if let Some(r) = reservation {
            let held = records.bytes(r.place);
            *held = held.saturating_sub(r.bytes);
            if let Some(result) = state.result() {
                *records.bytes(place_of(result)) += result.weight();
                if result.weight() > r.bytes {
                    tracing::warn!(
                        %id, estimate = r.bytes, weight = result.weight(),
                        "a result weighs more than the room made for it"
                    );
                }
            }
        }
        let Some(record) = records.jobs.get_mut(&id) else {
            return (state, finishing.then(SystemTime::now));
        };
        let finished = finishing && record.finished_at.is_none();
        if finished {
            record.finished_at = Some(SystemTime::now());
        }
        record.state = state.clone();
        record.done = done;
        let finished_at = record.finished_at;
        if finished {
            records.finished.push_back(id);
        }
        (state, finished_at)
    }

    pub async fn remove(&self, id: Uuid) {
        self.records().forget(&id);
    }

    /// Marks job `id` as kept in memory only (its end could not be saved for good), or no
    /// longer.
    pub fn mark_unsaved(&self, id: Uuid, unsaved: bool) {
        if let Some(record) = self.records().jobs.get_mut(&id) {
            record.unsaved = unsaved;
        }
    }

    pub async fn purge_expired(&self) -> usize {
        self.records().purge(self.retention, SystemTime::now())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::cache::Solved;
    use crate::render::{Answer, Column, Output, Table, UnitTable};
    use crate::{described, unit_table};
    use serde::Serialize;

    described! {
        #[derive(Debug, PartialEq, Serialize)]
        struct Blob {
            text: String => [],
        }
    }

    impl Output for Blob {
        const UNITS: &'static UnitTable = unit_table!(Blob);
        fn table(&self) -> Table {
            Table::new(
                &[Column::text("text", |b: &Blob, text| {
                    text.push_str(&b.text)
                })],
                [self],
            )
        }
    }

    /// A result whose JSON and CSV take about `bytes` together, as a job keeps it.
    fn kept(key: &str, bytes: usize) -> JobResult {
        let blob = Blob {
            text: "x".repeat(bytes / 2),
        };
        let solved = Solved::new(
            key.to_string(),
            KindName::of::<crate::job::RollingJob>(),
            Answer::new(blob),
        )
        .unwrap();
        JobResult::Ready(Arc::new(solved.kept().unwrap()))
    }

    fn record() -> JobRecord {
        JobRecord::queued(
            Uuid::new_v4(),
            KindName::of::<crate::job::RollingJob>(),
            Work::Known(1),
            "k",
        )
    }

    /// Finishes job `id` with a result of `bytes`.
    async fn succeed(store: &MemoryJobStore, id: Uuid, bytes: usize) {
        store
            .update(id, JobState::Succeeded(kept("k", bytes)), 1)
            .await;
    }

    #[tokio::test]
    async fn a_result_is_kept_whole_for_its_retention_and_a_job_without_room_is_refused_before_its_work(
    ) {
        let store = MemoryJobStore::new(Duration::from_secs(60), 100, 10_000, None);
        let mut ids = Vec::new();
        for _ in 0..3 {
            let r = record();
            ids.push(r.id);
            store.insert(r.holding(3_000)).await.unwrap();
        }
        // Room for three results of 3 kB is made: a fourth does not fit, now.
        match store.insert(record().holding(3_000)).await {
            Err(Refusal::Full { what, retry_after }) => {
                assert!(what.contains("0.0 MB of 0.0 MB on disk"), "{what}");
                assert!(retry_after <= Duration::from_secs(60));
            }
            other => panic!("{other:?}"),
        }
        // Too large for an empty store: said so, with both numbers.
        assert_eq!(
            store.insert(record().holding(20_000)).await,
            Err(Refusal::TooLarge {
                needed: 20_000,
                limit: 10_000
            })
        );
        for id in &ids {
            succeed(&store, *id, 2_500).await;
        }
        // Every result is still there, whole.
        for id in &ids {
            let state = store.get(*id).await.unwrap().state;
            assert!(matches!(state, JobState::Succeeded(JobResult::Ready(_))));
        }
        // A result that weighs less than its room gives the rest back: one more 1 kB job fits.
        store.insert(record().holding(1_000)).await.unwrap();
        // Forgetting a job makes room.
        store.remove(ids[0]).await;
        store.insert(record().holding(3_000)).await.unwrap();
    }

    #[tokio::test]
    async fn results_beyond_the_memory_budget_are_spilled_to_disk_and_deleted_with_their_record() {
        let parent = std::env::temp_dir();
        let spill = SpillDir::create(&parent, 1 << 20).unwrap();
        let store = MemoryJobStore::new(Duration::from_secs(60), 100, 4_000, Some(spill));
        let (small, large) = (record(), record());
        let (small_id, large_id) = (small.id, large.id);
        store.insert(small.holding(3_000)).await.unwrap();
        store.insert(large.holding(100_000)).await.unwrap();
        succeed(&store, small_id, 2_000).await;
        succeed(&store, large_id, 90_000).await;
        assert!(matches!(
            store.get(small_id).await.unwrap().state,
            JobState::Succeeded(JobResult::Ready(_))
        ));
        let JobState::Succeeded(JobResult::Spilled(spilled)) =
            store.get(large_id).await.unwrap().state
        else {
            panic!("the large result is not on disk");
        };
        let json = spilled.json().await.unwrap();
        assert!(json.len() > 40_000 && json.starts_with(b"{\"text\":\"xxx"));
        let file = spilled.file(crate::render::Format::Csv).to_path_buf();
        assert!(file.exists());
        drop(spilled);
        store.remove(large_id).await;
        assert!(!file.exists(), "the spilled result outlived its record");
    }

    #[tokio::test]
    async fn at_most_max_jobs_records_are_kept_and_more_are_refused_until_one_is_forgotten() {
        let store = MemoryJobStore::new(Duration::from_secs(60), 3, 1 << 20, None);
        let mut ids = Vec::new();
        for _ in 0..3 {
            let r = record();
            ids.push(r.id);
            store.insert(r.holding(100)).await.unwrap();
            let cancelled = JobState::Cancelled { partial: None };
            store.update(ids[ids.len() - 1], cancelled, 0).await;
        }
        assert!(matches!(
            store.insert(record().holding(100)).await,
            Err(Refusal::Full { .. })
        ));
        for id in &ids {
            assert!(store.get(*id).await.is_some());
        }
        store.remove(ids[0]).await;
        store.insert(record().holding(100)).await.unwrap();
    }

    #[tokio::test]
    async fn expired_jobs_make_room() {
        let store = MemoryJobStore::new(Duration::from_millis(20), 1, 1 << 20, None);
        let first = record();
        let id = first.id;
        store.insert(first.holding(100)).await.unwrap();
        succeed(&store, id, 50).await;
        assert!(store.insert(record().holding(100)).await.is_err());
        tokio::time::sleep(Duration::from_millis(30)).await;
        store.insert(record().holding(100)).await.unwrap();
        assert!(store.get(id).await.is_none());
    }
}
