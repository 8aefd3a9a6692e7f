//! One Redis server in one role (the answer cache, or the jobs), as this process reaches it:
//! a connection manager that reconnects by itself, a bound on every call, and whether the
//! server was reachable at the last call, so that callers can skip it at once while it is
//! not (synchronous solves then answer from this process's memory, without waiting).

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::OnceLock;
use std::time::Duration;

use metrics::Gauge;
use redis::aio::{ConnectionManager, ConnectionManagerConfig};
use redis::{Cmd, FromRedisValue, Pipeline, RedisError, Script};

/// A call that takes longer is a failure: Redis answers in well under a millisecond.
const CALL_TIMEOUT: Duration = Duration::from_secs(1);
/// How often an unreachable server is tried again.
pub const RETRY_EVERY: Duration = Duration::from_millis(500);

/// Why a call to Redis failed, in a sentence, and the server's error code if it refused
/// the command.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Failure {
    pub why: String,
    /// The code a Redis error reply begins with (`NOGROUP`, `BUSYGROUP`...).
    code: Option<String>,
}

impl Failure {
    pub fn new(why: impl Into<String>) -> Self {
        Failure {
            why: why.into(),
            code: None,
        }
    }

    /// Whether Redis refused the command with error `code`.
    pub fn is(&self, code: &str) -> bool {
        self.code.as_deref() == Some(code)
    }
}

impl std::fmt::Display for Failure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.why)
    }
}

/// A Redis server in one role.
pub struct Link {
    /// `cache` or `jobs`, for messages and metrics.
    pub role: &'static str,
    connection: ConnectionManager,
    up: AtomicBool,
    gauge: OnceLock<Gauge>,
}

impl Link {
    /// A link to the server at `url`; connects at the first call (the server may start later).
    pub fn open(role: &'static str, url: &str) -> Result<Link, String> {
        let client = redis::Client::open(url).map_err(|e| format!("{role} URL {url}: {e}"))?;
        let config = ConnectionManagerConfig::new()
            .set_connection_timeout(Some(CALL_TIMEOUT))
            .set_response_timeout(Some(CALL_TIMEOUT))
            .set_number_of_retries(1)
            .set_max_delay(Duration::from_millis(200));
        let connection = ConnectionManager::new_lazy_with_config(client, config)
            .map_err(|e| format!("{role} URL {url}: {e}"))?;
        Ok(Link {
            role,
            connection,
            up: AtomicBool::new(true),
            gauge: OnceLock::new(),
        })
    }

    /// Reports the link's state in `gauge` (1 reachable, 0 not) from now on.
    pub fn report_to(&self, gauge: Gauge) {
        gauge.set(f64::from(u8::from(self.is_up())));
        let _ = self.gauge.set(gauge);
    }

    /// Whether the last call reached the server.
    pub fn is_up(&self) -> bool {
        self.up.load(Ordering::Relaxed)
    }

    fn set_up(&self, up: bool) {
        if self.up.swap(up, Ordering::Relaxed) != up {
            if up {
                tracing::info!(role = self.role, "Redis reachable again");
            } else {
                tracing::warn!(role = self.role, "Redis unreachable");
            }
        }
        if let Some(gauge) = self.gauge.get() {
            gauge.set(f64::from(u8::from(up)));
        }
    }

    /// Records what a call's outcome says of the server's reachability.
    fn outcome<T>(
        &self,
        result: Result<Result<T, RedisError>, tokio::time::error::Elapsed>,
    ) -> Result<T, Failure> {
        match result {
            Ok(Ok(value)) => {
                self.set_up(true);
                Ok(value)
            }
            Ok(Err(e)) => {
                let lost = e.is_io_error()
                    || e.is_timeout()
                    || e.is_connection_dropped()
                    || e.is_connection_refusal()
                    || e.is_unrecoverable_error();
                if lost {
                    self.set_up(false);
                }
                Err(Failure {
                    why: format!("Redis ({}): {e}", self.role),
                    code: e.code().map(str::to_string),
                })
            }
            Err(_) => {
                self.set_up(false);
                Err(Failure::new(format!(
                    "Redis ({}) did not answer within {CALL_TIMEOUT:?}",
                    self.role
                )))
            }
        }
    }

    /// Runs `call` on the connection; a call cut by a lost connection is tried once more
    /// (the manager reconnects at once: the first call after a restart of Redis succeeds).
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
        self.outcome(result)
    }

    /// Runs one command.
    pub async fn query<T: FromRedisValue>(&self, cmd: &Cmd) -> Result<T, Failure> {
        self.call(|mut c| async move { cmd.query_async(&mut c).await })
            .await
    }

    /// Runs a pipeline (atomic if built so).
    pub async fn pipe<T: FromRedisValue>(&self, pipe: &Pipeline) -> Result<T, Failure> {
        self.call(|mut c| async move { pipe.query_async(&mut c).await })
            .await
    }

    /// Runs a Lua script with `keys` and `args`.
    pub async fn script<T: FromRedisValue>(
        &self,
        script: &Script,
        keys: &[&str],
        args: &[&[u8]],
    ) -> Result<T, Failure> {
        let mut invocation = script.prepare_invoke();
        for key in keys {
            invocation.key(*key);
        }
        for arg in args {
            invocation.arg(*arg);
        }
        let invocation = &invocation;
        self.call(|mut c| async move { invocation.invoke_async(&mut c).await })
            .await
    }

    /// Pings the server every half second, so that its reachability is known (and
    /// reported) even by a process that has no call to make, and comes back up by itself
    /// (other calls skip a link that is down). Runs until dropped.
    pub async fn watch(&self) {
        loop {
            tokio::time::sleep(RETRY_EVERY).await;
            let _ = self.query::<String>(&Cmd::ping()).await;
        }
    }
}
