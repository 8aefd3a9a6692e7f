//! The service's settings: every limit is a flag with an environment variable, and the whole
//! set is validated at start-up, so that a bad value is a clear error before the first
//! request rather than a panic or a surprise later.

use std::fmt;
use std::net::SocketAddr;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;

use axum::http::HeaderValue;
use clap::{Parser, ValueEnum};

use super::access::{Access, Keys, Quota, Quotas, Scopes, Source};
use super::server::{BodyPace, ConnectionLimits};
use crate::engine::fleet::FleetConfig;
use crate::engine::EngineConfig;
use crate::job::Limits;

/// `thirdbody serve`: the flags as typed.
#[derive(Clone, Debug, Parser)]
pub struct ServeArgs {
    /// Address and port to listen on.
    #[arg(long, env = "THIRDBODY_BIND", default_value = "127.0.0.1:8080")]
    pub bind: SocketAddr,

    /// Largest request body, in bytes.
    #[arg(long, env = "THIRDBODY_BODY_LIMIT", default_value_t = 1 << 20)]
    pub body_limit: usize,

    /// Longest a request may take in all (e.g. 60s).
    #[arg(long, env = "THIRDBODY_REQUEST_TIMEOUT", default_value = "60s", value_parser = duration)]
    pub request_timeout: Duration,

    /// Longest a synchronous solve may take before it is stopped with 504 (e.g. 30s, 500ms).
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
    /// jobs (3/16), the input memo and the solved points of sweeps (1/32 each).
    #[arg(long, env = "THIRDBODY_MEMORY_BUDGET", default_value_t = 256 << 20)]
    pub memory_budget: u64,

    /// Records of asynchronous jobs kept at most; the oldest finished are forgotten first.
    #[arg(long, env = "THIRDBODY_MAX_JOBS", default_value_t = 10_000)]
    pub max_jobs: usize,

    /// How long an answer stays cached.
    #[arg(long, env = "THIRDBODY_CACHE_TTL", default_value = "1h", value_parser = duration)]
    pub cache_ttl: Duration,

    /// How long a finished asynchronous job's result stays in memory for its client to
    /// collect; after that it is read from the database (--database).
    #[arg(long, env = "THIRDBODY_JOB_RETENTION", default_value = "15m", value_parser = duration)]
    pub job_retention: Duration,

    /// The database of saved analyses: every job and its result, listed at GET /v1/jobs and
    /// kept across restarts (an SQLite file, made if missing, one process per file;
    /// `:memory:` keeps them only while the process runs). Unused in a fleet, whose
    /// history is in Redis.
    #[arg(long, env = "THIRDBODY_DATABASE", default_value = "thirdbody.db")]
    pub database: String,

    /// How long finished jobs and their results are kept in the history (the database, or
    /// Redis in a fleet), e.g. 30days, 12h.
    #[arg(long, env = "THIRDBODY_HISTORY_RETENTION", default_value = "30days", value_parser = duration)]
    pub history_retention: Duration,

    /// Where the results of finished jobs that do not fit in the memory budget are kept: a
    /// directory of this process's is made there, and removed when it stops. Default: the
    /// system's temporary directory.
    #[arg(long, env = "THIRDBODY_SPILL_DIR")]
    pub spill_dir: Option<PathBuf>,

    /// Bytes of results that may be kept there (0: none; results are then kept in memory
    /// only, and a job whose result does not fit is refused when it is submitted).
    #[arg(long, env = "THIRDBODY_SPILL_BYTES", default_value_t = 1 << 30)]
    pub spill_bytes: u64,

    /// Connections open at once; more wait in the kernel's backlog (keep it below the
    /// process's limit on open files, with a margin: a connection closed to make room for a
    /// newcomer may take a moment to release its socket).
    #[arg(long, env = "THIRDBODY_MAX_CONNECTIONS", default_value_t = 512)]
    pub max_connections: usize,

    /// Longest a client may take to send a request's headers.
    #[arg(long, env = "THIRDBODY_HEADER_TIMEOUT", default_value = "10s", value_parser = duration)]
    pub header_timeout: Duration,

