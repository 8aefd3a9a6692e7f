//! `POST /v1/sweeps`: a sweep over radius, load and speed, solved now; JSON or CSV.

use super::solve_endpoint;
use crate::job::sweep::{SweepInput, SweepJob, SweepOutput};

solve_endpoint!(
    /// Solve a sweep.
    ///
    /// One row per point of the Cartesian product of `vary`'s lists over `base`. With
    /// `Accept: text/csv` the answer is CSV (SI units, one header line). Big sweeps belong in
    /// `POST /v1/jobs`, which reports progress and can be cancelled.
    "/v1/sweeps",
    "solve_sweep",
    SweepJob,
    SweepInput,
    SweepOutput,
    "One row per point"
);
