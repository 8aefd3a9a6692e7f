//! One Redis server in one role (the answer cache, or the jobs): a connection manager that
//! reconnects by itself, a bound on every call, and the server's health as the last calls
//! and pings found it (down, full, slow), so that callers skip it at once while it is of no
//! use (synchronous solves then answer from this process alone) and `/readyz` can say why.

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

use metrics::Gauge;
use redis::aio::{ConnectionManager, ConnectionManagerConfig};
use redis::{Cmd, FromRedisValue, Pipeline, RedisError};

/// A call that takes longer is a failure: Redis answers in well under a millisecond.
const CALL_TIMEOUT: Duration = Duration::from_secs(1);
/// How often an unreachable server is tried again.
pub const RETRY_EVERY: Duration = Duration::from_millis(500);
/// A server whose ping takes longer is slow: a synchronous solve would wait more than it gains.
const SLOW: Duration = Duration::from_millis(25);
/// How long a refusal for want of memory marks the server full, unless a write probe says not.
const FULL_FOR: Duration = Duration::from_secs(10);

#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Health {
    Up,
    /// Reachable, but its round trips take longer than [`SLOW`].
    Slow(Duration),
    /// Reachable, but refusing writes at its memory limit.
    Full,
    Down,
    /// Reachable, and refusing this process's credentials (AUTH).
    Denied,
}

impl Health {
    pub fn as_str(&self) -> &'static str {
        match self {
            Health::Up => "up",
            Health::Slow(_) => "slow",
            Health::Full => "full",
            Health::Down => "down",
            Health::Denied => "denied",
        }
    }

    pub fn reason(&self, role: &str) -> Option<String> {
        match self {
            Health::Up => None,
            Health::Slow(rtt) => Some(format!(
                "Redis ({role}) answers slowly ({} ms a round trip): synchronous solves \
                 answer from this process alone",
                rtt.as_millis()
            )),
            Health::Full => Some(format!(
                "Redis ({role}) is full: it refuses writes at its memory limit (maxmemory)"
            )),
            Health::Down => Some(format!("Redis ({role}) cannot be reached")),
            Health::Denied => Some(format!(
                "Redis ({role}) refuses this process's credentials (AUTH): check the password \
                 in its URL (--redis-url, --redis-jobs-url)"
            )),
        }
    }
}

/// Why a call to Redis failed, in a sentence, and the server's error code (`NOGROUP`...).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{why}")]
pub struct Failure {
    pub why: String,
    code: Option<String>,
}

impl Failure {
    pub fn new(why: impl Into<String>) -> Self {
        Failure {
            why: why.into(),
            code: None,
        }
    }

    pub fn is(&self, code: &str) -> bool {
        self.code.as_deref() == Some(code)
    }
}

pub struct Link {
    /// `cache` or `jobs`, for messages and metrics.
    pub role: &'static str,
    url: String,
    connection: ConnectionManager,
    up: AtomicBool,
    /// Whether the last failure was a refusal of the credentials.
    denied: AtomicBool,
    /// The last ping's round trip, in µs.
    round_trip: AtomicU64,
    /// When a write was last refused for want of memory (ms since `opened`; 0: never).
    full_at: AtomicU64,
    opened: Instant,
    gauge: OnceLock<Gauge>,
}

impl Link {
    /// Connects at the first call (the server may start later).
    pub fn open(role: &'static str, url: &str) -> Result<Link, LinkError> {
        let failed = |source| LinkError {
            role,
            url: redacted(url),
            source,
        };
        let client = redis::Client::open(url).map_err(failed)?;
        let config = ConnectionManagerConfig::new()
            .set_connection_timeout(Some(CALL_TIMEOUT))
            .set_response_timeout(Some(CALL_TIMEOUT))
            .set_number_of_retries(1)
            .set_max_delay(Duration::from_millis(200));
        let connection = ConnectionManager::new_lazy_with_config(client, config).map_err(failed)?;
        Ok(Link {
            role,
            url: url.to_string(),
            connection,
            up: AtomicBool::new(true),
            denied: AtomicBool::new(false),
            round_trip: AtomicU64::new(0),
            full_at: AtomicU64::new(0),
            opened: Instant::now(),
            gauge: OnceLock::new(),
        })
    }

    /// A link of its own to the same server, for a caller that blocks on it (a worker
    /// waiting for work): on the shared link a blocked call would hold up every other.
    pub fn dedicated(&self) -> Result<Link, LinkError> {
        Link::open(self.role, &self.url)
    }