    /// How long an idle keep-alive connection stays open between requests.
    #[arg(long, env = "THIRDBODY_KEEP_ALIVE_TIMEOUT", default_value = "5s", value_parser = duration)]
    pub keep_alive_timeout: Duration,

    /// Longest a write of an answer may wait for the client to read (the time between two
    /// successive writes, not the whole answer); then the connection is closed.
    #[arg(long, env = "THIRDBODY_SEND_TIMEOUT", default_value = "10s", value_parser = duration)]
    pub send_timeout: Duration,

    /// Longest wait for the next piece of a request body; also the grace period before
    /// --body-min-rate applies. A body slower than either is answered 408.
    #[arg(long, env = "THIRDBODY_BODY_TIMEOUT", default_value = "10s", value_parser = duration)]
    pub body_timeout: Duration,

    /// Bytes per second a request body must average once --body-timeout has passed.
    #[arg(long, env = "THIRDBODY_BODY_MIN_RATE", default_value_t = 240)]
    pub body_min_rate: u64,

    /// Event streams (GET /v1/jobs/{id}/events) open at once, a share of --max-connections
    /// (default: an eighth of them); more are refused with 429 (polling GET /v1/jobs/{id}
    /// still works).
    #[arg(long, env = "THIRDBODY_MAX_EVENT_STREAMS")]
    pub max_event_streams: Option<usize>,

    /// Origins allowed to call the API from a browser, comma-separated (`*` for any);
    /// none by default.
    #[arg(
        long = "cors-origin",
        env = "THIRDBODY_CORS_ORIGINS",
        value_delimiter = ','
    )]
    pub cors_origins: Vec<String>,

    /// API keys: a JSON file of hashed keys, each with a name, scopes and an optional
    /// expiry, read again within a second when it changes (or the JSON itself, e.g. in an
    /// environment variable: then changed by a restart). See README, "API keys". Absent:
    /// no key is accepted, and every caller is anonymous.
    #[arg(long, env = "THIRDBODY_API_KEYS")]
    pub api_keys: Option<String>,

    /// What a caller without an API key may do: a comma-separated list of submit, read and
    /// metrics, or `none` (then everything but the dashboard's files and the probes needs a
    /// key).
    #[arg(
        long,
        env = "THIRDBODY_ANONYMOUS",
        default_value = "submit,read,metrics"
    )]
    pub anonymous: String,

    /// Points (about ten microseconds of a solver thread each: a local-law answer is one, a
    /// continuum answer what its grid costs, 7,000 on the default grid) each API key's tenant
    /// may ask to be computed in a minute, fleet-wide; more are refused with 429 until the
    /// minute ends (0: no limit). An answer already cached costs nothing.
    #[arg(long, env = "THIRDBODY_QUOTA_POINTS", default_value_t = 0)]
    pub quota_points: u64,

    /// Unfinished asynchronous jobs each API key's tenant may have at once (0: no limit).
    #[arg(long, env = "THIRDBODY_QUOTA_JOBS", default_value_t = 0)]
    pub quota_jobs: usize,

    /// Bytes each API key's tenant may hold in the answers of its jobs, kept for the
    /// history's retention: a job is refused (429) if its answer's room would pass it, until
    /// a job is deleted or forgotten (0: no limit). A job counts the most its answer may
    /// take.
    #[arg(long, env = "THIRDBODY_QUOTA_RESULT_BYTES", default_value_t = 0)]
    pub quota_result_bytes: u64,

    /// Points per minute for all callers without an API key together: their share, so that
    /// anonymous traffic cannot starve the tenants (0: no limit).
    #[arg(long, env = "THIRDBODY_ANONYMOUS_QUOTA_POINTS", default_value_t = 0)]
    pub anonymous_quota_points: u64,

    /// Unfinished asynchronous jobs all callers without an API key may have at once,
    /// together, in this process (0: no limit beyond --max-queued-jobs). A fleet runs jobs on
    /// its workers: there it does not apply.
    #[arg(long, env = "THIRDBODY_ANONYMOUS_QUOTA_JOBS", default_value_t = 0)]
    pub anonymous_quota_jobs: usize,

    /// Log format.
    #[arg(long, env = "THIRDBODY_LOG_FORMAT", value_enum, default_value_t = LogFormat::Json)]
    pub log_format: LogFormat,

    /// On shutdown, how long to keep accepting (answering 503, /readyz failing) so that a
    /// load balancer sees the instance leave before connections are refused.
    #[arg(long, env = "THIRDBODY_DRAIN_DELAY", default_value = "0s", value_parser = duration)]
    pub drain_delay: Duration,

    /// On shutdown, how long the jobs accepted (queued and running) and the requests in
    /// flight have to finish. A job still running 5 s before the end (half the timeout, if
    /// shorter) is interrupted, and its clients have those last seconds to read that.
    #[arg(long, env = "THIRDBODY_SHUTDOWN_TIMEOUT", default_value = "30s", value_parser = duration)]
    pub shutdown_timeout: Duration,

    #[command(flatten)]
    pub fleet: FleetArgs,
}

