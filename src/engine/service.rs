//! The compute path of the service: validated job → cache key → cache lookup that coalesces
//! identical misses → a permit (or a refusal) → a blocking thread with a deadline and a
//! cancel flag. Synchronous solves and asynchronous jobs both go through it.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use metrics::{Counter, Gauge};
use tokio::sync::OwnedSemaphorePermit;
use tokio_util::task::TaskTracker;
use tracing::Instrument;
use uuid::Uuid;

use super::cache::{ResultCache, Solved};
use super::jobs::{JobEntry, JobState, JobStatus, JobStore};
use super::metrics::{self as names, Metrics};
use super::pool::Pool;
use super::{run_with_meta, Control};
use crate::job::{Job, JobError, Meta};

/// Memory for the map from input text to cache key (bytes): a few thousand typical inputs.
const INPUT_KEYS_BYTES: u64 = 16 << 20;

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
    /// Memory for cached answers (bytes, roughly).
    pub cache_bytes: u64,
    /// How long an answer stays cached.
    pub cache_ttl: Duration,
    /// How long a finished asynchronous job is kept.
    pub job_retention: Duration,
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

/// The compute service: pool, cache and asynchronous jobs.
pub struct Engine {
    config: EngineConfig,
    pool: Pool,
    cache: ResultCache,
    /// The text of valid inputs (their kind and compact JSON with sorted keys) → their
    /// cache key, so that a repeated request is answered without being validated again.
    input_keys: moka::future::Cache<String, String>,
    jobs: JobStore,
    /// The tasks of asynchronous jobs, waited for on shutdown.
    tracker: TaskTracker,
    draining: AtomicBool,
    /// Asynchronous jobs waiting for a permit.
    queued: AtomicUsize,
    metrics: Metrics,
    cache_hits: Counter,
    cache_misses: Counter,
    jobs_queued: Gauge,
    jobs_running: Gauge,
}

