//! The HTTP service end to end: real HTTP against servers on port 0 (one per test, each with
//! its own engine, cache and metrics), plus in-process router tests with `oneshot`.

mod access;
mod checks;
#[path = "../shared/clock.rs"]
mod clock;
mod continuum;
mod errors;
mod fits;
mod forms;
mod helpers;
mod in_process;
mod jobs;
#[path = "../shared/json.rs"]
mod json;
mod limits;
mod motion;
mod ops;
mod pictures;
mod prony;
mod results;
mod solve;
mod storage;
