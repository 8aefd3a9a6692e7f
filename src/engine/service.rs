//! The compute path of the service: validated job → cache key → cache lookup → one solve
//! per key in flight → a permit (or a refusal) → a blocking thread with a deadline and a
//! cancel flag. Synchronous solves and asynchronous jobs both go through it.

use std::collections::{HashMap, HashSet, VecDeque};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use futures_util::FutureExt;
use metrics::{Counter, Gauge};
use tokio::sync::{watch, OwnedSemaphorePermit};
use tokio_util::sync::CancellationToken;
use tokio_util::task::TaskTracker;
use tracing::Instrument;
use uuid::Uuid;

use super::background::Background;
use super::backlog::{Backlog, Backlogged, Ticket};
use super::bounded::Bounded;
use super::budget::{self, Budget};
use super::cache::{Claim, MemoryCache, ResultCache, Solved};
use super::coalesce::Coalescer;
use super::doorkeeper::Doorkeeper;
use super::fleet::Shared;
use super::memo::PointMemo;
use super::metrics::{self as names, Metrics};
use super::pool::Pool;
use super::spill::{JobResult, SpillDir};
use super::store::{JobRecord, JobState, JobStatus, JobStore, MemoryJobStore, Refusal};
use crate::job::{Control, Job, JobError, Meta, Unfinished, Work};

/// How long a cancel waits for the job to stop (it checks between units of work, which take
/// microseconds to milliseconds).
const CANCEL_WAIT: Duration = Duration::from_secs(5);

/// The limits of an engine.
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
    /// Memory for everything kept between requests (bytes, estimated): cached answers, the
    /// results of finished jobs, the input memo, solved points ([`Budget`]).
    pub memory_budget: u64,
    /// Records of asynchronous jobs kept at most (the oldest finished are forgotten first).
    pub max_jobs: usize,
    /// How long an answer stays cached.
    pub cache_ttl: Duration,
    /// How long a finished asynchronous job is kept.
    pub job_retention: Duration,
    /// Where results too large for the memory budget are kept (a directory of this
    /// process's is made there), and how many bytes of them at most; `None` or 0 bytes: in
    /// memory only.
    pub spill: Option<(PathBuf, u64)>,
}

/// Where an engine keeps answers and job records.
#[derive(Clone)]
pub struct Storage {
    pub cache: Arc<dyn ResultCache>,
    pub jobs: Arc<dyn JobStore>,
    /// The fleet the engine works in, if any ([`super::fleet`]): its jobs then run on the
    /// fleet's work stream, not in this process's tasks.
    pub fleet: Option<Arc<Shared>>,
}

impl Storage {
    /// In this process's memory (and its spill directory), within `config`'s bounds: the
    /// default. Fails if the spill directory cannot be made.
    pub fn in_process(config: &EngineConfig) -> std::io::Result<Storage> {
        let budget = Budget::split(config.memory_budget);
        let spill = match &config.spill {
            Some((parent, bytes)) if *bytes > 0 => Some(SpillDir::create(parent, *bytes)?),
            _ => None,
        };
        Ok(Storage {
            cache: Arc::new(MemoryCache::for_engine(config)),
            jobs: Arc::new(MemoryJobStore::new(
                config.job_retention,
                config.max_jobs,
                budget.job_results,
                spill,
            )),
            fleet: None,
        })
    }
}

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
        }
    }
}

impl From<JobError> for EngineError {
    fn from(e: JobError) -> Self {
        EngineError::Job(e)
    }
}

/// Whether an answer came from the cache or was solved for this call.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CacheStatus {
    Hit,
    Miss,
}

impl CacheStatus {
    pub fn as_str(self) -> &'static str {
        match self {
            CacheStatus::Hit => "hit",
            CacheStatus::Miss => "miss",
        }
    }
}

/// A solve that did not answer: why, and the partial answer of a job that keeps what it
/// finished ([`crate::job::Unfinished`]).
struct Stopped {
    error: JobError,
    partial: Option<Arc<Solved>>,
}

