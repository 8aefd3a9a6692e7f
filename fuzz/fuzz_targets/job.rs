//! Any bytes, as the body of `thirdbody solve -` or `POST /v1/jobs`: parsed, validated and,
//! when valid and small, solved. Nothing may panic; an answer must render (no NaN).

#![no_main]

use libfuzzer_sys::fuzz_target;
use thirdbody::job::{Control, Job, Limits, Work};
use thirdbody::render::Format;

/// Jobs larger than this are validated but not solved: the fuzzer hunts panics, not time.
const MAX_SOLVES: usize = 64;

/// Nor are jobs that cost more than this (points of about 10 µs: a continuum answer on a
/// fine grid takes seconds; its plan and refusal are what is fuzzed).
const MAX_POINTS: u64 = 20_000;

fuzz_target!(|bytes: &[u8]| {
    let limits = Limits {
        max_sweep_points: MAX_SOLVES,
    };
    let Ok(job) = Job::from_json(bytes, &limits) else {
        return;
    };
    let _ = job.canonical();
    let small =
        matches!(job.work(), Work::Known(n) if n <= MAX_SOLVES) && job.cost().points <= MAX_POINTS;
    if !small || job.kind() == "figure" {
        return;
    }
    if let Ok(answer) = job.run(job.meta(), &Control::new(None, 1)) {
        answer.render(Format::Json).expect("an answer renders as JSON");
        answer.render(Format::Csv).expect("an answer renders as CSV");
    }
});
