//! The service's settings: every limit an operator may need to change is a flag with an
//! environment variable, and the whole set is validated at start-up, so that a bad value is
//! a clear error before the first request rather than a panic or a surprise later. What an
//! operator has no reason to change is a named constant beside the flags of its concern,
//! saying why it has its value.
//!
//! The flags by concern: [`serve`] (where it listens, what it keeps and for how long, how it
//! stops, and the connections' constants), [`limits`] (the work and memory one process
//! takes on, and its deadlines), [`access`] (keys, anonymous callers, quotas, browser
//! origins) and [`fleet`] (Redis, and the fleet's constants).

pub mod access;
pub mod fleet;
pub mod limits;
pub mod serve;

use std::net::SocketAddr;
use std::sync::Arc;
use std::time::Duration;

use clap::Parser;

pub use access::{AccessArgs, CorsOrigins};
pub use fleet::FleetArgs;
pub use limits::LimitArgs;
pub use serve::{LogFormat, ProcessArgs};

use super::access::Access;
use super::server::ConnectionLimits;
use crate::engine::fleet::FleetConfig;
use crate::engine::EngineConfig;
use crate::job::Limits;

/// `thirdbody serve`: the flags as typed, by concern.
#[derive(Clone, Debug, Parser)]
pub struct ServeArgs {
    #[command(flatten)]
    pub process: ProcessArgs,
    #[command(flatten)]
    pub limits: LimitArgs,
    #[command(flatten)]
    pub access: AccessArgs,
    #[command(flatten)]
    pub fleet: FleetArgs,
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
    /// The API keys, what anonymous callers may do, and the quotas.
    pub access: Arc<Access>,
    pub log_format: LogFormat,
    /// On shutdown, how long to keep accepting (answering 503) before refusing
    /// connections: [`serve::DRAIN_DELAY`].
    pub drain_delay: Duration,
    pub shutdown_timeout: Duration,
}

/// A setting that cannot work, and why.
#[derive(Debug, PartialEq, thiserror::Error)]
pub enum ConfigError {
    /// A number outside the range its flag allows.
    #[error("{flag} {value}: allowed {least}{zero} to {most}{unit}")]
    OutOfRange {
        flag: &'static str,
        value: u64,
        least: u64,
        most: u64,
        /// What the least value means, where it is 0 and special: ` (no limit)`.
        zero: String,
        /// The unit, after the most: ` bytes (1 TiB)`.
        unit: String,
    },
    /// A duration outside the range its flag allows.
    #[error("{flag} {value}: allowed {least} and at most {most_days}days")]
    DurationOutOfRange {
        flag: &'static str,
        value: String,
        least: &'static str,
        most_days: u64,
    },
    /// Anything else: the flag, the value and why, in a sentence.
    #[error("{0}")]
    Invalid(String),
}

/// Most of any other count (points, jobs): beyond this a number is a typo.
const MAX_COUNT: u64 = 100_000_000;
/// Most of any amount of bytes kept (memory, Redis): 1 TiB, beyond any machine this service
/// runs on; 2⁶⁴ − 1 is a typo (and sums of such amounts would wrap).
const MAX_BYTES: u64 = 1 << 40;
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

    /// `--memory-budget 0: allowed 65536 to 1099511627776 bytes (1 TiB)`.
    fn check(&self) -> Result<(), ConfigError> {
        if (self.least..=self.most).contains(&self.value) {
            return Ok(());
        }
        let spaced = |text: &str, open: &str, close: &str| match text {
            "" => String::new(),
            text => format!(" {open}{text}{close}"),
        };
        Err(ConfigError::OutOfRange {
            flag: self.flag,
            value: self.value,
            least: self.least,
            most: self.most,
            zero: spaced(self.zero, "(", ")"),
            unit: spaced(self.unit, "", ""),
        })
    }
}

/// Checks `bounded`, in order; the first out of range is the error.
fn check_all(bounded: impl IntoIterator<Item = Bounded>) -> Result<(), ConfigError> {
    bounded.into_iter().try_for_each(|b| b.check())
}