impl From<JobError> for Stopped {
    fn from(error: JobError) -> Self {
        Stopped {
            error,
            partial: None,
        }
    }
}

/// The handles of an asynchronous job this process runs: what its record cannot hold.
struct LiveJob {
    control: Arc<Control>,
    /// Wakes a job still waiting for a permit when it is cancelled (the solver itself
    /// watches `control`).
    cancel: CancellationToken,
    /// Whether the job is being stopped by the shutdown rather than by its client.
    interrupted: AtomicBool,
    /// The job's status, for those who wait for a change.
    status: watch::Sender<JobStatus>,
}

impl LiveJob {
    /// Asks the job to stop: at once if it is queued, at the solver's next check if it runs.
    fn cancel(&self) {
        self.cancel.cancel();
        self.control.cancel();
    }

    /// The state of a job that stopped on a cancel: interrupted if the shutdown asked.
    fn stopped(&self, partial: Option<JobResult>) -> JobState {
        if self.interrupted.load(Ordering::SeqCst) {
            JobState::Interrupted
        } else {
            JobState::Cancelled { partial }
        }
    }
}

/// Finished jobs no client has read finished yet, oldest first.
#[derive(Debug, Default)]
struct Uncollected {
    ids: HashSet<Uuid>,
    order: VecDeque<Uuid>,
}

impl Uncollected {
    /// Adds `id`, giving up the oldest beyond `max` (their clients are long gone).
    fn insert(&mut self, id: Uuid, max: usize) {
        self.ids.insert(id);
        self.order.push_back(id);
        while self.ids.len() > max {
            match self.order.pop_front() {
                Some(old) => {
                    self.ids.remove(&old);
                }
                None => break,
            }
        }
        // Ids read since are still in `order`: drop them when they outnumber the rest.
        if self.order.len() > 2 * self.ids.len() + 16 {
            let ids = &self.ids;
            self.order.retain(|id| ids.contains(id));
        }
    }
}

/// Ids of asynchronous jobs: a tag of the process that accepted the job, then random bits.
/// A process that does not know an id can tell whether it is its own (expired, or never
/// given) or another run's (whose unfinished jobs a shutdown interrupted).
#[derive(Clone, Copy, Debug)]
struct JobIds {
    instance: [u8; 4],
}

impl JobIds {
    fn new() -> Self {
        let tag = Uuid::new_v4();
        let mut instance = [0; 4];
        instance.copy_from_slice(&tag.as_bytes()[..4]);
        JobIds { instance }
    }

    fn next(&self) -> Uuid {
        let mut bytes = *Uuid::new_v4().as_bytes();
        bytes[..4].copy_from_slice(&self.instance);
        // Keep the version (4) and variant bits of the random UUID.
        Uuid::from_bytes(bytes)
    }

    fn issued(&self, id: Uuid) -> bool {
        id.as_bytes()[..4] == self.instance
    }
}

/// The compute service: pool, cache and asynchronous jobs.
pub struct Engine {
    config: EngineConfig,
    pub(super) pool: Pool,
    pub(super) cache: Arc<dyn ResultCache>,
    coalescer: Coalescer,
    /// The text of valid inputs (their kind and compact JSON with sorted keys) → their
    /// cache key, so that a repeated request is answered without being validated again.
    input_keys: Bounded<Arc<str>>,
    /// Which inputs were seen once: the memo takes an input on its second sighting.
    doorkeeper: Doorkeeper,
    /// Solved points of sweeps, for a retry after a deadline.
    pub(super) points: Arc<PointMemo>,
    /// Work jobs leave for later (tables to build); `None` if its thread could not start.
    background: Option<Arc<Background>>,
    jobs: Arc<dyn JobStore>,
    /// The fleet, when the engine works in one.
    pub(super) fleet: Option<Arc<Shared>>,
    /// The jobs this process runs, by id.
    live: Mutex<HashMap<Uuid, Arc<LiveJob>>>,
    /// Jobs finished that no client has read finished yet (at most `max_jobs`, the oldest
    /// given up first).
    uncollected: Mutex<Uncollected>,
    /// The jobs unfinished or uncollected when the drain began, whose clients have not yet
    /// read them finished: the drain waits for them (see [`Engine::jobs_collected`]).
    owed: Mutex<HashSet<Uuid>>,
    ids: JobIds,
    /// Solver threads asynchronous jobs may hold at once: all but one, so that synchronous
    /// requests always find one that no job holds.
    pub(super) job_slots: Arc<tokio::sync::Semaphore>,
    /// The tasks of asynchronous jobs (and the fleet's workers), waited for on shutdown.
    pub(super) tracker: TaskTracker,
    draining: AtomicBool,
    /// Asynchronous jobs waiting for a permit.
    queued: AtomicUsize,
    /// The estimated work of the asynchronous jobs accepted and not ended.
    backlog: Arc<Backlog>,
    pub(super) metrics: Metrics,
    cache_hits: Counter,
    cache_misses: Counter,
    jobs_queued: Gauge,
    pub(super) jobs_running: Gauge,
}

