//! How a sweep splits into parts on the fleet's stream, by what its points were measured to
//! cost. Each part pays a few Redis round trips and gains only when another core takes it,
//! so a cheap sweep is one entry (a 10,000-point rolling sweep costs ~60 ms: split in 40
//! parts it took 4× as long), and a heavy one splits into parts of about [`PART_SECONDS`].

use std::ops::Range;
use std::time::Duration;

use crate::job::parts::ranges;

/// A sweep whose points together cost less is solved whole: splitting could save little.
pub const WHOLE_BELOW: Duration = Duration::from_millis(150);
/// The solve time a part aims at: long beside its Redis round trips (~0.1 ms each on a
/// LAN), short enough that the last parts of a sweep end close together.
pub const PART_SECONDS: f64 = 0.025;
/// How long a learned rate is kept without news (a fleet's code and machines change).
pub const RATE_TTL: Duration = Duration::from_secs(24 * 3600);
/// Weight of the latest part (or job) in a class's learned rate.
pub const LEARNING: f64 = 0.5;

/// The parts of a sweep of `points` points at `rate` seconds each. Not measured yet (`None`),
/// parts of `default_points`, or smaller if the job's own estimate (`estimate` seconds a
/// point) says a part of that many would pass [`PART_SECONDS`]: the first continuum sweep
/// is spread over the fleet at once. An empty plan is one entry, the job solved whole.
pub fn plan(
    points: Option<usize>,
    rate: Option<f64>,
    estimate: f64,
    default_points: usize,
) -> Vec<Range<usize>> {
    let Some(points) = points else {
        return Vec::new();
    };
    let per_rate = |rate: f64| ((PART_SECONDS / rate).ceil() as usize).max(1);
    let valid = |rate: &f64| rate.is_finite() && *rate > 0.0;
    let per_part = match rate.filter(valid) {
        None => Some(estimate)
            .filter(valid)
            .map_or(default_points, per_rate)
            .min(default_points)
            .max(1),
        Some(rate) if rate * points as f64 <= WHOLE_BELOW.as_secs_f64() => points,
        Some(rate) => per_rate(rate),
    };
    if points <= per_part {
        Vec::new()
    } else {
        ranges(points, per_part)
    }
}

/// The rate learned from a part or a job of `points` points solved in `took`, given the last.
pub fn learn(before: Option<f64>, took: Duration, points: usize) -> f64 {
    let now = took.as_secs_f64() / points.max(1) as f64;
    match before {
        Some(before) => before + LEARNING * (now - before),
        None => now,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A job that is not a sweep is one entry, and so is a cheap sweep; an unmeasured one
    /// splits into parts of the default size.
    #[test]
    fn only_a_sweep_worth_it_or_unmeasured_splits() {
        assert!(plan(None, Some(1.0), 1e-5, 250).is_empty());
        assert_eq!(
            plan(Some(600), None, 1e-5, 250),
            vec![0..250, 250..500, 500..600]
        );
        assert!(plan(Some(250), None, 1e-5, 250).is_empty());
        // 10,000 rolling points at 6 µs: 60 ms in all.
        assert!(plan(Some(10_000), Some(6e-6), 1e-5, 250).is_empty());
    }

    /// Unmeasured, a sweep whose points its own estimate says are dear is split finer than
    /// the default at once (issue 47: the first 200-point continuum sweep ran as one part
    /// on one replica for 30 s while a worker sat idle); a cheap one keeps the default.
    #[test]
    fn an_unmeasured_dear_sweep_splits_by_its_estimate() {
        // Continuum points estimated at 70 ms: a part each.
        assert_eq!(plan(Some(200), None, 0.07, 100).len(), 200);
        // At 5 ms, parts of 5 points.
        assert!(plan(Some(200), None, 5e-3, 100)
            .iter()
            .all(|r| r.len() == 5));
        assert_eq!(plan(Some(600), None, 1e-5, 250).len(), 3);
        assert_eq!(plan(Some(600), None, f64::NAN, 250).len(), 3);
    }

    #[test]
    fn a_heavy_sweep_splits_into_parts_of_the_target_time() {
        // 400 three-body points at 1 ms: 0.4 s, parts of 25 points (25 ms).
        let parts = plan(Some(400), Some(1e-3), 1e-5, 250);
        assert_eq!(parts.len(), 16);
        assert!(parts.iter().all(|r| r.len() == 25));
        // A point dearer than a part's target is a part of its own.
        assert_eq!(plan(Some(10), Some(0.5), 1e-5, 250).len(), 10);
    }

    #[test]
    fn parts_cover_every_point_once_in_order() {
        for (points, rate) in [(1_001, 1e-4), (7, 0.1), (100_000, 6e-6)] {
            let parts = plan(Some(points), Some(rate), 1e-5, 250);
            let mut next = 0;
            for range in &parts {
                assert_eq!(range.start, next);
                next = range.end;
            }
            assert_eq!(next, if parts.is_empty() { 0 } else { points });
        }
    }

    #[test]
    fn the_rate_follows_the_latest_parts() {
        let first = learn(None, Duration::from_millis(100), 100);
        assert!((first - 1e-3).abs() < 1e-12);
        let second = learn(Some(first), Duration::from_millis(300), 100);
        assert!((second - 2e-3).abs() < 1e-12);
    }
}
