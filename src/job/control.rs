//! What a running job shares with whoever watches it: a cancel flag, a deadline and a count
//! of work done. A job kind polls it between units of work ([`Control::check`], or the
//! helpers that do it for it: [`Control::solve`], [`Control::map`]).

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;
use std::thread;
use std::time::Instant;

use super::JobError;
use crate::model::ModelError;

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

    /// Asks the job to stop at its next check.
    pub fn cancel(&self) {
        self.cancelled.store(true, Ordering::Relaxed);
    }

    /// Units of work done so far (the job's [`super::Work`] counts in the same units).
    pub fn done(&self) -> usize {
        self.done.load(Ordering::Relaxed)
    }

    /// Records `units` more of work done.
    pub fn advance(&self, units: usize) {
        self.done.fetch_add(units, Ordering::Relaxed);
    }

    /// `Err` once the job is cancelled or past its deadline: a job calls this between units
    /// of work and stops with the error.
    pub fn check(&self) -> Result<(), JobError> {
        if self.cancelled.load(Ordering::Relaxed) {
            Err(JobError::Cancelled)
        } else if self.deadline.is_some_and(|d| Instant::now() >= d) {
            Err(JobError::DeadlineExceeded)
        } else {
            Ok(())
        }
    }

    /// One unit of work: checked first, counted when it succeeds.
    pub fn solve<R>(&self, solve: impl FnOnce() -> Result<R, ModelError>) -> Result<R, JobError> {
        self.check()?;
        let solution = solve()?;
        self.advance(1);
        Ok(solution)
    }

    /// Applies `solve` to every item, in parallel over the control's threads, results in
    /// order; one unit of work per item. Stops at the first failure, cancellation or
    /// deadline.
    pub fn map<T: Sync, R: Send>(
        &self,
        items: &[T],
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
                match self.solve(|| solve(item)) {
                    Ok(solution) => solved.push((i, solution)),
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
        let threads = self.threads.min(items.len()).max(1);
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
}
