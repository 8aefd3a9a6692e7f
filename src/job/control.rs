//! What a running job shares with whoever watches it: a cancel flag, a deadline and a count
//! of work done. A job kind polls it between units of work ([`Control::check`], or the
//! helpers that do it for it: [`Control::solve`], [`Control::map`], [`Control::map_each`], [`Control::kept`]).

use std::any::Any;
use std::fmt;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::thread;
use std::time::Instant;

use serde::{Deserialize, Serialize};
use utoipa::ToSchema;

use super::JobError;
use crate::model::{ModelError, Stop};

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

/// What a job that maps over items does with an item the model refuses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum OnRefusal {
    /// Go on with the other items: the refused one is answered with the reason (default).
    #[default]
    Continue,
    /// Stop at the first refusal: the job fails with it.
    Fail,
}

/// What became of the items of a [`Control::map_each`].
#[derive(Debug)]
pub struct Swept<R, E> {
    /// Each item's solution or refusal, in order; `None` for an item the map did not reach
    /// because it stopped.
    pub outcomes: Vec<Option<Result<R, E>>>,
    /// Why the map stopped before reaching every item (a cancel, the deadline); `None`
    /// also when it stopped at a refusal ([`OnRefusal::Fail`]), which is in `outcomes`.
    pub stopped: Option<JobError>,
}

impl<R, E> Swept<R, E> {
    /// Takes the first refusal out, with its index.
    pub fn take_first_refusal(&mut self) -> Option<(usize, E)> {
        let i = self
            .outcomes
            .iter()
            .position(|o| matches!(o, Some(Err(_))))?;
        match self.outcomes[i].take() {
            Some(Err(e)) => Some((i, e)),
            _ => None,
        }
    }
}