    /// Reports the link's state in `gauge` (1 reachable, 0 not) from now on.
    pub fn report_to(&self, gauge: Gauge) {
        gauge.set(f64::from(u8::from(self.is_up())));
        let _ = self.gauge.set(gauge);
    }

    pub fn is_up(&self) -> bool {
        self.up.load(Ordering::Relaxed)
    }

    pub fn health(&self) -> Health {
        let full_at = self.full_at.load(Ordering::Relaxed);
        let round_trip = Duration::from_micros(self.round_trip.load(Ordering::Relaxed));
        if !self.is_up() && self.denied.load(Ordering::Relaxed) {
            Health::Denied
        } else if !self.is_up() {
            Health::Down
        } else if full_at > 0 && self.since_opened() < full_at + FULL_FOR.as_millis() as u64 {
            Health::Full
        } else if round_trip > SLOW {
            Health::Slow(round_trip)
        } else {
            Health::Up
        }
    }

    /// Whether a synchronous solve should use the server: reachable and quick.
    pub fn is_quick(&self) -> bool {
        matches!(self.health(), Health::Up | Health::Full)
    }

    fn since_opened(&self) -> u64 {
        u64::try_from(self.opened.elapsed().as_millis()).unwrap_or(u64::MAX)
    }

    /// Records whether the server was reached; `why` not (logged when it changes).
    fn set_up(&self, up: bool, why: &str) {
        if self.up.swap(up, Ordering::Relaxed) != up {
            if up {
                tracing::info!(role = self.role, "Redis reachable again");
            } else {
                tracing::warn!(role = self.role, error = why, "Redis unreachable");
            }
        }
        if let Some(gauge) = self.gauge.get() {
            gauge.set(f64::from(u8::from(up)));
        }
    }

    /// Runs `call`, and records what its outcome says of the server; a call cut by a lost
    /// connection is tried once more (so that the first call after a restart succeeds).
    async fn call<T, F, Fut>(&self, call: F) -> Result<T, Failure>
    where
        F: Fn(ConnectionManager) -> Fut,
        Fut: std::future::Future<Output = Result<T, RedisError>>,
    {
        let mut result = tokio::time::timeout(CALL_TIMEOUT, call(self.connection.clone())).await;
        if let Ok(Err(e)) = &result {
            if e.is_connection_dropped() || e.is_io_error() {
                result = tokio::time::timeout(CALL_TIMEOUT, call(self.connection.clone())).await;
            }
        }
        match result {
            Ok(Ok(value)) => {
                self.denied.store(false, Ordering::Relaxed);
                self.set_up(true, "");
                Ok(value)
            }
            Ok(Err(e)) => {
                let lost = e.is_io_error()
                    || e.is_timeout()
                    || e.is_connection_dropped()
                    || e.is_connection_refusal()
                    || e.is_unrecoverable_error();
                let denied = e.kind() == redis::ErrorKind::AuthenticationFailed
                    || matches!(e.code(), Some("NOAUTH" | "WRONGPASS"));
                self.denied.store(denied, Ordering::Relaxed);
                if lost || denied {
                    self.set_up(false, &e.to_string());
                }
                let code = e.code().map(str::to_string);
                let role = self.role;
                // Refused for want of memory, alone or inside a transaction.
                let full = code.as_deref() == Some("OOM") || e.to_string().contains("OOM");
                let why = if full {
                    let now = self.since_opened().max(1);
                    let before = self.full_at.swap(now, Ordering::Relaxed);
                    if before == 0 || now > before + FULL_FOR.as_millis() as u64 {
                        tracing::error!(
                            role,
                            "Redis is full: it refuses writes at its memory limit (maxmemory)"
                        );
                    }
                    Health::Full.reason(role).unwrap_or_default()
                } else if denied {
                    Health::Denied.reason(role).unwrap_or_default()
                } else if lost {
                    format!("Redis ({role}) cannot be reached: {e}")
                } else {
                    format!("Redis ({role}) refused a command: {e}")
                };
                Err(Failure { why, code })
            }
            Err(_) => {
                let why = format!(
                    "Redis ({}) cannot be reached: no answer within {CALL_TIMEOUT:?}",
                    self.role
                );
                self.set_up(false, &why);
                Err(Failure::new(why))
            }
        }
    }

    pub async fn query<T: FromRedisValue>(&self, cmd: &Cmd) -> Result<T, Failure> {
        self.call(|mut c| async move { cmd.query_async(&mut c).await })
            .await
    }