impl Engine {
    /// An engine that keeps everything in this process.
    pub fn new(config: EngineConfig, metrics: Metrics) -> std::io::Result<Arc<Engine>> {
        let storage = Storage::in_process(&config)?;
        Ok(Engine::with_storage(config, metrics, storage))
    }

    /// An engine that keeps answers and job records in `storage`.
    pub fn with_storage(config: EngineConfig, metrics: Metrics, storage: Storage) -> Arc<Engine> {
        if let Some(shared) = &storage.fleet {
            for link in [&shared.fleet.cache, &shared.fleet.jobs] {
                link.report_to(metrics.labelled_gauge(names::REDIS_UP, &[("role", link.role)]));
            }
        }
        let job_threads = config.pool_size.saturating_sub(1).max(1);
        Arc::new(Engine {
            pool: Pool::new(config.pool_size),
            cache: storage.cache,
            coalescer: Coalescer::default(),
            // An input and its key weigh about 100 bytes, and the entry's overhead more.
            input_keys: Bounded::new(
                Budget::split(config.memory_budget).inputs,
                config.cache_ttl,
                budget::ENTRY_OVERHEAD,
                |key: &Arc<str>| key.len() as u64,
            ),
            doorkeeper: Doorkeeper::new(
                Budget::split(config.memory_budget).inputs / budget::ENTRY_OVERHEAD,
            ),
            points: Arc::new(PointMemo::new(
                Budget::split(config.memory_budget).points,
                config.cache_ttl,
            )),
            background: Background::start()
                .inspect_err(|e| {
                    tracing::warn!("no background thread ({e}): no tables built later")
                })
                .ok(),
            jobs: storage.jobs,
            fleet: storage.fleet,
            live: Mutex::default(),
            uncollected: Mutex::default(),
            owed: Mutex::default(),
            ids: JobIds::new(),
            job_slots: Arc::new(tokio::sync::Semaphore::new(job_threads)),
            backlog: Backlog::new(job_threads, config.job_deadline),
            tracker: TaskTracker::new(),
            draining: AtomicBool::new(false),
            queued: AtomicUsize::new(0),
            cache_hits: metrics.counter(names::CACHE_HITS, &[]),
            cache_misses: metrics.counter(names::CACHE_MISSES, &[]),
            jobs_queued: metrics.gauge(names::JOBS_QUEUED),
            jobs_running: metrics.gauge(names::JOBS_RUNNING),
            metrics,
            config,
        })
    }

    pub fn metrics(&self) -> &Metrics {
        &self.metrics
    }

    fn live(&self) -> MutexGuard<'_, HashMap<Uuid, Arc<LiveJob>>> {
        self.live.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// The cached answer to an input seen before (`text`: its kind and compact JSON), found
    /// without validating the input again; `None` if it was not seen or its answer expired.
    /// Refused while draining, like every other call for an answer.
    pub async fn cached_input(&self, text: &str) -> Result<Option<Arc<Solved>>, EngineError> {
        self.admit()?;
        let Some(key) = self.input_keys.get(text) else {
            return Ok(None);
        };
        let solved = self.cache.get(&key).await;
        if solved.is_some() {
            self.cache_hits.increment(1);
        }
        Ok(solved)
    }