/// Several processes on one Redis: absent, the service keeps everything in its own memory.
#[derive(Clone, Debug, clap::Args)]
pub struct FleetArgs {
    /// Redis shared by the fleet's processes (e.g. redis://redis:6379): answers cached
    /// there for every process, jobs recorded there and their work taken from a stream
    /// there. Absent: this process alone, everything in its memory.
    #[arg(long, env = "THIRDBODY_REDIS_URL")]
    pub redis_url: Option<String>,

    /// A second Redis for the jobs (no eviction, persisted), if the one of --redis-url is
    /// only a cache (allkeys-lru); default: the same server.
    #[arg(long, env = "THIRDBODY_REDIS_JOBS_URL", requires = "redis_url")]
    pub redis_jobs_url: Option<String>,

    /// How long a part of a job may go without its process's heartbeat before another
    /// process takes it over.
    #[arg(long, env = "THIRDBODY_CLAIM_IDLE", default_value = "30s", value_parser = duration)]
    pub claim_idle: Duration,

    /// Deliveries of one part of a job before the job fails (each time its process died).
    #[arg(long, env = "THIRDBODY_MAX_DELIVERIES", default_value_t = 3)]
    pub max_deliveries: u32,

    /// Points per part of a sweep on the fleet's stream until the fleet has measured what
    /// a point of its kind costs (then parts are sized by cost: one for a cheap sweep).
    #[arg(long, env = "THIRDBODY_PART_POINTS", default_value_t = 250)]
    pub part_points: usize,

    /// When one Redis holds both the cache and the jobs: the bytes the cached answers may
    /// take there at most (the oldest go first), so that answers never crowd out jobs; and
    /// never more than half of the server's maxmemory (read when connected, and every
    /// minute; the bound chosen is logged).
    #[arg(long, env = "THIRDBODY_REDIS_CACHE_BYTES", default_value_t = 64 << 20)]
    pub redis_cache_bytes: u64,
}

impl FleetArgs {
    /// The fleet's settings, if there is a fleet.
    fn validate(&self) -> Result<Option<FleetConfig>, ConfigError> {
        let Some(cache_url) = self.redis_url.clone() else {
            return Ok(None);
        };
        let jobs_url = self
            .redis_jobs_url
            .clone()
            .unwrap_or_else(|| cache_url.clone());
        for (flag, url) in [("--redis-url", &cache_url), ("--redis-jobs-url", &jobs_url)] {
            if let Err(e) = redis::Client::open(url.as_str()) {
                let url = crate::engine::fleet::link::redacted(url);
                return Err(ConfigError(format!("{flag} {url}: {e}")));
            }
        }
        if self.claim_idle < Duration::from_secs(1) {
            return Err(ConfigError(format!(
                "--claim-idle {}: allowed 1s or more (a heartbeat every 200 ms keeps a \
                 running part)",
                humantime::format_duration(self.claim_idle)
            )));
        }
        Ok(Some(FleetConfig {
            cache_url,
            jobs_url,
            claim_idle: self.claim_idle,
            max_deliveries: self.max_deliveries,
            part_points: self.part_points,
            shared_cache_bytes: self.redis_cache_bytes,
        }))
    }
}

