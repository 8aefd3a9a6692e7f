//! The solve path: keyed job → cache → one solve per key in flight → a permit (or a refusal)
//! → a blocking thread with a deadline and a cancel flag → the answer rendered and kept.
//! Synchronous solves, asynchronous jobs and the fleet's workers all solve through it.

use std::sync::Arc;
use std::time::Instant;

use futures_util::FutureExt;
use metrics::{Counter, Gauge};

use super::bounded::Bounded;
use super::budget::{self, Budget};
use super::cache::{Claim, ResultCache, Solved};
use super::coalesce::Coalescer;
use super::config::EngineConfig;
use super::doorkeeper::Doorkeeper;
use super::error::EngineError;
use super::memo::PointMemo;
use super::metrics::{self as names, Metrics, SolveDurations};
use super::pool::{Permit, Pool};
use crate::job::{Control, JobError, Keyed, Unfinished};

/// Whether an answer came from the cache or was solved for this call.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CacheStatus {
    Hit,
    Miss,
}

impl CacheStatus {
    pub fn as_str(self) -> &'static str {
        ["hit", "miss"][self as usize]
    }
}

/// What a solve does with the cache besides reading it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CacheUse {
    /// Keeps the answer for the next caller (a client's solve).
    Keep,
    /// Lets the answer go once the caller has it (a large answer solved for a check, which
    /// nobody else asks for; identical concurrent solves share it, unkept).
    ReadOnly,
}

/// A solve that did not answer ([`crate::job::Unfinished`]).
pub(super) struct Stopped {
    pub error: JobError,
    /// What it finished (kept for an asynchronous job only).
    pub partial: Option<Arc<Solved>>,
}

impl From<JobError> for Stopped {
    fn from(error: JobError) -> Self {
        Stopped {
            error,
            partial: None,
        }
    }
}

/// The solver threads, the answers and what is remembered between requests.
pub struct Solver {
    pub(super) pool: Pool,
    pub(super) cache: Arc<dyn ResultCache>,
    coalescer: Coalescer,
    /// Valid inputs' text (kind and compact JSON) → cache key: a repeat is not validated again.
    input_keys: Bounded<Arc<str>>,
    doorkeeper: Doorkeeper,
    points: Arc<PointMemo>,
    metrics: Metrics,
    solve_durations: SolveDurations,
    cache_hits: Counter,
    cache_misses: Counter,
    jobs_running: Gauge,
}

impl Solver {
    pub fn new(config: &EngineConfig, metrics: Metrics, cache: Arc<dyn ResultCache>) -> Self {
        let budget = Budget::split(config.memory_budget);
        Solver {
            pool: Pool::new(config.pool_size, budget.solves),
            cache,
            coalescer: Coalescer::default(),
            // An input and its key weigh about 100 bytes, and the entry's overhead more.
            input_keys: Bounded::new(
                budget.inputs,
                config.cache_ttl,
                budget::ENTRY_OVERHEAD,
                |key: &Arc<str>| key.len() as u64,
            ),
            doorkeeper: Doorkeeper::new(budget.inputs / budget::ENTRY_OVERHEAD),
            points: Arc::new(PointMemo::new(budget.points, config.cache_ttl)),
            cache_hits: metrics.counter(names::CACHE_HITS, &[]),
            cache_misses: metrics.counter(names::CACHE_MISSES, &[]),
            jobs_running: metrics.gauge(names::JOBS_RUNNING, &[]),
            solve_durations: SolveDurations::new(metrics.clone()),
            metrics,
        }
    }

    pub fn metrics(&self) -> &Metrics {
        &self.metrics
    }

    /// The cached answer to the input `text` (its kind and compact JSON) if it was seen
    /// before, found without validating it again.
    pub(super) async fn cached_input(&self, text: &str) -> Option<Arc<Solved>> {
        let key = self.input_keys.get(text)?;
        self.cached(&key).await
    }

    /// Remembers that the valid input `text` has the cache key `key`, if it was seen before
    /// ([`Doorkeeper`]).
    pub(super) fn remember_input(&self, text: String, key: String) {
        if self.doorkeeper.seen_before(&text) {
            self.input_keys.insert(text, key.into());
        }
    }

    /// The cached answer under `key`, counted as a hit.
    pub async fn cached(&self, key: &str) -> Option<Arc<Solved>> {
        let solved = self.cache.get(key).await;
        solved.inspect(|_| self.cache_hits.increment(1))
    }