    /// Remembers that the input `text` (as for [`Engine::cached_input`]) is a valid job
    /// with cache key `key`, if it was seen before ([`Doorkeeper`]).
    pub fn remember_input(&self, text: String, key: String) {
        if self.doorkeeper.seen_before(&text) {
            self.input_keys.insert(text, key.into());
        }
    }

    /// Solves `job`, whose [`Meta`] is `meta` (computed once by the caller: it holds the
    /// cache key), now, or takes its answer from the cache. Identical concurrent calls share
    /// one solve. With no solver thread free the call is refused at once.
    pub async fn solve(
        self: &Arc<Self>,
        job: Job,
        meta: Meta,
    ) -> Result<(Arc<Solved>, CacheStatus), EngineError> {
        let deadline = Instant::now() + self.config.solve_deadline;
        self.solve_by(job, meta, deadline).await
    }

    /// [`Engine::solve`] with a deadline of the caller's (shared by several solves, as a
    /// checks suite's), never later than the solve deadline from now.
    pub async fn solve_by(
        self: &Arc<Self>,
        job: Job,
        meta: Meta,
        deadline: Instant,
    ) -> Result<(Arc<Solved>, CacheStatus), EngineError> {
        let deadline = deadline.min(Instant::now() + self.config.solve_deadline);
        self.admit()?;
        let key = meta.input_hash.clone();
        if let Some(solved) = self.cache.get(&key).await {
            self.cache_hits.increment(1);
            return Ok((solved, CacheStatus::Hit));
        }
        let engine = self.clone();
        let key_claimed = key.clone();
        let solve = move || {
            async move {
                if let Claim::Solved(solved) =
                    engine.cache.claim(&meta.input_hash, deadline).await?
                {
                    return Ok(solved);
                }
                let solved = engine.solve_claimed(job, meta, deadline).await;
                engine.cache.release(&key_claimed).await;
                solved
            }
            .boxed()
        };
        let (solved, started) = self.coalescer.run(&key, solve).await;
        let solved = solved.map_err(|e| self.refused(e))?;
        if started {
            Ok((solved, CacheStatus::Miss))
        } else {
            self.cache_hits.increment(1);
            Ok((solved, CacheStatus::Hit))
        }
    }

    /// Solves `job` now, this process holding the fleet's claim on it, and keeps the answer.
    async fn solve_claimed(
        &self,
        job: Job,
        meta: Meta,
        deadline: Instant,
    ) -> Result<Arc<Solved>, EngineError> {
        let permit = self.pool.try_acquire().ok_or(EngineError::Overloaded)?;
        let control = Arc::new(self.control(deadline));
        let solved = self
            .execute(permit, job, meta, control, false)
            .await
            .map_err(|stopped| stopped.error)?;
        self.cache.insert(solved.clone()).await;
        Ok(solved)
    }