impl Engine {
    pub fn new(config: EngineConfig, metrics: Metrics) -> Arc<Engine> {
        Arc::new(Engine {
            pool: Pool::new(config.pool_size),
            cache: ResultCache::new(config.cache_bytes, config.cache_ttl),
            input_keys: moka::future::Cache::builder()
                .max_capacity(INPUT_KEYS_BYTES)
                .weigher(|input: &String, key: &String| {
                    u32::try_from(input.len() + key.len()).unwrap_or(u32::MAX)
                })
                .time_to_live(config.cache_ttl)
                .build(),
            jobs: JobStore::new(config.job_retention),
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

    /// The cached answer to an input seen before (`text`: its kind and compact JSON), found
    /// without validating the input again; `None` if it was not seen or its answer expired.
    /// Refused while draining, like every other call for an answer.
    pub async fn cached_input(&self, text: &str) -> Result<Option<Arc<Solved>>, EngineError> {
        self.admit()?;
        let Some(key) = self.input_keys.get(text).await else {
            return Ok(None);
        };
        let solved = self.cache.get(&key).await;
        if solved.is_some() {
            self.cache_hits.increment(1);
        }
        Ok(solved)
    }

    /// Remembers that the input `text` (as for [`Engine::cached_input`]) is a valid job
    /// with cache key `key`.
    pub async fn remember_input(&self, text: String, key: String) {
        self.input_keys.insert(text, key).await;
    }

    /// Solves `job`, whose [`Meta`] is `meta` (computed once by the caller: it holds the
    /// cache key), now, or takes its answer from the cache. Identical concurrent calls share
    /// one solve. With no solver thread free the call is refused at once.
    pub async fn solve(
        &self,
        job: Job,
        meta: Meta,
    ) -> Result<(Arc<Solved>, CacheStatus), EngineError> {
        self.admit()?;
        let key = meta.input_hash.clone();
        let solve = async {
            let permit = self.pool.try_acquire().ok_or(EngineError::Overloaded)?;
            let deadline = Instant::now() + self.config.solve_deadline;
            let control = Arc::new(Control::new(Some(deadline), 1));
            Ok(self.execute(permit, job, meta, control).await?)
        };
        let (solved, fresh) = self
            .cache
            .get_or_solve(key.clone(), solve)
            .await
            .map_err(|e| self.refused(e))?;
        if fresh {
            Ok((solved, CacheStatus::Miss))
        } else {
            self.cache_hits.increment(1);
            Ok((solved, CacheStatus::Hit))
        }
    }

    /// Queues `job` to run in the background; its entry tracks it. Refused when the queue
    /// is full or the service is draining.
    pub fn submit(self: &Arc<Self>, job: Job) -> Result<Arc<JobEntry>, EngineError> {
        self.admit()?;
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
        self.jobs_queued.increment(1.0);
        let deadline = Instant::now() + self.config.job_deadline;
        let control = Arc::new(Control::new(Some(deadline), 1));
        let entry = self
            .jobs
            .insert(JobEntry::new(job.kind(), job.size(), control));
        let span = tracing::info_span!("job", id = %entry.id, kind = job.kind().as_str());
        let (engine, task_entry) = (self.clone(), entry.clone());
        self.tracker.spawn(
            async move {
                let state = engine.run_job(&task_entry, job).await;
                tracing::info!(status = state.status().as_str(), "job finished");
                task_entry.set_state(state);
            }
            .instrument(span),
        );
        Ok(entry)
    }

    /// The asynchronous job `id`, unless unknown or expired.
    pub fn job(&self, id: Uuid) -> Option<Arc<JobEntry>> {
        self.jobs.get(id)
    }

    /// Forgets the finished jobs past their retention.
    pub fn purge_expired_jobs(&self) -> usize {
        self.jobs.purge_expired()
    }

    /// Stops taking work: new solves and jobs are refused, queued jobs are cancelled.
    /// Running jobs go on; [`Engine::jobs_finished`] waits for them.
    pub fn begin_drain(&self) {
        self.draining.store(true, Ordering::SeqCst);
        for entry in self.jobs.with_status(JobStatus::Queued) {
            entry.cancel();
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

    /// Cancels every job still running (when the drain ran out of time).
    pub fn cancel_running_jobs(&self) {
        for entry in self.jobs.with_status(JobStatus::Running) {
            entry.cancel();
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
            EngineError::Overloaded => "overloaded",
            EngineError::Draining => "draining",
            EngineError::Job(_) => return e,
        };
        self.metrics
            .counter(names::REJECTIONS, &[("reason", reason)])
            .increment(1);
        e
    }

    /// Solves `job` on a blocking thread holding `permit`, renders its answer there, and
    /// records the solve.
    async fn execute(
        &self,
        permit: OwnedSemaphorePermit,
        job: Job,
        meta: Meta,
        control: Arc<Control>,
    ) -> Result<Arc<Solved>, JobError> {
        self.cache_misses.increment(1);
        let kind = job.kind();
        let start = Instant::now();
        let result = Pool::run(permit, control, move |control| {
            let key = meta.input_hash.clone();
            Solved::new(key, run_with_meta(&job, meta, control)?).map(Arc::new)
        })
        .await;
        let outcome = match &result {
            Ok(_) => "succeeded",
            Err(JobError::Cancelled) => "cancelled",
            Err(JobError::DeadlineExceeded) => "deadline_exceeded",
            Err(_) => "failed",
        };
        self.metrics
            .histogram(
                names::SOLVE_DURATION,
                &[("kind", kind.as_str()), ("outcome", outcome)],
            )
            .record(start.elapsed());
        result
    }

    /// The life of an asynchronous job after its submission; returns its final state.
    async fn run_job(&self, entry: &JobEntry, job: Job) -> JobState {
        let meta = job.meta();
        let permit = match self.cache.get(&meta.input_hash).await {
            Some(hit) => {
                self.cache_hits.increment(1);
                Err(JobState::Succeeded(hit))
            }
            None => tokio::select! {
                () = entry.cancelled() => Err(JobState::Cancelled),
                permit = self.pool.acquire() => Ok(permit),
            },
        };
        self.queued.fetch_sub(1, Ordering::SeqCst);
        self.jobs_queued.decrement(1.0);
        let permit = match permit {
            Ok(permit) => permit,
            Err(state) => return state,
        };
        entry.set_state(JobState::Running);
        self.jobs_running.increment(1.0);
        let result = self.execute(permit, job, meta, entry.control()).await;
        self.jobs_running.decrement(1.0);
        match result {
            Ok(solved) => {
                self.cache.insert(solved.clone()).await;
                JobState::Succeeded(solved)
            }
            Err(JobError::Cancelled) => JobState::Cancelled,
            Err(e) => JobState::Failed(e),
        }
    }
}