/// How log lines are written.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum LogFormat {
    /// One JSON object per line, with the request id.
    Json,
    /// For people at a terminal.
    Text,
}

/// Which browser origins may call the API.
#[derive(Clone, Debug, PartialEq)]
pub enum CorsOrigins {
    /// No CORS headers: browsers on other origins cannot read answers.
    None,
    Any,
    List(Vec<HeaderValue>),
}

/// The validated settings.
#[derive(Clone, Debug)]
pub struct Config {
    pub bind: SocketAddr,
    /// The fleet on Redis, if any.
    pub fleet: Option<FleetConfig>,
    pub connections: ConnectionLimits,
    /// Event streams open at once.
    pub max_event_streams: usize,
    pub engine: EngineConfig,
    pub limits: Limits,
    pub body_limit: usize,
    pub request_timeout: Duration,
    pub cors_origins: CorsOrigins,
    /// The API keys and what anonymous callers may do.
    pub access: Arc<Access>,
    pub log_format: LogFormat,
    pub drain_delay: Duration,
    pub shutdown_timeout: Duration,
}

/// A setting that cannot work, and why.
#[derive(Debug, PartialEq)]
pub struct ConfigError(String);

impl fmt::Display for ConfigError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for ConfigError {}

/// Most solver threads a pool may have: beyond this a number is a typo, not a machine.
const MAX_POOL_SIZE: u64 = 1024;
/// Smallest body limit that still fits a sweep of a few lists.
const MIN_BODY_LIMIT: u64 = 1024;
/// Largest body limit: a body is held in memory whole, and parsed at ~40 times its size.
const MAX_BODY_LIMIT: u64 = 1 << 30;
/// Most connections: far above any process's limit on open files.
const MAX_CONNECTIONS: u64 = 1 << 20;
/// Most of any other count (points, jobs): beyond this a number is a typo.
const MAX_COUNT: u64 = 100_000_000;
/// Largest minimum body rate: 1 GB/s.
const MAX_BODY_MIN_RATE: u64 = 1_000_000_000;
/// Most of any amount of bytes kept (memory, disk, Redis): 1 TiB, beyond any machine this
/// service runs on; 2⁶⁴ − 1 is a typo (and sums of such amounts would wrap).
const MAX_BYTES: u64 = 1 << 40;
/// Least memory budget, and least share of Redis for answers: 64 KiB, a few answers.
const MIN_BYTES_KEPT: u64 = 1 << 16;
/// Most deliveries of a part of a job: a part whose processes died a hundred times will
/// not finish on the hundred-and-first.
const MAX_DELIVERIES: u64 = 100;
/// Longest of any duration: a year (times are added to clocks, which must not overflow).
const MAX_DURATION: Duration = Duration::from_secs(365 * 24 * 3600);

/// A numeric flag as given, and the values it allows.
struct Bounded {
    flag: &'static str,
    value: u64,
    least: u64,
    most: u64,
    /// What the least value means, where it is 0 and special ("no limit").
    zero: &'static str,
    /// The unit, after the most ("bytes (1 TiB)"), if any.
    unit: &'static str,
}

impl Bounded {
    fn count(flag: &'static str, value: impl TryInto<u64>, least: u64, most: u64) -> Bounded {
        Bounded {
            flag,
            value: value.try_into().unwrap_or(u64::MAX),
            least,
            most,
            zero: "",
            unit: "",
        }
    }

    /// A count whose 0 means `zero` ("no limit").
    fn or_zero(
        flag: &'static str,
        value: impl TryInto<u64>,
        most: u64,
        zero: &'static str,
    ) -> Bounded {
        Bounded {
            zero,
            ..Bounded::count(flag, value, 0, most)
        }
    }

    fn in_unit(self, unit: &'static str) -> Bounded {
        Bounded { unit, ..self }
    }