/// Checks that each duration `(flag, value)` is more than 0 and at most a year.
fn check_durations<'a>(
    durations: impl IntoIterator<Item = (&'static str, &'a Duration)>,
) -> Result<(), ConfigError> {
    for (flag, value) in durations {
        if value.is_zero() || *value > MAX_DURATION {
            // In days: not humantime's "11months 30days 3h 50m 24s" (30.44-day months).
            return Err(ConfigError::DurationOutOfRange {
                flag,
                value: humantime::format_duration(*value).to_string(),
                least: "more than 0s",
                most_days: MAX_DURATION.as_secs() / (24 * 3600),
            });
        }
    }
    Ok(())
}

/// A duration that cannot be read, with an example of what can.
#[derive(Debug, thiserror::Error)]
#[error("{0} (write e.g. 30s, 500ms, 10m)")]
struct BadDuration(humantime::DurationError);

/// A duration flag's parser: humantime's, with an example of what it reads.
fn duration(text: &str) -> Result<Duration, BadDuration> {
    humantime::parse_duration(text).map_err(BadDuration)
}

impl ServeArgs {
    /// Checks every setting, each concern on its own, then the ones that depend on each
    /// other.
    pub fn validate(self) -> Result<Config, ConfigError> {
        let limits = self.limits.validate()?;
        let process = self.process.validate(self.fleet.redis_url.is_some())?;
        let access = self.access.validate()?;
        let fleet = self.fleet.validate()?;
        let connections = serve::connections(limits.max_connections);
        Ok(Config {
            bind: process.bind,
            fleet,
            connections,
            max_event_streams: serve::event_streams(limits.max_connections),
            engine: EngineConfig {
                pool_size: limits.pool_size,
                solve_deadline: limits.solve_deadline,
                job_deadline: limits.job_deadline,
                max_queued_jobs: limits.max_queued_jobs,
                memory_budget: limits.memory_budget,
                max_jobs: serve::MAX_JOBS,
                cache_ttl: serve::CACHE_TTL,
                job_retention: process.job_retention,
                database: process.database,
                history_retention: process.history_retention,
            },
            limits: Limits {
                max_sweep_points: limits.max_sweep_points,
            },
            body_limit: limits.body_limit,
            request_timeout: limits.request_timeout(),
            cors_origins: access.cors_origins,
            access: Arc::new(access.access),
            log_format: process.log_format,
            drain_delay: serve::DRAIN_DELAY,
            shutdown_timeout: process.shutdown_timeout,
        })
    }
}

#[cfg(test)]
mod tests {
    use axum::http::HeaderValue;

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
                &["--max-queued-jobs", "18446744073709551615"],
                "--max-queued-jobs",
            ),
            (&["--job-deadline", "500000000y"], "--job-deadline"),
            (
                &["--solve-deadline", "0s"],
                "--solve-deadline 0s: allowed more than 0s",
            ),
        ] {
            let error = config(args).unwrap_err();
            assert!(error.contains(needle), "{args:?}: {error}");
        }
    }

    /// Every numeric flag has a range, named with the flag and the value when it is left
    /// (2⁶⁴ − 1 was taken for bytes and quotas, 0 queued jobs for a service refusing every
    /// job); 0 is allowed where it means something (no limit).
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
                ["--quota-points", most],
                "--quota-points 18446744073709551615: allowed 0 (no limit) to 100000000",
            ),
            (
                ["--quota-jobs", most],
                "--quota-jobs 18446744073709551615: allowed 0 (no limit) to 100000000",
            ),
            (
                ["--max-queued-jobs", "0"],
                "--max-queued-jobs 0: allowed 1 to 100000000",
            ),
            (
                ["--max-deliveries", "4294967295"],
                "--max-deliveries 4294967295: allowed 1 to 100",
            ),
            (
                ["--body-limit", most],
                "--body-limit 18446744073709551615: allowed 1024 to 1073741824 bytes (1 GiB)",
            ),
            (
                ["--job-deadline", "2y"],
                "--job-deadline 2years: allowed more than 0s and at most 365days",
            ),
        ] {
            assert_eq!(config(&args).unwrap_err(), expected);
        }
        for args in [
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