    /// Queues `job` to run in the background; returns its record. Refused when the queue
    /// is full, the service is draining, or there is no room to keep the job's result.
    pub async fn submit(self: &Arc<Self>, job: Job) -> Result<JobRecord, EngineError> {
        self.admit()?;
        self.store_reachable()?;
        let meta = job.meta();
        // A job whose answer is cached is answered at once: it takes no place in the queue.
        if let Some(solved) = self.cache.get(&meta.input_hash).await {
            self.cache_hits.increment(1);
            let mut record = JobRecord::queued(self.ids.next(), job.kind(), job.work());
            let done = match job.work() {
                Work::Known(total) => total,
                Work::Unknown => 0,
            };
            self.jobs
                .insert(record.clone(), solved.weight())
                .await
                .map_err(|e| self.refused(e.into()))?;
            let state = JobState::Succeeded(JobResult::Ready(solved));
            self.jobs.update(record.id, state.clone(), done).await;
            self.uncollected().insert(record.id, self.config.max_jobs);
            record.state = state;
            record.done = done;
            return Ok(record);
        }
        if let Some(shared) = &self.fleet {
            return self.enqueue(shared, job, meta).await;
        }
        let max = self.config.max_queued_jobs;
        if self
            .queued
            .fetch_update(Ordering::SeqCst, Ordering::SeqCst, |n| {
                (n < max).then_some(n + 1)
            })
            .is_err()
        {
            return Err(self.refused(EngineError::Overloaded));
        }
        let units = match job.work() {
            Work::Known(units) => units,
            Work::Unknown => 1,
        };
        let ticket = match self.backlog.admit(job.cost_class(), units) {
            Ok(ticket) => ticket,
            Err(backlogged) => {
                self.queued.fetch_sub(1, Ordering::SeqCst);
                return Err(self.refused(EngineError::Backlogged(backlogged)));
            }
        };
        let record = JobRecord::queued(self.ids.next(), job.kind(), job.work());
        let id = record.id;
        if let Err(refusal) = self.jobs.insert(record.clone(), job.result_bytes()).await {
            self.queued.fetch_sub(1, Ordering::SeqCst);
            return Err(self.refused(refusal.into()));
        }
        self.jobs_queued.increment(1.0);
        let deadline = Instant::now() + self.config.job_deadline;
        let live = Arc::new(LiveJob {
            control: Arc::new(self.control(deadline)),
            cancel: CancellationToken::new(),
            interrupted: AtomicBool::new(false),
            status: watch::Sender::new(JobStatus::Queued),
        });
        self.live().insert(id, live.clone());
        let span = tracing::info_span!("job", id = %id, kind = job.kind());
        let engine = self.clone();
        self.tracker.spawn(
            async move {
                let work = job.work();
                let state = engine.run_job(&live, id, job, meta, &ticket).await;
                drop(ticket);
                let status = state.status();
                let done = match (status, work) {
                    (JobStatus::Succeeded, Work::Known(total)) => total,
                    _ => live.control.done(),
                };
                state.log_end(id);
                engine.jobs.update(id, state, done).await;
                engine.uncollected().insert(id, engine.config.max_jobs);
                engine.live().remove(&id);
                live.status.send_replace(status);
            }
            .instrument(span),
        );
        Ok(record)
    }

    /// Puts `job` on the fleet's work stream (in parts, if it splits into more than a part's
    /// points); refused when the stream holds more than 64 entries per queued job allowed.
    async fn enqueue(
        &self,
        shared: &Shared,
        job: Job,
        meta: Meta,
    ) -> Result<JobRecord, EngineError> {
        let unavailable = |e: super::fleet::Failure| self.refused(EngineError::Unavailable(e.why));
        let backlog = shared.backlog().await.map_err(unavailable)?;
        if backlog >= self.config.max_queued_jobs.saturating_mul(64) {
            return Err(self.refused(EngineError::Overloaded));
        }
        let per_part = shared.fleet.config.part_points;
        let parts = job
            .points()
            .filter(|&n| n > per_part)
            .map(|n| crate::job::parts::ranges(n, per_part))
            .unwrap_or_default();
        let record = JobRecord::queued(self.ids.next(), job.kind(), job.work());
        let deadline = std::time::SystemTime::now() + self.config.job_deadline;
        shared
            .store
            .enqueue(&record, &job.to_wire(), &meta.input_hash, deadline, &parts)
            .await
            .map_err(unavailable)?;
        Ok(record)
    }

    /// `Unavailable` while the fleet's job store cannot be reached.
    pub fn store_reachable(&self) -> Result<(), EngineError> {
        match &self.fleet {
            Some(shared) if !shared.fleet.jobs.is_up() => Err(EngineError::Unavailable(
                "no answer from it at the last try".to_string(),
            )),
            _ => Ok(()),
        }
    }