    /// `--spill-bytes 18446744073709551615: allowed 0 (none) to 1099511627776 bytes (1 TiB)`.
    fn check(&self) -> Result<(), ConfigError> {
        if (self.least..=self.most).contains(&self.value) {
            return Ok(());
        }
        let zero = match self.zero {
            "" => String::new(),
            zero => format!(" ({zero})"),
        };
        let unit = match self.unit {
            "" => String::new(),
            unit => format!(" {unit}"),
        };
        Err(ConfigError(format!(
            "{} {}: allowed {}{zero} to {}{unit}",
            self.flag, self.value, self.least, self.most
        )))
    }
}

fn duration(text: &str) -> Result<Duration, String> {
    humantime::parse_duration(text).map_err(|e| format!("{e} (write e.g. 30s, 500ms, 10m)"))
}

impl ServeArgs {
    /// Checks every setting and the ones that depend on each other.
    pub fn validate(self) -> Result<Config, ConfigError> {
        let fail = |message: String| Err(ConfigError(message));
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        let pool_size = self.pool_size.unwrap_or(cores);
        let max_event_streams = self
            .max_event_streams
            .unwrap_or((self.max_connections / 8).max(1));
        let fleet = &self.fleet;
        let bytes = "bytes (1 TiB)";
        let no_limit = "no limit";
        for bounded in [
            Bounded::count("--pool-size", pool_size, 1, MAX_POOL_SIZE),
            Bounded::count(
                "--body-limit",
                self.body_limit,
                MIN_BODY_LIMIT,
                MAX_BODY_LIMIT,
            )
            .in_unit("bytes (1 GiB)"),
            Bounded::count("--body-min-rate", self.body_min_rate, 0, MAX_BODY_MIN_RATE)
                .in_unit("bytes/s"),
            Bounded::count("--max-sweep-points", self.max_sweep_points, 1, MAX_COUNT),
            // 0 would refuse every job: a job waits in the queue before it runs.
            Bounded::count("--max-queued-jobs", self.max_queued_jobs, 1, MAX_COUNT),
            Bounded::count("--max-jobs", self.max_jobs, 1, MAX_COUNT),
            Bounded::count(
                "--max-connections",
                self.max_connections,
                1,
                MAX_CONNECTIONS,
            ),
            Bounded::count(
                "--max-event-streams",
                max_event_streams,
                1,
                u64::try_from(self.max_connections).unwrap_or(u64::MAX),
            ),
            Bounded::count(
                "--memory-budget",
                self.memory_budget,
                MIN_BYTES_KEPT,
                MAX_BYTES,
            )
            .in_unit(bytes),
            Bounded::or_zero("--spill-bytes", self.spill_bytes, MAX_BYTES, "none").in_unit(bytes),
            Bounded::or_zero("--quota-points", self.quota_points, MAX_COUNT, no_limit),
            Bounded::or_zero("--quota-jobs", self.quota_jobs, MAX_COUNT, no_limit),
            Bounded::or_zero(
                "--quota-result-bytes",
                self.quota_result_bytes,
                MAX_BYTES,
                no_limit,
            )
            .in_unit(bytes),
            Bounded::or_zero(
                "--anonymous-quota-points",
                self.anonymous_quota_points,
                MAX_COUNT,
                no_limit,
            ),
            Bounded::or_zero(
                "--anonymous-quota-jobs",
                self.anonymous_quota_jobs,
                MAX_COUNT,
                no_limit,
            ),
            Bounded::count("--max-deliveries", fleet.max_deliveries, 1, MAX_DELIVERIES),
            Bounded::count("--part-points", fleet.part_points, 1, MAX_COUNT),
            Bounded::count(
                "--redis-cache-bytes",
                fleet.redis_cache_bytes,
                MIN_BYTES_KEPT,
                MAX_BYTES,
            )
            .in_unit(bytes),
        ] {
            bounded.check()?;
        }
        // (flag, value, whether 0 is allowed)
        for (flag, value, zero) in [
            ("--header-timeout", self.header_timeout, false),
            ("--keep-alive-timeout", self.keep_alive_timeout, false),
            ("--send-timeout", self.send_timeout, false),
            ("--body-timeout", self.body_timeout, false),
            ("--request-timeout", self.request_timeout, false),
            ("--solve-deadline", self.solve_deadline, false),
            ("--job-deadline", self.job_deadline, false),
            ("--cache-ttl", self.cache_ttl, false),
            ("--job-retention", self.job_retention, false),
            ("--history-retention", self.history_retention, false),
            ("--shutdown-timeout", self.shutdown_timeout, false),
            ("--drain-delay", self.drain_delay, true),
            ("--claim-idle", self.fleet.claim_idle, false),
        ] {
            if (value.is_zero() && !zero) || value > MAX_DURATION {
                let least = if zero { "0s" } else { "more than 0s" };
                // In days: not humantime's "11months 30days 3h 50m 24s" (30.44-day months).
                let days = MAX_DURATION.as_secs() / (24 * 3600);
                return fail(format!(
                    "{flag} {}: allowed {least} and at most {days}days",
                    humantime::format_duration(value),
                ));
            }
        }
        // (A fleet keeps no job in a process's memory: its history is its only retention.)
        if self.fleet.redis_url.is_none() && self.history_retention < self.job_retention {
            return fail(format!(
                "--history-retention {} must be at least --job-retention {}: a finished job \
                 is kept in memory for the one and in the history for the other",
                humantime::format_duration(self.history_retention),
                humantime::format_duration(self.job_retention)
            ));
        }
        if self.solve_deadline >= self.request_timeout {
            return fail(format!(
                "--solve-deadline {} must be shorter than --request-timeout {}, so that a \
                 slow solve ends with 504 rather than a cut connection",
                humantime::format_duration(self.solve_deadline),
                humantime::format_duration(self.request_timeout)
            ));
        }
        let spill = match self.spill_bytes {
            0 => None,
            bytes => {
                let dir = self.spill_dir.unwrap_or_else(std::env::temp_dir);
                if !dir.is_dir() {
                    return fail(format!(
                        "--spill-dir {}: not a directory (results beyond the memory budget are \
                         kept there; --spill-bytes 0 keeps them in memory only)",
                        dir.display()
                    ));
                }
                Some((dir, bytes))
            }
        };
        let mut access = access(self.api_keys.as_deref(), &self.anonymous)?;
        access.quotas = Quotas {
            keyed: Quota {
                points_per_minute: self.quota_points,
                jobs: self.quota_jobs,
                result_bytes: self.quota_result_bytes,
            },
            anonymous: Quota {
                points_per_minute: self.anonymous_quota_points,
                jobs: self.anonymous_quota_jobs,
                ..Quota::default()
            },
        };
        Ok(Config {
            bind: self.bind,
            fleet: self.fleet.validate()?,
            connections: ConnectionLimits {
                max_connections: self.max_connections,
                header_timeout: self.header_timeout,
                keep_alive_timeout: self.keep_alive_timeout,
                send_timeout: self.send_timeout,
                body: BodyPace {
                    timeout: self.body_timeout,
                    min_rate: self.body_min_rate,
                },
            },
            max_event_streams,
            engine: EngineConfig {
                pool_size,
                solve_deadline: self.solve_deadline,
                job_deadline: self.job_deadline,
                max_queued_jobs: self.max_queued_jobs,
                memory_budget: self.memory_budget,
                max_jobs: self.max_jobs,
                cache_ttl: self.cache_ttl,
                job_retention: self.job_retention,
                database: self.database,
                history_retention: self.history_retention,
                spill,
            },
            limits: Limits {
                max_sweep_points: self.max_sweep_points,
            },
            body_limit: self.body_limit,
            request_timeout: self.request_timeout,
            cors_origins: cors_origins(&self.cors_origins)?,
            access: Arc::new(access),
            log_format: self.log_format,
            drain_delay: self.drain_delay,
            shutdown_timeout: self.shutdown_timeout,
        })
    }
}

