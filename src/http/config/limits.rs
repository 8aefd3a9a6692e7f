//! The work and the memory one process takes on, and its deadlines.

use std::time::Duration;

use super::{check_all, check_durations, duration, Bounded, ConfigError, MAX_BYTES, MAX_COUNT};
use crate::job::Limits;

/// How much longer than `--solve-deadline` a request may take in all: 30 s to read its body
/// and write its answer (a large sweep's CSV to a slow client), so that a slow solve ends
/// with 504 rather than a cut connection.
pub const REQUEST_MARGIN: Duration = Duration::from_secs(30);
/// Most solver threads a pool may have: beyond this a number is a typo, not a machine.
const MAX_POOL_SIZE: u64 = 1024;
/// Smallest body limit that still fits a sweep of a few lists.
const MIN_BODY_LIMIT: u64 = 1024;
/// Largest body limit: a body is held in memory whole, and parsed at ~40 times its size.
const MAX_BODY_LIMIT: u64 = 1 << 30;
/// Most connections: far above any process's limit on open files.
const MAX_CONNECTIONS: u64 = 1 << 20;
/// Least memory budget: 64 KiB, a few answers.
const MIN_MEMORY_BUDGET: u64 = 1 << 16;

/// What one process takes on at once, and for how long.
#[derive(Clone, Debug, clap::Args)]
pub struct LimitArgs {
    /// Largest request body, in bytes.
    #[arg(long, env = "THIRDBODY_BODY_LIMIT", default_value_t = 1 << 20)]
    pub body_limit: usize,

    /// Longest a synchronous solve may take before it is stopped with 504 (e.g. 30s, 500ms);
    /// a request may take 30 s more in all, to read its body and write its answer.
    #[arg(long, env = "THIRDBODY_SOLVE_DEADLINE", default_value = "30s", value_parser = duration)]
    pub solve_deadline: Duration,

    /// Longest an asynchronous job may take from its submission.
    #[arg(long, env = "THIRDBODY_JOB_DEADLINE", default_value = "10m", value_parser = duration)]
    pub job_deadline: Duration,

    /// Jobs solved at once (one solver thread each); default: the number of cores.
    #[arg(long, env = "THIRDBODY_POOL_SIZE")]
    pub pool_size: Option<usize>,

    /// Largest sweep, in points (the product of its lists).
    #[arg(long, env = "THIRDBODY_MAX_SWEEP_POINTS", default_value_t = Limits::default().max_sweep_points)]
    pub max_sweep_points: usize,

    /// Asynchronous jobs that may wait for a solver thread; more are refused with 429 (as is
    /// a job that could not end within --job-deadline behind the work already accepted).
    #[arg(long, env = "THIRDBODY_MAX_QUEUED_JOBS", default_value_t = 64)]
    pub max_queued_jobs: usize,

    /// Memory for everything kept between requests and what solves hold, in bytes: cached
    /// answers (9/16), the working memory of the solves running (3/16), results of finished
    /// jobs (3/16; larger ones are kept in the database), the input memo and the solved
    /// points of sweeps (1/32 each).
    #[arg(long, env = "THIRDBODY_MEMORY_BUDGET", default_value_t = 256 << 20)]
    pub memory_budget: u64,

    /// Connections open at once; more wait in the kernel's backlog (keep it below the
    /// process's limit on open files, with a margin: a connection closed to make room for a
    /// newcomer may take a moment to release its socket). An eighth of them may follow jobs'
    /// event streams.
    #[arg(long, env = "THIRDBODY_MAX_CONNECTIONS", default_value_t = 512)]
    pub max_connections: usize,
}

/// The limits as checked, the pool sized.
pub struct Checked {
    pub body_limit: usize,
    pub solve_deadline: Duration,
    pub job_deadline: Duration,
    pub pool_size: usize,
    pub max_sweep_points: usize,
    pub max_queued_jobs: usize,
    pub memory_budget: u64,
    pub max_connections: usize,
}

impl Checked {
    /// Longest a request may take in all: [`REQUEST_MARGIN`] beyond a solve's deadline.
    pub fn request_timeout(&self) -> Duration {
        self.solve_deadline + REQUEST_MARGIN
    }
}

impl LimitArgs {
    /// Checks every limit's range.
    pub fn validate(self) -> Result<Checked, ConfigError> {
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        let pool_size = self.pool_size.unwrap_or(cores);
        check_all([
            Bounded::count("--pool-size", pool_size, 1, MAX_POOL_SIZE),
            Bounded::count(
                "--body-limit",
                self.body_limit,
                MIN_BODY_LIMIT,
                MAX_BODY_LIMIT,
            )
            .in_unit("bytes (1 GiB)"),
            Bounded::count("--max-sweep-points", self.max_sweep_points, 1, MAX_COUNT),
            // 0 would refuse every job: a job waits in the queue before it runs.
            Bounded::count("--max-queued-jobs", self.max_queued_jobs, 1, MAX_COUNT),
            Bounded::count(
                "--max-connections",
                self.max_connections,
                1,
                MAX_CONNECTIONS,
            ),
            Bounded::count(
                "--memory-budget",
                self.memory_budget,
                MIN_MEMORY_BUDGET,
                MAX_BYTES,
            )
            .in_unit("bytes (1 TiB)"),
        ])?;
        check_durations([
            ("--solve-deadline", &self.solve_deadline),
            ("--job-deadline", &self.job_deadline),
        ])?;
        Ok(Checked {
            body_limit: self.body_limit,
            solve_deadline: self.solve_deadline,
            job_deadline: self.job_deadline,
            pool_size,
            max_sweep_points: self.max_sweep_points,
            max_queued_jobs: self.max_queued_jobs,
            memory_budget: self.memory_budget,
            max_connections: self.max_connections,
        })
    }
}
