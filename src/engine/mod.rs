//! Runs validated jobs: one rolling solve, or the many of a sweep or figure spread over the
//! cores, with progress, cancellation and a deadline checked between solves.
//!
//! This is the only place that knows how a job maps onto model calls; the CLI calls [`run`]
//! directly. The HTTP service goes through an [`Engine`]: admission control on a pool of
//! permits sized to the cores ([`pool`]), a result cache that coalesces identical misses
//! ([`cache`]) and a store of asynchronous jobs ([`jobs`]).

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;
use std::thread;
use std::time::Instant;

use serde::Serialize;
use utoipa::ToSchema;

use crate::job::figure::FigureOutput;
use crate::job::rolling::RollingOutput;
use crate::job::sweep::{SweepJob, SweepOutput};
use crate::job::three_body::ThreeBodyOutput;
use crate::job::{Job, JobError, Meta};
use crate::model::{self, three_body, ModelError};

pub mod cache;
pub mod jobs;
pub mod metrics;
pub mod pool;
mod service;

pub use service::{CacheStatus, Engine, EngineConfig, EngineError};

/// Shared between a running job and whoever watches it: progress, cancellation, deadline.
#[derive(Debug)]
pub struct Control {
    cancelled: AtomicBool,
    deadline: Option<Instant>,
    done: AtomicUsize,
    threads: usize,
}

impl Default for Control {
    /// No deadline, one thread per available core.
    fn default() -> Self {
        Control::new(None, thread::available_parallelism().map_or(1, |n| n.get()))
    }
}

impl Control {
    /// A control with an optional `deadline` that lets a job use up to `threads` threads.
    pub fn new(deadline: Option<Instant>, threads: usize) -> Self {
        Control {
            cancelled: AtomicBool::new(false),
            deadline,
            done: AtomicUsize::new(0),
            threads: threads.max(1),
        }
    }

    /// Asks the job to stop at its next check (between two solves).
    pub fn cancel(&self) {
        self.cancelled.store(true, Ordering::Relaxed);
    }

    /// Rolling solves finished so far.
    pub fn done(&self) -> usize {
        self.done.load(Ordering::Relaxed)
    }

    fn check(&self) -> Result<(), JobError> {
        if self.cancelled.load(Ordering::Relaxed) {
            Err(JobError::Cancelled)
        } else if self.deadline.is_some_and(|d| Instant::now() >= d) {
            Err(JobError::DeadlineExceeded)
        } else {
            Ok(())
        }
    }
}

/// The answer to any job.
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
#[serde(untagged)]
pub enum Output {
    Rolling(RollingOutput),
    ThreeBody(ThreeBodyOutput),
    Sweep(SweepOutput),
    Figure(FigureOutput),
}

/// Runs `job` to completion, or until `control` stops it.
pub fn run(job: &Job, control: &Control) -> Result<Output, JobError> {
    run_with_meta(job, job.meta(), control)
}

/// [`run`] for a caller that already holds the job's [`Meta`] (its cache key).
pub fn run_with_meta(job: &Job, meta: Meta, control: &Control) -> Result<Output, JobError> {
    Ok(match job {
        Job::Rolling(j) => {
            let solution = parallel_map(&[j.rolling], control, |p| model::solve(p, &j.options))?;
            Output::Rolling(RollingOutput::new(&solution[0], meta))
        }
        Job::ThreeBody(j) => {
            let solution =
                parallel_map(&[j.system], control, |s| three_body::solve(s, &j.options))?;
            Output::ThreeBody(ThreeBodyOutput::new(&solution[0], meta))
        }
        Job::Sweep(sweep) => Output::Sweep(match sweep {
            SweepJob::Rolling(s) => {
                let options = &s.base.options;
                let solutions = parallel_map(&s.points(), control, |p| model::solve(p, options))?;
                SweepOutput::rolling(s, &solutions, meta)
            }
            SweepJob::ThreeBody(s) => {
                let options = &s.base.options;
                let solutions =
                    parallel_map(&s.points(), control, |p| three_body::solve(p, options))?;
                SweepOutput::three_body(s, &solutions, meta)
            }
        }),
        Job::Figure(j) => {
            let options = &j.plan.options;
            let solutions = parallel_map(&j.plan.contacts, control, |p| model::solve(p, options))?;
            Output::Figure(FigureOutput::new(j.plan.assemble(&solutions), meta))
        }
    })
}

/// Applies `solve` to every item, in parallel over `control`'s threads, results in order.
/// Stops at the first failure, cancellation or deadline.
pub fn parallel_map<T: Sync, R: Send>(
    items: &[T],
    control: &Control,
    solve: impl Fn(&T) -> Result<R, ModelError> + Sync,
) -> Result<Vec<R>, JobError> {
    let next = AtomicUsize::new(0);
    let failure: Mutex<Option<JobError>> = Mutex::new(None);
    let failed = AtomicBool::new(false);
    let worker = || {
        let mut solved = Vec::new();
        while !failed.load(Ordering::Relaxed) {
            let i = next.fetch_add(1, Ordering::Relaxed);
            let Some(item) = items.get(i) else { break };
            match control
                .check()
                .and_then(|()| solve(item).map_err(JobError::from))
            {
                Ok(solution) => {
                    control.done.fetch_add(1, Ordering::Relaxed);
                    solved.push((i, solution));
                }
                Err(e) => {
                    failed.store(true, Ordering::Relaxed);
                    failure
                        .lock()
                        .unwrap_or_else(|p| p.into_inner())
                        .get_or_insert(e);
                }
            }
        }
        solved
    };
    let threads = control.threads.min(items.len()).max(1);
    let mut solved: Vec<(usize, R)> = if threads == 1 {
        worker()
    } else {
        thread::scope(|s| {
            let handles: Vec<_> = (0..threads).map(|_| s.spawn(worker)).collect();
            handles
                .into_iter()
                .flat_map(|h| h.join().unwrap_or_default())
                .collect()
        })
    };
    if let Some(e) = failure.into_inner().unwrap_or_else(|p| p.into_inner()) {
        return Err(e);
    }
    if solved.len() != items.len() {
        return Err(JobError::Internal(
            "a solver thread stopped unexpectedly".to_string(),
        ));
    }
    solved.sort_by_key(|(i, _)| *i);
    Ok(solved.into_iter().map(|(_, s)| s).collect())
}
