//! The instruments of the compute path, recorded on a recorder owned by whoever runs the
//! engine rather than on the process-global one of the `metrics` crate: each HTTP service
//! (and each test server in one test process) then counts only its own solves.

use std::sync::{Arc, Mutex};
use std::time::Duration;

use metrics::{Counter, Gauge, Histogram, Key, Label, Metadata, NoopRecorder, Recorder};

/// Seconds spent solving a job, by kind and outcome (its `_count` is the number of solves).
pub const SOLVE_DURATION: &str = "thirdbody_solve_duration_seconds";
/// Results found in the cache (coalesced waiters included).
pub const CACHE_HITS: &str = "thirdbody_cache_hits_total";
/// Results that had to be solved.
pub const CACHE_MISSES: &str = "thirdbody_cache_misses_total";
/// Asynchronous jobs waiting for a permit.
pub const JOBS_QUEUED: &str = "thirdbody_jobs_queued";
/// Asynchronous jobs being solved.
pub const JOBS_RUNNING: &str = "thirdbody_jobs_running";
/// Work refused, by reason (`overloaded`, `draining`, `unavailable`).
pub const REJECTIONS: &str = "thirdbody_rejections_total";
/// Whether each Redis role (`cache`, `jobs`) was reachable at the last call (1 or 0).
pub const REDIS_UP: &str = "thirdbody_redis_up";
/// Entries of the fleet's work stream solved, by outcome.
pub const PARTS: &str = "thirdbody_parts_total";
/// Entries delivered again (their worker went silent).
pub const REDELIVERIES: &str = "thirdbody_redeliveries_total";

static METADATA: Metadata<'static> =
    Metadata::new(module_path!(), metrics::Level::INFO, Some(module_path!()));

#[derive(Clone)]
pub struct Metrics {
    recorder: Arc<dyn Recorder + Send + Sync>,
}

impl Metrics {
    /// Records on `recorder`, and describes the engine's metrics there.
    pub fn new(recorder: Arc<dyn Recorder + Send + Sync>) -> Self {
        let metrics = Metrics { recorder };
        metrics.describe_seconds(SOLVE_DURATION, "Time spent solving jobs");
        metrics.describe_counter(CACHE_HITS, "Results served from the cache");
        metrics.describe_counter(CACHE_MISSES, "Results that were solved");
        let r = &metrics.recorder;
        r.describe_gauge(JOBS_QUEUED.into(), None, "Async jobs waiting".into());
        r.describe_gauge(JOBS_RUNNING.into(), None, "Async jobs being solved".into());
        metrics.describe_counter(REJECTIONS, "Work refused, by reason");
        metrics
    }

    /// Records nothing (the command line's engine).
    pub fn noop() -> Self {
        Metrics {
            recorder: Arc::new(NoopRecorder),
        }
    }

    pub fn describe_counter(&self, name: &'static str, help: &'static str) {
        self.recorder
            .describe_counter(name.into(), None, help.into());
    }

    /// Describes a histogram of durations.
    pub fn describe_seconds(&self, name: &'static str, help: &'static str) {
        let unit = Some(metrics::Unit::Seconds);
        self.recorder
            .describe_histogram(name.into(), unit, help.into());
    }

    pub fn counter(&self, name: &'static str, labels: &[(&'static str, &str)]) -> Counter {
        self.recorder
            .register_counter(&key(name, labels), &METADATA)
    }

    pub fn gauge(&self, name: &'static str, labels: &[(&'static str, &str)]) -> Gauge {
        self.recorder.register_gauge(&key(name, labels), &METADATA)
    }

    pub fn histogram(&self, name: &'static str, labels: &[(&'static str, &str)]) -> Histogram {
        self.recorder
            .register_histogram(&key(name, labels), &METADATA)
    }
}

/// [`SOLVE_DURATION`] by kind and outcome, each series looked up on the recorder once: a
/// look-up hashes and copies its labels, about a microsecond on every solve otherwise.
pub struct SolveDurations {
    metrics: Metrics,
    /// (kind, outcome) → its series; a few dozen at most, so a list.
    seen: Mutex<Vec<(&'static str, &'static str, Histogram)>>,
}

impl SolveDurations {
    pub fn new(metrics: Metrics) -> Self {
        SolveDurations {
            metrics,
            seen: Mutex::default(),
        }
    }

    pub fn record(&self, kind: &'static str, outcome: &'static str, elapsed: Duration) {
        let mut seen = super::lock(&self.seen);
        let found = seen.iter().find(|(k, o, _)| *k == kind && *o == outcome);
        let histogram = match found {
            Some((.., histogram)) => histogram.clone(),
            None => {
                let labels = [("kind", kind), ("outcome", outcome)];
                let histogram = self.metrics.histogram(SOLVE_DURATION, &labels);
                seen.push((kind, outcome, histogram.clone()));
                histogram
            }
        };
        drop(seen);
        histogram.record(elapsed);
    }
}

fn key(name: &'static str, labels: &[(&'static str, &str)]) -> Key {
    let labels: Vec<Label> = labels
        .iter()
        .map(|&(k, v)| Label::new(k, v.to_string()))
        .collect();
    Key::from_parts(name, labels)
}