    /// The reachability of each Redis role, when the engine works in a fleet.
    pub fn fleet_health(&self) -> Option<[(&'static str, bool); 2]> {
        self.fleet.as_ref().map(|shared| shared.fleet.health())
    }

    /// The asynchronous job `id`, unless unknown or expired; a job this process runs has
    /// its progress counted up to now.
    pub async fn job(&self, id: Uuid) -> Option<JobRecord> {
        let mut record = self.jobs.get(id).await?;
        if record.state.status().is_finished() {
            self.collected(id);
        }
        if let Some(live) = self.live().get(&id) {
            if !record.state.status().is_finished() {
                record.done = live.control.done();
            }
        }
        Some(record)
    }

    /// Whether `id` is the id of a job this process accepted (known or forgotten since).
    pub fn issued(&self, id: Uuid) -> bool {
        self.jobs.shared() || self.ids.issued(id)
    }

    /// A receiver of the status changes of the job `id`, if this process runs it.
    pub fn watch(&self, id: Uuid) -> Option<watch::Receiver<JobStatus>> {
        self.live().get(&id).map(|live| live.status.subscribe())
    }

    /// Cancels the job `id`: a queued job at once, a running one at the solver's next check;
    /// waits a little for it to stop and returns it then. A finished job is left as it is.
    pub async fn cancel(&self, id: Uuid) -> Option<JobRecord> {
        let before = self.job(id).await?;
        let live = self.live().get(&id).cloned();
        if live.is_none() && self.jobs.shared() && !before.state.status().is_finished() {
            // Run by a worker of the fleet: it sees the cancel at its next heartbeat.
            let state = JobState::Cancelled { partial: None };
            self.jobs.update(id, state, before.done).await;
        }
        if let Some(live) = live {
            live.cancel();
            let mut status = live.status.subscribe();
            // Still running after the wait: the answer says so, and the job stops soon after.
            let _ = tokio::time::timeout(CANCEL_WAIT, status.wait_for(|s| s.is_finished())).await;
        }
        Some(self.job(id).await.unwrap_or(before))
    }

    /// Cancels the job `id` if it has not finished (see [`Engine::cancel`]) and forgets it;
    /// returns it as it ended.
    pub async fn delete(&self, id: Uuid) -> Option<JobRecord> {
        let record = self.cancel(id).await?;
        self.jobs.remove(id).await;
        Some(record)
    }

    /// Forgets the finished jobs past their retention.
    pub async fn purge_expired_jobs(&self) -> usize {
        self.jobs.purge_expired().await
    }

    /// Stops taking work: new solves and jobs are refused. The jobs accepted, queued or
    /// running, go on; [`Engine::jobs_finished`] waits for them to finish and
    /// [`Engine::jobs_collected`] for their clients to read them.
    pub fn begin_drain(&self) {
        self.draining.store(true, Ordering::SeqCst);
        let unfinished: Vec<Uuid> = self.live().keys().copied().collect();
        let uncollected: Vec<Uuid> = self.uncollected().ids.iter().copied().collect();
        self.owed()
            .extend(unfinished.into_iter().chain(uncollected));
    }

    fn owed(&self) -> MutexGuard<'_, HashSet<Uuid>> {
        self.owed.lock().unwrap_or_else(|p| p.into_inner())
    }

    fn uncollected(&self) -> MutexGuard<'_, Uncollected> {
        self.uncollected.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// A client read the job `id` finished: it owes its client nothing more.
    fn collected(&self, id: Uuid) {
        self.uncollected().ids.remove(&id);
        self.owed().remove(&id);
    }

    /// Resolves when every job unfinished at the start of the drain has been read finished
    /// by its client (polled, or followed to its completion event), so that none of their
    /// answers is lost with the process.
    pub async fn jobs_collected(&self) {
        /// How often the drain looks.
        const LOOK: Duration = Duration::from_millis(20);
        while !self.owed().is_empty() {
            tokio::time::sleep(LOOK).await;
        }
    }

    /// Asynchronous jobs of this process queued or running: those a drain waits to finish.
    pub fn unfinished_jobs(&self) -> usize {
        self.live().len()
    }