    /// Solves `keyed` by `deadline`, or takes its answer from the cache. Identical concurrent
    /// calls share one solve (in a fleet, one across processes). With no solver thread free
    /// the call is refused at once.
    pub async fn solve_by(
        self: &Arc<Self>,
        keyed: Keyed,
        deadline: Instant,
        cache: CacheUse,
    ) -> Result<(Arc<Solved>, CacheStatus), EngineError> {
        let key = keyed.key().to_string();
        if let Some(solved) = self.cached(&key).await {
            return Ok((solved, CacheStatus::Hit));
        }
        let solver = self.clone();
        let key_claimed = key.clone();
        let solve = move || {
            async move {
                if let Claim::Solved(solved) = solver.cache.claim(&key_claimed, deadline).await? {
                    return Ok(solved);
                }
                let solved = solver.solve_claimed(keyed, deadline, cache).await;
                solver.cache.release(&key_claimed).await;
                solved
            }
            .boxed()
        };
        let (solved, started) = self.coalescer.run(&key, solve).await;
        let solved = solved?;
        if started {
            Ok((solved, CacheStatus::Miss))
        } else {
            self.cache_hits.increment(1);
            Ok((solved, CacheStatus::Hit))
        }
    }

    /// Solves `keyed` now, this process holding the fleet's claim on it.
    async fn solve_claimed(
        &self,
        keyed: Keyed,
        deadline: Instant,
        cache: CacheUse,
    ) -> Result<Arc<Solved>, EngineError> {
        let bytes = keyed.job().cost().bytes;
        let permit = self
            .pool
            .try_acquire(bytes)
            .ok_or(EngineError::Overloaded)?;
        let control = Arc::new(self.control(deadline));
        let solved = self
            .execute(permit, keyed, control, false)
            .await
            .map_err(|stopped| stopped.error)?;
        if cache == CacheUse::Keep {
            self.cache.insert(solved.clone()).await;
        }
        Ok(solved)
    }

    /// The control of a job run by this engine: one thread (lent more while cores are idle,
    /// at the lowest priority), `deadline`, the point memo.
    pub(super) fn control(&self, deadline: Instant) -> Control {
        Control::new(Some(deadline), 1)
            .with_memo(self.points.clone())
            .with_lent_threads(super::heavy::lent_thread)
    }

    /// Counts a job as running (the `jobs_running` gauge) until the guard is dropped.
    pub(super) fn running(&self) -> Running {
        self.jobs_running.increment(1.0);
        Running(self.jobs_running.clone())
    }

    /// Solves `keyed` holding `permit`, renders its answer, and records the solve. With
    /// `keep` (an asynchronous job's result, kept for its retention) the answer is rendered
    /// in every form now ([`Solved::kept`]), and a stopped job keeps what it finished.
    pub(super) async fn execute(
        &self,
        permit: Permit,
        keyed: Keyed,
        control: Arc<Control>,
        keep: bool,
    ) -> Result<Arc<Solved>, Stopped> {
        self.cache_misses.increment(1);
        let (job, meta, key) = keyed.into_parts();
        let (kind, small) = (job.kind(), job.is_small());
        let start = Instant::now();
        let solve = move |control: &Control| {
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
        let outcome = match result.as_ref().map_err(|stopped| &stopped.error) {
            Ok(_) => "succeeded",
            Err(JobError::Cancelled) => "cancelled",
            Err(JobError::DeadlineExceeded) => "deadline_exceeded",
            Err(_) => "failed",
        };
        self.solve_durations
            .record(kind.name(), outcome, start.elapsed());
        result
    }
}

pub(super) struct Running(Gauge);

impl Drop for Running {
    fn drop(&mut self) {
        self.0.decrement(1.0);
    }
}

#[cfg(test)]
mod tests {
    use std::time::Duration;

    use super::*;
    use crate::engine::cache::MemoryCache;

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
            database: crate::engine::archive::IN_MEMORY.to_string(),
            history_retention: Duration::from_secs(3600),
        };
        let cache = Arc::new(MemoryCache::for_engine(&config));
        let solver = Solver::new(&config, Metrics::noop(), cache);
        let input = "rolling\n{\"load\":1e-9}";
        solver.remember_input(input.into(), "key".into());
        assert_eq!(solver.input_keys.get(input), None);
        solver.remember_input(input.into(), "key".into());
        assert_eq!(solver.input_keys.get(input).as_deref(), Some("key"));
    }
}
