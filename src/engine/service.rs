//! The engine: what the service asks of the compute side, behind one type. It admits or
//! refuses new work (and counts refusals) and hands each call to its part: the solve path
//! ([`Solver`]) or the life of asynchronous jobs ([`Lifecycle`]).

use std::collections::HashSet;
use std::future::Future;
use std::sync::Arc;
use std::time::{Duration, Instant};

use super::admission::{Admissions, Turn};
use super::archive::ArchiveError;
use super::cache::Solved;
use super::config::EngineConfig;
use super::error::EngineError;
use super::fleet::Fleet;
use super::lifecycle::{Lifecycle, OnEnd};
use super::metrics::{self as names, Metrics};
use super::quota::{Charge, PointCounts};
use super::solver::{CacheStatus, CacheUse, Solver};
use super::storage::Storage;
use super::store::{JobRecord, JobStatus, Listing, Owner};
use crate::job::Keyed;

/// The unfinished jobs of one tenant counted at most: far more than any quota of them.
const UNFINISHED_COUNTED: usize = 10_000;

/// The compute service: the solve path and the asynchronous jobs.
pub struct Engine {
    solve_deadline: Duration,
    pub solver: Arc<Solver>,
    pub jobs: Arc<Lifecycle>,
    /// The points each tenant asked for this minute: their quota's count.
    pub points: Arc<PointCounts>,
    admissions: Admissions,
    fleet: Option<Arc<Fleet>>,
}

impl Engine {
    pub fn new(config: EngineConfig, metrics: Metrics) -> Result<Arc<Engine>, ArchiveError> {
        let storage = Storage::in_process(&config)?;
        Ok(Engine::with_storage(config, metrics, storage))
    }

    pub fn with_storage(config: EngineConfig, metrics: Metrics, storage: Storage) -> Arc<Engine> {
        if let Some(shared) = &storage.fleet {
            for link in [&shared.fleet.cache, &shared.fleet.jobs] {
                link.report_to(metrics.gauge(names::REDIS_UP, &[("role", link.role)]));
            }
        }
        let solver = Arc::new(Solver::new(&config, metrics.clone(), storage.cache));
        let fleet = storage.fleet.as_ref().map(|s| s.fleet.clone());
        let points = Arc::new(PointCounts::new(fleet.clone()));
        let jobs = Lifecycle::new(
            config.clone(),
            &metrics,
            solver.clone(),
            storage.jobs,
            storage.fleet,
        );
        Arc::new(Engine {
            solve_deadline: config.solve_deadline,
            solver,
            jobs: Arc::new(jobs),
            points,
            admissions: Admissions::default(),
            fleet,
        })
    }

    /// `tenant`'s turn to admit a job (its quotas counted, then the job stored), after its
    /// admissions before, in this process and across a fleet ([`Admissions`]).
    pub async fn turn(&self, tenant: &str) -> Result<Turn, EngineError> {
        self.admissions.turn(tenant, self.fleet.as_ref()).await
    }

    /// The jobs of `owner` not finished yet (queued or running), as the job store lists them.
    pub async fn unfinished_of(&self, owner: &Owner) -> Result<usize, EngineError> {
        // Two listings, one a status: a job that starts running between them is in both,
        // and counted once by its id (counted by totals, it was counted twice).
        let mut unfinished = HashSet::new();
        for status in [JobStatus::Queued, JobStatus::Running] {
            let listing = Listing {
                owner: owner.clone(),
                kind: None,
                status: Some(status),
                offset: 0,
                limit: UNFINISHED_COUNTED,
            };
            let page = self.jobs.list(&listing).await?;
            unfinished.extend(page.jobs.iter().map(|job| job.id));
        }
        Ok(unfinished.len())
    }

    pub fn metrics(&self) -> &Metrics {
        self.solver.metrics()
    }

    /// Answers the input `text` (its kind and compact JSON, as sent): one seen before whose
    /// answer is cached at once, without validating it again (validation and the cache key
    /// cost more than the look-up); else `validate` makes its job, which is solved. The
    /// caller decides where `validate` runs (a large input is read on a blocking thread).
    pub async fn answer<E: From<EngineError>>(
        self: &Arc<Self>,
        text: String,
        validate: impl Future<Output = Result<Keyed, E>>,
    ) -> Result<(Arc<Solved>, CacheStatus), E> {
        self.admit()?;
        if let Some(solved) = self.solver.cached_input(&text).await {
            return Ok((solved, CacheStatus::Hit));
        }
        let keyed = validate.await?;
        self.solver.remember_input(text, keyed.key().to_string());
        Ok(self.solve(keyed).await?)
    }

    /// Solves `keyed` now, or takes its answer from the cache. Identical concurrent calls
    /// share one solve. With no solver thread free the call is refused at once.
    pub async fn solve(
        self: &Arc<Self>,
        keyed: Keyed,
    ) -> Result<(Arc<Solved>, CacheStatus), EngineError> {
        let deadline = Instant::now() + self.solve_deadline;
        self.solve_by(keyed, deadline, CacheUse::Keep).await
    }

    /// [`Engine::solve`] by the caller's deadline (shared by several solves, as a checks
    /// suite's; never later than the solve deadline), using the cache as `cache` says.
    pub async fn solve_by(
        self: &Arc<Self>,
        keyed: Keyed,
        deadline: Instant,
        cache: CacheUse,
    ) -> Result<(Arc<Solved>, CacheStatus), EngineError> {
        self.admit()?;
        let deadline = deadline.min(Instant::now() + self.solve_deadline);
        let solved = self.solver.solve_by(keyed, deadline, cache).await;
        solved.map_err(|e| self.refused(e))
    }

    /// Queues `keyed` to run in the background ([`Lifecycle::submit`]). `charged`: the points
    /// a quota charged for it, trued up when it ends if they were a guess (in this process;
    /// a fleet's workers run jobs elsewhere, and the guess stands), refunded if refused.
    pub async fn submit(
        &self,
        keyed: Keyed,
        owner: Option<Owner>,
        charged: Option<Charge>,
    ) -> Result<JobRecord, EngineError> {
        self.admit()?;
        let points = self.points.clone();
        let on_end = charged
            .clone()
            .filter(|c| c.guessed)
            .map(|charge| -> OnEnd {
                Box::new(move |took| {
                    tokio::spawn(async move { points.true_up(&charge, took).await });
                })
            });
        let record = self.jobs.submit(keyed, owner, on_end).await;
        if let (Err(_), Some(charge)) = (&record, &charged) {
            self.points.refund(charge).await;
        }
        record.map_err(|e| self.refused(e))
    }

    fn admit(&self) -> Result<(), EngineError> {
        if self.jobs.is_draining() {
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
        self.metrics()
            .counter(names::REJECTIONS, &[("reason", reason)])
            .increment(1);
        e
    }
}