    /// Jobs finished that no client has read yet: those a drain waits for clients to read
    /// (once it has begun, the jobs it owes that are finished; before, every one unread).
    pub fn unread_jobs(&self) -> usize {
        if self.is_draining() {
            let live: HashSet<Uuid> = self.live().keys().copied().collect();
            self.owed().iter().filter(|id| !live.contains(id)).count()
        } else {
            self.uncollected().ids.len()
        }
    }

    pub fn is_draining(&self) -> bool {
        self.draining.load(Ordering::SeqCst)
    }

    /// Resolves when every asynchronous job has finished (call after `begin_drain`).
    pub async fn jobs_finished(&self) {
        self.tracker.close();
        self.tracker.wait().await;
    }

    /// Waits (after `begin_drain`) for the jobs to finish until `end`; what is still running
    /// then is interrupted ([`Engine::interrupt_unfinished_jobs`]) and given a second to stop.
    /// Returns whether every job finished in time.
    pub async fn finish_jobs(&self, end: tokio::time::Instant) -> bool {
        if tokio::time::timeout_at(end, self.jobs_finished())
            .await
            .is_ok()
        {
            return true;
        }
        self.interrupt_unfinished_jobs();
        // They stop at their next check, microseconds to milliseconds away.
        let _ = tokio::time::timeout(Duration::from_secs(1), self.jobs_finished()).await;
        false
    }

    /// Stops every job not finished yet (the drain ran out of time): they end
    /// `interrupted`.
    pub fn interrupt_unfinished_jobs(&self) {
        if let Some(shared) = &self.fleet {
            shared.interrupt();
        }
        for live in self.live().values() {
            live.interrupted.store(true, Ordering::SeqCst);
            live.cancel();
        }
    }

    /// The control of a job run by this engine: one thread, `deadline`, the point memo and
    /// the background thread.
    pub(super) fn control(&self, deadline: Instant) -> Control {
        let control = Control::new(Some(deadline), 1).with_memo(self.points.clone());
        match &self.background {
            Some(background) => control.with_later(background.clone()),
            None => control,
        }
    }

    fn admit(&self) -> Result<(), EngineError> {
        if self.is_draining() {
            Err(self.refused(EngineError::Draining))
        } else {
            Ok(())
        }
    }

    /// Counts a refusal (a no to new work) and passes the error on.
    fn refused(&self, e: EngineError) -> EngineError {
        let reason = match e {
            EngineError::Overloaded | EngineError::Backlogged(_) => "overloaded",
            EngineError::Draining => "draining",
            EngineError::Unavailable(_) => "unavailable",
            EngineError::ResultsFull { .. } | EngineError::ResultTooLarge { .. } => "results_full",
            EngineError::Job(_) => return e,
        };
        self.metrics
            .counter(names::REJECTIONS, &[("reason", reason)])
            .increment(1);
        e
    }

    /// Solves `job` holding `permit` (on a blocking thread, or here if it is small), renders
    /// its answer, and records the solve. With `keep` (an asynchronous job's result, kept for
    /// its retention) the answer is rendered in every form now ([`Solved::kept`]), and a job
    /// stopped before its end keeps what it finished.
    async fn execute(
        &self,
        permit: OwnedSemaphorePermit,
        job: Job,
        meta: Meta,
        control: Arc<Control>,
        keep: bool,
    ) -> Result<Arc<Solved>, Stopped> {
        self.cache_misses.increment(1);
        let (kind, small) = (job.kind(), job.is_small());
        let start = Instant::now();
        let solve = move |control: &Control| {
            let key = meta.input_hash.clone();
            let kept = |solved: Solved| match keep {
                true => solved.kept().map_err(|e| JobError::Internal(e.to_string())),
                false => Ok(solved),
            };
            Ok(match job.run_keeping(meta, control) {
                Ok(answer) => Solved::new(key, job.kind(), answer)
                    .and_then(kept)
                    .map(Arc::new)
                    .map_err(Stopped::from),
                Err(Unfinished { error, partial }) => Err(Stopped {
                    error,
                    partial: partial
                        .filter(|_| keep)
                        .and_then(|a| Solved::partial(key, job.kind(), a).and_then(kept).ok())
                        .map(Arc::new),
                }),
            })
        };
        let result = if small {
            // Tens of microseconds: less than the two thread hand-offs of `Pool::run`.
            let _permit = permit;
            solve(&control)
        } else {
            Pool::run(permit, control, solve).await
        }
        .unwrap_or_else(|e| Err(Stopped::from(e)));
        let outcome = match &result {
            Ok(_) => "succeeded",
            Err(Stopped {
                error: JobError::Cancelled,
                ..
            }) => "cancelled",
            Err(Stopped {
                error: JobError::DeadlineExceeded,
                ..
            }) => "deadline_exceeded",
            Err(_) => "failed",
        };
        self.metrics
            .fixed_histogram(
                names::SOLVE_DURATION,
                &[("kind", kind), ("outcome", outcome)],
            )
            .record(start.elapsed());
        result
    }