/// Shared between a running job and whoever watches it: progress, cancellation, deadline.
#[derive(Debug)]
pub struct Control {
    cancelled: AtomicBool,
    deadline: Option<Instant>,
    done: AtomicUsize,
    /// Units recalled from the memo rather than solved.
    recalled: AtomicUsize,
    /// Threads the job may use; the engine lends a running job more while cores are idle.
    threads: AtomicUsize,
    /// Called on each thread past the first that [`Control::map_each`] starts (the engine
    /// puts it in the idle class: a lent thread takes only a core nobody else wants).
    lent_thread: Option<fn()>,
    memo: Option<Arc<dyn Memo>>,
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
            recalled: AtomicUsize::new(0),
            threads: AtomicUsize::new(threads.max(1)),
            lent_thread: None,
            memo: None,
        }
    }

    /// The same control, calling `start` on each thread past the first it runs items on.
    pub fn with_lent_threads(mut self, start: fn()) -> Self {
        self.lent_thread = Some(start);
        self
    }

    /// The threads the job may use.
    pub fn threads(&self) -> usize {
        self.threads.load(Ordering::Relaxed)
    }

    /// Lets the job use `threads` threads from its next [`Control::map_each`] on.
    pub fn set_threads(&self, threads: usize) {
        self.threads.store(threads.max(1), Ordering::Relaxed);
    }

    /// The same control, keeping solved units in `memo` ([`Control::kept`]).
    pub fn with_memo(mut self, memo: Arc<dyn Memo>) -> Self {
        self.memo = Some(memo);
        self
    }

    /// Asks the job to stop at its next check.
    pub fn cancel(&self) {
        self.cancelled.store(true, Ordering::Relaxed);
    }

    /// Units of work done so far (the job's [`super::Work`] counts in the same units).
    pub fn done(&self) -> usize {
        self.done.load(Ordering::Relaxed)
    }

    /// Units of work recalled from the memo ([`Control::kept`]) rather than solved: done, at
    /// almost no cost.
    pub fn recalled(&self) -> usize {
        self.recalled.load(Ordering::Relaxed)
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

    /// Whether the job must stop now (cancelled, past its deadline): what a [`Stop`] made
    /// of this control asks inside a long solve.
    pub fn must_stop(&self) -> bool {
        self.check().is_err()
    }

    /// Why a solve failed: the control's own error for one it stopped (a [`Stop`] asking
    /// [`Control::must_stop`]), else the model's.
    pub fn failed(&self, e: ModelError) -> JobError {
        match e {
            ModelError::Stopped => self.check().err().unwrap_or(JobError::Cancelled),
            e => e.into(),
        }
    }

    /// One unit of work: checked first, stopped within by this control (through the
    /// [`Stop`] it is given), counted when it succeeds.
    pub fn solve<R>(
        &self,
        solve: impl FnOnce(Stop) -> Result<R, ModelError>,
    ) -> Result<R, JobError> {
        self.check()?;
        let asked = || self.must_stop();
        let solution = solve(Stop::when(&asked)).map_err(|e| self.failed(e))?;
        self.advance(1);
        Ok(solution)
    }

    /// `solve` for units worth keeping: an item whose `key` is in the control's memo is
    /// recalled rather than solved, and every item solved is kept there at once, so that
    /// what a run solved before its deadline is not lost to its retry. `bytes` is what one
    /// solution holds in memory. Without a memo it is `solve` itself.
    pub fn kept<'a, T, R: Clone + Send + Sync + 'static, E>(
        &'a self,
        key: impl Fn(&T) -> String + Sync + 'a,
        bytes: impl Fn(&R) -> usize + Sync + 'a,
        solve: impl Fn(&T) -> Result<R, E> + Sync + 'a,
    ) -> impl Fn(&T) -> Result<R, E> + Sync + 'a {
        move |item| {
            let Some(memo) = &self.memo else {
                return solve(item);
            };
            let key = key(item);
            if let Some(kept) = memo.recall(&key).and_then(|k| k.downcast::<R>().ok()) {
                self.recalled.fetch_add(1, Ordering::Relaxed);
                return Ok((*kept).clone());
            }
            let solution = solve(item)?;
            let size = bytes(&solution);
            memo.keep(key, Arc::new(solution.clone()), size);
            Ok(solution)
        }
    }

    /// Applies `solve` to every item, in parallel over the control's threads, results in
    /// order; one unit of work per item. Stops at the first failure, cancellation or
    /// deadline.
    pub fn map<T: Sync, R: Send>(
        &self,
        items: &[T],
        solve: impl Fn(&T) -> Result<R, ModelError> + Sync,
    ) -> Result<Vec<R>, JobError> {
        let swept = self.map_each(items, OnRefusal::Fail, solve);
        if let Some(e) = swept.stopped {
            return Err(e);
        }
        swept
            .outcomes
            .into_iter()
            .map(|outcome| match outcome {
                Some(Ok(solution)) => Ok(solution),
                Some(Err(e)) => Err(e.into()),
                None => Err(JobError::Internal(
                    "a solver thread stopped unexpectedly".to_string(),
                )),
            })
            .collect()
    }

    /// Applies `solve` to every item, in parallel over the control's threads, outcomes in
    /// order; one unit of work per item, refused or not. An item `solve` refuses does not
    /// stop the others, unless `on_refusal` says so (the items not reached after it are
    /// then `None`). A cancel or the deadline stops the map (`stopped`): the items it did
    /// not reach are `None`, the others kept, so that a stopped job keeps what it finished.
    pub fn map_each<T: Sync, R: Send, E: Send>(
        &self,
        items: &[T],
        on_refusal: OnRefusal,
        solve: impl Fn(&T) -> Result<R, E> + Sync,
    ) -> Swept<R, E> {
        let next = AtomicUsize::new(0);
        let stop: Mutex<Option<JobError>> = Mutex::new(None);
        let halted = AtomicBool::new(false);
        let halt = |e: JobError| {
            halted.store(true, Ordering::Relaxed);
            stop.lock()
                .unwrap_or_else(|p| p.into_inner())
                .get_or_insert(e);
        };
        let worker = || {
            let mut solved = Vec::new();
            while !halted.load(Ordering::Relaxed) {
                let i = next.fetch_add(1, Ordering::Relaxed);
                let Some(item) = items.get(i) else { break };
                if let Err(e) = self.check() {
                    halt(e);
                    break;
                }
                let outcome = solve(item);
                // An item that failed because the job was stopped inside it (by a [`Stop`]
                // asking this control) was not reached.
                if let (Err(_), Err(e)) = (&outcome, self.check()) {
                    halt(e);
                    break;
                }
                self.advance(1);
                if outcome.is_err() && on_refusal == OnRefusal::Fail {
                    halted.store(true, Ordering::Relaxed);
                }
                solved.push((i, outcome));
            }
            solved
        };
        let threads = self.threads().min(items.len()).max(1);
        let solved: Vec<(usize, Result<R, E>)> = if threads == 1 {
            worker()
        } else {
            thread::scope(|s| {
                let start = |k: usize| {
                    let (worker, lent) = (&worker, self.lent_thread.filter(|_| k > 0));
                    move || {
                        if let Some(start) = lent {
                            start();
                        }
                        worker()
                    }
                };
                let handles: Vec<_> = (0..threads).map(|k| s.spawn(start(k))).collect();
                handles
                    .into_iter()
                    .flat_map(|h| h.join().unwrap_or_default())
                    .collect()
            })
        };
        let mut outcomes: Vec<Option<Result<R, E>>> = items.iter().map(|_| None).collect();
        for (i, outcome) in solved {
            outcomes[i] = Some(outcome);
        }
        let mut stopped = stop.into_inner().unwrap_or_else(|p| p.into_inner());
        let refused = || outcomes.iter().any(|o| matches!(o, Some(Err(_))));
        if stopped.is_none() && outcomes.iter().any(Option::is_none) && !refused() {
            stopped = Some(JobError::Internal(
                "a solver thread stopped unexpectedly".to_string(),
            ));
        }
        Swept { outcomes, stopped }
    }
}