    pub async fn pipe<T: FromRedisValue>(&self, pipe: &Pipeline) -> Result<T, Failure> {
        self.call(|mut c| async move { pipe.query_async(&mut c).await })
            .await
    }

    /// Deletes `key` only if it still holds `value` ([`DELETE_IF_HELD`]).
    pub async fn delete_if_held(&self, key: &str, value: &str) -> Result<(), Failure> {
        let mut pipe = redis::pipe();
        eval(&mut pipe, DELETE_IF_HELD, &[key]).arg(value).ignore();
        self.pipe(&pipe).await
    }

    /// Pings the server until dropped, so that its health is known without calls to make,
    /// and comes back (other calls skip a link down).
    pub async fn watch(&self) {
        loop {
            tokio::time::sleep(RETRY_EVERY).await;
            let sent = Instant::now();
            if self.query::<String>(&Cmd::ping()).await.is_ok() {
                let micros = u64::try_from(sent.elapsed().as_micros()).unwrap_or(u64::MAX);
                let before = self.round_trip.swap(micros, Ordering::Relaxed);
                let slow = |us: u64| Duration::from_micros(us) > SLOW;
                if slow(micros) && !slow(before) {
                    tracing::warn!(
                        role = self.role,
                        round_trip_ms = micros / 1000,
                        "Redis answers slowly"
                    );
                }
            }
            if self.health() == Health::Full {
                let probe = Cmd::set_options(
                    format!("thirdbody:probe:{}", self.role),
                    1,
                    redis::SetOptions::default().with_expiration(redis::SetExpiry::PX(1000)),
                );
                if self.query::<()>(&probe).await.is_ok() {
                    self.full_at.store(0, Ordering::Relaxed);
                    tracing::info!(role = self.role, "Redis takes writes again");
                }
            }
        }
    }
}

/// `url` with its password replaced by `***`, for messages and logs: all between `://` and
/// the last `@` but the user (a password may hold `/`, `?` or `@`), and a `pass` or
/// `password` parameter (`redis+unix://`).
pub fn redacted(url: &str) -> String {
    let Some((scheme, rest)) = url.split_once("://") else {
        return url.to_string();
    };
    let mut shown = match rest.rsplit_once('@') {
        Some((userinfo, host)) => {
            let user = userinfo.split_once(':').map_or("", |(user, _)| user);
            format!("{scheme}://{user}:***@{host}")
        }
        None => url.to_string(),
    };
    if let Some((base, query)) = shown.split_once('?') {
        let parameters: Vec<String> = query
            .split('&')
            .map(|pair| match pair.split_once('=') {
                Some((name @ ("pass" | "password"), _)) => format!("{name}=***"),
                _ => pair.to_string(),
            })
            .collect();
        shown = format!("{base}?{}", parameters.join("&"));
    }
    shown
}

/// Why a Redis URL cannot be used (its password hidden).
#[derive(Debug, thiserror::Error)]
#[error("{role} URL {url}: {source}")]
pub struct LinkError {
    role: &'static str,
    url: String,
    source: RedisError,
}

/// Adds `script` on `keys` to `pipe`, its arguments to follow: `EVAL` with its text, so that
/// it needs no loading inside a transaction.
pub(super) fn eval<'a>(pipe: &'a mut Pipeline, script: &str, keys: &[&str]) -> &'a mut Pipeline {
    pipe.cmd("EVAL").arg(script).arg(keys.len()).arg(keys)
}

/// Deletes KEYS[1] only if it still holds ARGV[1] (it may have been taken over since).
pub(super) const DELETE_IF_HELD: &str = r#"
if redis.call('GET', KEYS[1]) == ARGV[1] then return redis.call('DEL', KEYS[1]) end
return 0
"#;

#[cfg(test)]
mod redaction {
    use super::redacted;

    #[test]
    fn a_password_never_shows() {
        for (url, shown) in [
            ("redis://:s3cret@redis:6379/0", "redis://:***@redis:6379/0"),
            (
                "rediss://app:s3cret@redis.example:6380",
                "rediss://app:***@redis.example:6380",
            ),
            ("redis://127.0.0.1:6379", "redis://127.0.0.1:6379"),
            (
                "redis://:ab/cd?e@f@redis:6379/0",
                "redis://:***@redis:6379/0",
            ),
            (
                "redis+unix:///run/redis.sock?db=1&pass=s3cret",
                "redis+unix:///run/redis.sock?db=1&pass=***",
            ),
        ] {
            assert_eq!(redacted(url), shown);
        }
    }
}