    /// The life of an asynchronous job after its submission; returns its final state.
    /// Runs an accepted job to its end state; its solve time teaches `ticket`'s class.
    async fn run_job(
        &self,
        live: &LiveJob,
        id: Uuid,
        job: Job,
        meta: Meta,
        ticket: &Ticket,
    ) -> JobState {
        let permit = match self.cache.get(&meta.input_hash).await {
            Some(hit) => {
                self.cache_hits.increment(1);
                Err(JobState::Succeeded(JobResult::Ready(hit)))
            }
            None => tokio::select! {
                () = live.cancel.cancelled() => Err(live.stopped(None)),
                permits = async {
                    let slot = self.job_slots.clone().acquire_owned().await;
                    (slot, self.pool.acquire().await)
                } => Ok(permits),
            },
        };
        self.queued.fetch_sub(1, Ordering::SeqCst);
        self.jobs_queued.decrement(1.0);
        let (_slot, permit) = match permit {
            Ok(permits) => permits,
            Err(state) => return state,
        };
        self.jobs.update(id, JobState::Running, 0).await;
        live.status.send_replace(JobStatus::Running);
        self.jobs_running.increment(1.0);
        let (started, work) = (Instant::now(), job.work());
        let result = self
            .execute(permit, job, meta, live.control.clone(), true)
            .await;
        // A job of unknown work (a fit) is one unit, and teaches only when it ends well;
        // units recalled from the memo (a retry's) cost nothing and teach nothing.
        let done = match (&result, work) {
            (Ok(_), _) => ticket.units(),
            (Err(_), Work::Known(_)) => live.control.done(),
            (Err(_), Work::Unknown) => 0,
        };
        let solved = done.saturating_sub(live.control.recalled());
        ticket.ran(solved, started.elapsed());
        self.jobs_running.decrement(1.0);
        match result {
            Ok(solved) => {
                self.cache.insert(solved.clone()).await;
                JobState::Succeeded(JobResult::Ready(solved))
            }
            Err(Stopped { error, partial }) => {
                let partial = partial.map(JobResult::Ready);
                match error {
                    JobError::Cancelled => live.stopped(partial),
                    error => JobState::Failed { error, partial },
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[tokio::test]
    async fn the_input_memo_takes_an_input_on_its_second_sighting() {
        let config = EngineConfig {
            pool_size: 1,
            solve_deadline: Duration::from_secs(1),
            job_deadline: Duration::from_secs(1),
            max_queued_jobs: 1,
            memory_budget: 1 << 20,
            max_jobs: 1,
            cache_ttl: Duration::from_secs(60),
            job_retention: Duration::from_secs(60),
            spill: None,
        };
        let engine = Engine::new(config, Metrics::noop()).unwrap();
        let input = "rolling\n{\"load\":1e-9}";
        engine.remember_input(input.into(), "key".into());
        assert_eq!(engine.input_keys.get(input), None);
        engine.remember_input(input.into(), "key".into());
        assert_eq!(engine.input_keys.get(input).as_deref(), Some("key"));
    }
}
