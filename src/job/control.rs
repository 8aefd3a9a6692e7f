//! What a running job shares with whoever watches it: a cancel flag, a deadline and a count
//! of work done. A job kind polls it between units of work ([`Control::check`], or the
//! helpers that do it for it: [`Control::solve`], [`Control::map`], [`Control::map_kept`]).

use std::any::Any;
use std::fmt;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::thread;
use std::time::Instant;

use super::JobError;
use crate::model::ModelError;

/// A solved unit of work, as kept.
pub type Kept = Arc<dyn Any + Send + Sync>;

/// Units of work solved before, kept across runs: a job that ran out of time leaves the
/// units it solved for its retry, and jobs that share units share their solves. The engine
/// keeps them within its memory budget.
pub trait Memo: fmt::Debug + Send + Sync {
    /// The unit under `key`, if kept.
    fn recall(&self, key: &str) -> Option<Kept>;
    /// Keeps `value` (about `bytes` in memory) under `key`.
    fn keep(&self, key: String, value: Kept, bytes: usize);
}

/// Work a job leaves to be done off its own path, when the machine has time: the engine runs
/// it on a background thread (see `engine::background`); without one it is dropped.
pub trait Later: fmt::Debug + Send + Sync {
    /// Runs `work` some time later, once per `key` while it is pending, or not at all if
    /// too much is pending already.
    fn offer(&self, key: String, work: Box<dyn FnOnce() + Send>);
}

/// Shared between a running job and whoever watches it: progress, cancellation, deadline.
#[derive(Debug)]
pub struct Control {
    cancelled: AtomicBool,
    deadline: Option<Instant>,
    done: AtomicUsize,
    threads: usize,
    memo: Option<Arc<dyn Memo>>,
    later: Option<Arc<dyn Later>>,
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
            memo: None,
            later: None,
        }
    }

    /// The same control, keeping solved units in `memo` ([`Control::map_kept`]).
    pub fn with_memo(mut self, memo: Arc<dyn Memo>) -> Self {
        self.memo = Some(memo);
        self
    }

    /// The same control, leaving work for later to `later` ([`Control::later`]).
    pub fn with_later(mut self, later: Arc<dyn Later>) -> Self {
        self.later = Some(later);
        self
    }

    /// Offers `work` to be done later, off this job's path (see [`Later`]); without a
    /// [`Later`] the work is dropped.
    pub fn later(&self, key: String, work: impl FnOnce() + Send + 'static) {
        if let Some(later) = &self.later {
            later.offer(key, Box::new(work));
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

    /// [`Control::map`] for units worth keeping: an item whose `key` is in the control's
    /// memo is recalled rather than solved, and every item solved is kept there at once, so
    /// that what a run solved before its deadline is not lost to its retry. `bytes` is what
    /// one solution holds in memory. Without a memo it is [`Control::map`].
    pub fn map_kept<T: Sync, R: Clone + Send + Sync + 'static>(
        &self,
        items: &[T],
        key: impl Fn(&T) -> String + Sync,
        bytes: impl Fn(&R) -> usize + Sync,
        solve: impl Fn(&T) -> Result<R, ModelError> + Sync,
    ) -> Result<Vec<R>, JobError> {
        let Some(memo) = &self.memo else {
            return self.map(items, solve);
        };
        self.map(items, |item| {
            let key = key(item);
            if let Some(kept) = memo.recall(&key).and_then(|k| k.downcast::<R>().ok()) {
                return Ok((*kept).clone());
            }
            let solution = solve(item)?;
            let size = bytes(&solution);
            memo.keep(key, Arc::new(solution.clone()), size);
            Ok(solution)
        })
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
