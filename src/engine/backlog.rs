//! Admission of asynchronous jobs by their estimated cost, not only their count: a job is
//! refused when the work accepted before it, shared by the job threads, and its own would
//! not end within its deadline, rather than accepted to wait in the queue and fail there.
//! (A count alone let 64 queued 10,000-point three-body sweeps, ~8 s each, in as readily as
//! 64 single solves.)
//!
//! A job's cost is its units of work (points, or one) times its class's seconds per unit,
//! learned from the jobs of that class that ran here (an exponentially weighted mean). A
//! class not seen yet costs nothing, so a fresh process admits by count alone until its
//! first jobs have run. The estimate of a job stays in the backlog until the job ends.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use super::fleet::placement::learn;
use super::lock;

/// Jobs shorter than this teach nothing: their time is mostly the fixed cost of a job, which
/// spread over few units would overstate the cost of a big job of the class (and short
/// jobs delay no one much).
const TEACHES: Duration = Duration::from_millis(50);

/// Why a job was refused: the work ahead of it and its own, against its deadline.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Backlogged {
    /// The wait for the work accepted before it, shared by the job threads.
    pub ahead: Duration,
    pub needs: Duration,
    pub deadline: Duration,
}

#[derive(Debug, Default)]
struct Accepted {
    /// Estimated solver-seconds of the jobs accepted and not ended.
    seconds: f64,
    /// Learned seconds per unit of work, by class.
    rates: HashMap<&'static str, f64>,
}

#[derive(Debug)]
pub struct Backlog {
    threads: f64,
    deadline: Duration,
    accepted: Mutex<Accepted>,
}

impl Backlog {
    pub fn new(threads: usize, deadline: Duration) -> Arc<Self> {
        Arc::new(Backlog {
            threads: threads.max(1) as f64,
            deadline,
            accepted: Mutex::default(),
        })
    }

    /// Accepts a job of `class` if it can end within its deadline behind the work accepted
    /// already (always, with nothing ahead: its deadline tells); its ticket keeps its
    /// estimate in the backlog until dropped.
    pub fn admit(
        self: &Arc<Self>,
        class: &'static str,
        units: usize,
    ) -> Result<Ticket, Backlogged> {
        let mut accepted = lock(&self.accepted);
        let rate = accepted.rates.get(class).copied().unwrap_or(0.0);
        let needs = rate * units as f64;
        let ahead = accepted.seconds / self.threads;
        if accepted.seconds > 0.0 && ahead + needs > self.deadline.as_secs_f64() {
            return Err(Backlogged {
                ahead: Duration::from_secs_f64(ahead),
                needs: Duration::from_secs_f64(needs),
                deadline: self.deadline,
            });
        }
        accepted.seconds += needs;
        Ok(Ticket {
            backlog: self.clone(),
            class,
            units,
            estimate: needs,
        })
    }
}

#[derive(Debug)]
pub struct Ticket {
    backlog: Arc<Backlog>,
    class: &'static str,
    units: usize,
    estimate: f64,
}

impl Ticket {
    /// Its units of work, as admitted: what a job that ended well did.
    pub fn units(&self) -> usize {
        self.units
    }

    /// The job ran for `took` and did `units` of work: its class's rate learns from it.
    pub fn ran(&self, units: usize, took: Duration) {
        if units == 0 || took < TEACHES {
            return;
        }
        let rates = &mut lock(&self.backlog.accepted).rates;
        let rate = learn(rates.get(self.class).copied(), took, units);
        rates.insert(self.class, rate);
    }
}

impl Drop for Ticket {
    fn drop(&mut self) {
        let mut accepted = lock(&self.backlog.accepted);
        accepted.seconds = (accepted.seconds - self.estimate).max(0.0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_class_not_seen_yet_is_admitted_by_count_alone() {
        let backlog = Backlog::new(1, Duration::from_secs(1));
        let tickets: Vec<_> = (0..100)
            .map(|_| backlog.admit("sweep", 1_000_000).unwrap())
            .collect();
        assert_eq!(tickets.len(), 100);
    }

    #[test]
    fn jobs_that_cannot_end_within_their_deadline_behind_the_backlog_are_refused() {
        let backlog = Backlog::new(2, Duration::from_secs(10));
        backlog
            .admit("sweep", 1000)
            .unwrap()
            .ran(1000, Duration::from_secs(2));
        // 2 ms a unit: a 1,000-unit job needs 2 s; two threads share the work ahead.
        let admitted: Vec<_> = std::iter::from_fn(|| backlog.admit("sweep", 1000).ok())
            .take(20)
            .collect();
        // The k-th job (from 0) waits k × 2 s / 2 threads and needs 2 s: k + 2 ≤ 10.
        assert_eq!(admitted.len(), 9);
        let refused = backlog.admit("sweep", 1000).unwrap_err();
        assert!(
            (refused.ahead.as_secs_f64() - 9.0).abs() < 1e-9,
            "{refused:?}"
        );
        assert!(
            (refused.needs.as_secs_f64() - 2.0).abs() < 1e-9,
            "{refused:?}"
        );
        // Another class is not charged this class's rate; a small job still fits.
        assert!(backlog.admit("rolling", 1_000_000).is_ok());
        assert!(backlog.admit("sweep", 1).is_ok());
        // As jobs end, their estimates leave the backlog.
        drop(admitted);
        assert!(backlog.admit("sweep", 1000).is_ok());
    }

    #[test]
    fn the_rate_follows_the_jobs_that_ran() {
        let backlog = Backlog::new(1, Duration::from_secs(100));
        let ticket = backlog.admit("three_body", 10).unwrap();
        ticket.ran(10, Duration::from_secs(1));
        ticket.ran(10, Duration::from_secs(3));
        ticket.ran(0, Duration::from_secs(50));
        ticket.ran(1, Duration::from_millis(49));
        drop(ticket);
        let next = backlog.admit("three_body", 10).unwrap();
        assert!((next.estimate - 2.0).abs() < 1e-12, "{}", next.estimate);
    }
}
