//! Where the service listens, what one process keeps and for how long, and how it stops;
//! and the constants of its connections, which no operator has needed to change.

use std::net::SocketAddr;
use std::time::Duration;

use clap::ValueEnum;

use super::{check_durations, duration, ConfigError};
use crate::http::server::{BodyPace, ConnectionLimits};

/// Longest a client may take to send a request's headers: a person's client sends them in
/// one packet, and 10 s is far beyond a slow network's round trip, yet short enough that a
/// connection held open without a request (slowloris) frees its place soon.
pub const HEADER_TIMEOUT: Duration = Duration::from_secs(10);
/// How long an idle keep-alive connection stays open between requests: a client polling a
/// job asks every second or so and keeps its connection; one gone quiet gives its place back
/// after 5 s (the common default of proxies, which keep theirs open longer than this).
pub const KEEP_ALIVE_TIMEOUT: Duration = Duration::from_secs(5);
/// Longest a write of an answer may wait for the client to read (the time between two
/// successive writes, not the whole answer): a client that reads nothing for 10 s is gone or
/// hostile, and its connection's place and buffers are worth more to others.
pub const SEND_TIMEOUT: Duration = Duration::from_secs(10);
/// Longest wait for the next piece of a request body, and the grace period before
/// [`BODY_MIN_RATE`] applies: the same 10 s as the headers'. A slower body is answered 408.
pub const BODY_TIMEOUT: Duration = Duration::from_secs(10);
/// Bytes per second a request body must average once [`BODY_TIMEOUT`] has passed: 240 B/s
/// (a 1 MiB body, the default limit, in about an hour and a quarter) refuses only a body
/// trickled on purpose, never a slow but honest link.
pub const BODY_MIN_RATE: u64 = 240;
/// Event streams (GET /v1/jobs/{id}/events) may take one place in this many of
/// `--max-connections`: followers of jobs cannot crowd out submissions and polls (more are
/// refused with 429; polling GET /v1/jobs/{id} still works).
pub const EVENT_STREAM_SHARE: usize = 8;
/// On shutdown, how long to keep accepting (answering 503, /readyz failing) before
/// connections are refused: none. Where a load balancer must see the instance leave first,
/// the orchestrator waits before sending SIGTERM (deploy/base/deployment.yaml's preStop).
pub const DRAIN_DELAY: Duration = Duration::ZERO;
/// How long an answer stays cached: an answer is a pure function of its input and the
/// model's version (both in its key), so it never goes stale; the memory budget evicts the
/// least used first, and an hour only returns the memory of answers nobody asks again.
pub const CACHE_TTL: Duration = Duration::from_secs(3600);
/// Records of asynchronous jobs one process keeps in memory at most (the oldest finished
/// are forgotten first, and read from the database then): 10,000 records take a few MB, and
/// their results are bounded by the memory budget already.
pub const MAX_JOBS: usize = 10_000;

/// Where the service listens, what it keeps, how it logs and stops.
#[derive(Clone, Debug, clap::Args)]
pub struct ProcessArgs {
    /// Address and port to listen on.
    #[arg(long, env = "THIRDBODY_BIND", default_value = "127.0.0.1:8080")]
    pub bind: SocketAddr,

    /// How long a finished asynchronous job's result stays in memory for its client to
    /// collect; after that it is read from the database (--database).
    #[arg(long, env = "THIRDBODY_JOB_RETENTION", default_value = "15m", value_parser = duration)]
    pub job_retention: Duration,

    /// The database of saved analyses: every job and its result, listed at GET /v1/jobs and
    /// kept across restarts, and the results of finished jobs beyond the memory budget (an
    /// SQLite file, made if missing, one process per file; `:memory:` keeps them only while
    /// the process runs, and keeps no result beyond the memory budget). Unused in a fleet,
    /// whose history is in Redis.
    #[arg(long, env = "THIRDBODY_DATABASE", default_value = "thirdbody.db")]
    pub database: String,

    /// How long finished jobs and their results are kept in the history (the database, or
    /// Redis in a fleet), e.g. 30days, 12h.
    #[arg(long, env = "THIRDBODY_HISTORY_RETENTION", default_value = "30days", value_parser = duration)]
    pub history_retention: Duration,

    /// Log format.
    #[arg(long, env = "THIRDBODY_LOG_FORMAT", value_enum, default_value_t = LogFormat::Json)]
    pub log_format: LogFormat,

    /// On shutdown, how long the jobs accepted (queued and running) and the requests in
    /// flight have to finish. A job still running 5 s before the end (half the timeout, if
    /// shorter) is interrupted, and its clients have those last seconds to read that.
    #[arg(long, env = "THIRDBODY_SHUTDOWN_TIMEOUT", default_value = "30s", value_parser = duration)]
    pub shutdown_timeout: Duration,
}

/// How log lines are written.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum LogFormat {
    /// One JSON object per line, with the request id.
    Json,
    /// For people at a terminal.
    Text,
}

impl ProcessArgs {
    /// Checks the durations, and that a job's history outlasts its time in memory (a fleet
    /// keeps no job in a process's memory: its history is its only retention).
    pub fn validate(self, in_fleet: bool) -> Result<ProcessArgs, ConfigError> {
        check_durations([
            ("--job-retention", &self.job_retention),
            ("--history-retention", &self.history_retention),
            ("--shutdown-timeout", &self.shutdown_timeout),
        ])?;
        if !in_fleet && self.history_retention < self.job_retention {
            return Err(ConfigError::Invalid(format!(
                "--history-retention {} must be at least --job-retention {}: a finished job \
                 is kept in memory for the one and in the history for the other",
                humantime::format_duration(self.history_retention),
                humantime::format_duration(self.job_retention)
            )));
        }
        Ok(self)
    }
}

/// The bounds of each connection, `max_connections` of them at once.
pub fn connections(max_connections: usize) -> ConnectionLimits {
    ConnectionLimits {
        max_connections,
        header_timeout: HEADER_TIMEOUT,
        keep_alive_timeout: KEEP_ALIVE_TIMEOUT,
        send_timeout: SEND_TIMEOUT,
        body: BodyPace {
            timeout: BODY_TIMEOUT,
            min_rate: BODY_MIN_RATE,
        },
    }
}

/// Event streams open at once, of `max_connections`.
pub fn event_streams(max_connections: usize) -> usize {
    (max_connections / EVENT_STREAM_SHARE).max(1)
}