/// The keys of `--api-keys` (read now: a file that cannot be used fails the start) and
/// the scopes of `--anonymous`.
fn access(api_keys: Option<&str>, anonymous: &str) -> Result<Access, ConfigError> {
    let anonymous =
        Scopes::parse(anonymous).map_err(|e| ConfigError(format!("--anonymous: {e}")))?;
    if anonymous.is_admin() {
        return Err(ConfigError(
            "--anonymous admin: an admin needs a key (allowed submit, read, metrics, or none)"
                .to_string(),
        ));
    }
    if anonymous == Scopes::NONE && api_keys.is_none() {
        return Err(ConfigError(
            "--anonymous none without --api-keys: nobody could use the service".to_string(),
        ));
    }
    let keys = Keys::load(api_keys.map(Source::of)).map_err(ConfigError)?;
    Ok(Access::new(keys, anonymous))
}

/// Origins are `scheme://host[:port]` exactly as browsers send them, or `*` alone.
fn cors_origins(origins: &[String]) -> Result<CorsOrigins, ConfigError> {
    let origins: Vec<&str> = origins
        .iter()
        .map(|o| o.trim())
        .filter(|o| !o.is_empty())
        .collect();
    match origins.as_slice() {
        [] => return Ok(CorsOrigins::None),
        ["*"] => return Ok(CorsOrigins::Any),
        _ => {}
    }
    origins
        .iter()
        .map(|&origin| {
            let valid = origin.split_once("://").is_some_and(|(scheme, host)| {
                matches!(scheme, "http" | "https") && !host.is_empty() && !host.contains('/')
            });
            match HeaderValue::from_str(origin) {
                Ok(value) if valid => Ok(value),
                _ => Err(ConfigError(format!(
                    "--cors-origin {origin:?}: expected an origin such as \
                     https://dashboard.example.org or http://localhost:3000 (no path), or * alone"
                ))),
            }
        })
        .collect::<Result<_, _>>()
        .map(CorsOrigins::List)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn config(args: &[&str]) -> Result<Config, String> {
        let args = std::iter::once("serve").chain(args.iter().copied());
        ServeArgs::try_parse_from(args)
            .map_err(|e| e.to_string())?
            .validate()
            .map_err(|e| e.to_string())
    }

    #[test]
    fn no_flags_is_a_working_service_on_localhost_8080() {
        let config = config(&[]).unwrap();
        assert_eq!(config.bind.to_string(), "127.0.0.1:8080");
        assert!(config.engine.pool_size >= 1);
        assert_eq!(config.limits, Limits::default());
        assert_eq!(config.cors_origins, CorsOrigins::None);
    }

    #[test]
    fn bad_settings_are_named_at_start_up() {
        for (args, needle) in [
            (&["--bind", "localhost"][..], "--bind"),
            (&["--pool-size", "0"], "--pool-size 0"),
            (&["--body-limit", "10"], "--body-limit 10"),
            (&["--solve-deadline", "soon"], "30s, 500ms"),
            (&["--cache-ttl", "0s"], "--cache-ttl 0s"),
            (
                &["--solve-deadline", "2m"],
                "shorter than --request-timeout",
            ),
            (&["--cors-origin", "dashboard.example"], "dashboard.example"),
            (&["--cors-origin", "https://a.example/path"], "no path"),
            (&["--log-format", "xml"], "xml"),
            (
                &["--anonymous", "read,write"],
                "--anonymous: unknown scope \"write\"",
            ),
            (&["--anonymous", "admin"], "an admin needs a key"),
            (&["--anonymous", "none"], "nobody could use the service"),
            (
                &["--api-keys", "/nonexistent/keys.json"],
                "--api-keys /nonexistent/keys.json",
            ),
            (&["--api-keys", "{\"keys\": 3}"], "--api-keys: invalid type"),
            (
                &["--max-connections", "18446744073709551615"],
                "--max-connections 18446744073709551615: allowed 1 to 1048576",
            ),
            (
                &["--max-connections", "0"],
                "--max-connections 0: allowed 1 to",
            ),
            (
                &["--max-event-streams", "600"],
                "--max-event-streams 600: allowed 1 to 512",
            ),
            (
                &["--max-queued-jobs", "18446744073709551615"],
                "--max-queued-jobs",
            ),
            (&["--max-jobs", "0"], "--max-jobs 0"),
            (&["--job-deadline", "500000000y"], "--job-deadline"),
            (
                &["--send-timeout", "0s"],
                "--send-timeout 0s: allowed more than 0s",
            ),
            (&["--drain-delay", "2y"], "--drain-delay"),
            (
                &["--body-min-rate", "2000000000"],
                "--body-min-rate 2000000000: allowed 0 to",
            ),
        ] {
            let error = config(args).unwrap_err();
            assert!(error.contains(needle), "{args:?}: {error}");
        }
    }

    /// Every numeric flag has a range, named with the flag and the value when it is left
    /// (2⁶⁴ − 1 was taken for bytes and quotas, 0 queued jobs for a service refusing every
    /// job); 0 is allowed where it means something (none, no limit).
    #[test]
    fn every_numeric_flag_is_bounded() {
        let most = "18446744073709551615";
        for (args, expected) in [
            (
                ["--memory-budget", most],
                "--memory-budget 18446744073709551615: allowed 65536 to 1099511627776 bytes (1 TiB)",
            ),
            (
                ["--memory-budget", "0"],
                "--memory-budget 0: allowed 65536 to 1099511627776 bytes (1 TiB)",
            ),
            (
                ["--spill-bytes", most],
                "--spill-bytes 18446744073709551615: allowed 0 (none) to 1099511627776 bytes (1 TiB)",
            ),
            (
                ["--quota-points", most],
                "--quota-points 18446744073709551615: allowed 0 (no limit) to 100000000",
            ),
            (
                ["--quota-jobs", most],
                "--quota-jobs 18446744073709551615: allowed 0 (no limit) to 100000000",
            ),
            (
                ["--quota-result-bytes", most],
                "--quota-result-bytes 18446744073709551615: allowed 0 (no limit) to 1099511627776 bytes (1 TiB)",
            ),
            (
                ["--anonymous-quota-points", most],
                "--anonymous-quota-points 18446744073709551615: allowed 0 (no limit) to 100000000",
            ),
            (
                ["--anonymous-quota-jobs", most],
                "--anonymous-quota-jobs 18446744073709551615: allowed 0 (no limit) to 100000000",
            ),
            (
                ["--max-queued-jobs", "0"],
                "--max-queued-jobs 0: allowed 1 to 100000000",
            ),
            (
                ["--max-deliveries", "4294967295"],
                "--max-deliveries 4294967295: allowed 1 to 100",
            ),
            (["--part-points", "0"], "--part-points 0: allowed 1 to 100000000"),
            (
                ["--body-limit", most],
                "--body-limit 18446744073709551615: allowed 1024 to 1073741824 bytes (1 GiB)",
            ),
            (
                ["--claim-idle", "2y"],
                "--claim-idle 2years: allowed more than 0s and at most 365days",
            ),
        ] {
            assert_eq!(config(&args).unwrap_err(), expected);
        }
        for args in [
            ["--spill-bytes", "0"],
            ["--quota-points", "0"],
            ["--memory-budget", "65536"],
            ["--memory-budget", "1099511627776"],
            ["--max-queued-jobs", "1"],
        ] {
            assert!(config(&args).is_ok(), "{args:?}");
        }
    }

    #[test]
    fn cors_origins_are_a_list_or_any() {
        let list = config(&["--cors-origin", "https://a.example,http://localhost:3000"]).unwrap();
        assert_eq!(
            list.cors_origins,
            CorsOrigins::List(vec![
                HeaderValue::from_static("https://a.example"),
                HeaderValue::from_static("http://localhost:3000")
            ])
        );
        let any = config(&["--cors-origin", "*"]).unwrap();
        assert_eq!(any.cors_origins, CorsOrigins::Any);
    }
}
