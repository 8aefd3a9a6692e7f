//! Several processes on one Redis: absent, the service keeps everything in its own memory
//! and its database.

use std::time::Duration;

use super::{check_all, Bounded, ConfigError, MAX_BYTES};
use crate::engine::fleet::FleetConfig;

/// How long a part of a job may go without its process's heartbeat before another process
/// takes it over: 10 s is fifty missed heartbeats (one every 200 ms), so a process taking
/// it over is one that died or hung, never one a loaded machine slowed; and a dead
/// process's part waits no longer than that for another.
pub const CLAIM_IDLE: Duration = Duration::from_secs(10);
/// Points per part of a sweep on the fleet's stream until the fleet has measured what a
/// point of its kind costs (then parts are sized by cost: one for a cheap sweep): 100
/// points of the costliest kind take a few seconds, so that the first sweep of a kind is
/// spread over the fleet and measured soon, and a part lost with its process is little work.
pub const PART_POINTS: usize = 100;
/// Most deliveries of a part of a job: a part whose processes died a hundred times will
/// not finish on the hundred-and-first.
const MAX_DELIVERIES: u64 = 100;
/// Least share of Redis for answers: 64 KiB, a few answers.
const MIN_CACHE_BYTES: u64 = 1 << 16;

/// The fleet's Redis, and how its processes share work.
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

    /// Deliveries of one part of a job before the job fails (each time its process died).
    #[arg(long, env = "THIRDBODY_MAX_DELIVERIES", default_value_t = 3)]
    pub max_deliveries: u32,

    /// When one Redis holds both the cache and the jobs: the bytes the cached answers may
    /// take there at most (the oldest go first), so that answers never crowd out jobs; and
    /// never more than half of the server's maxmemory (read when connected, and every
    /// minute; the bound chosen is logged).
    #[arg(long, env = "THIRDBODY_REDIS_CACHE_BYTES", default_value_t = 64 << 20)]
    pub redis_cache_bytes: u64,
}

impl FleetArgs {
    /// The fleet's settings, if there is a fleet.
    pub fn validate(self) -> Result<Option<FleetConfig>, ConfigError> {
        let cache_bytes = Bounded::count("--redis-cache-bytes", self.redis_cache_bytes, 0, 0);
        check_all([
            Bounded::count("--max-deliveries", self.max_deliveries, 1, MAX_DELIVERIES),
            Bounded {
                least: MIN_CACHE_BYTES,
                most: MAX_BYTES,
                unit: "bytes (1 TiB)",
                ..cache_bytes
            },
        ])?;
        let Some(cache_url) = self.redis_url else {
            return Ok(None);
        };
        let jobs_url = self.redis_jobs_url.unwrap_or_else(|| cache_url.clone());
        for (flag, url) in [("--redis-url", &cache_url), ("--redis-jobs-url", &jobs_url)] {
            if let Err(e) = redis::Client::open(url.as_str()) {
                let url = crate::engine::fleet::link::redacted(url);
                return Err(ConfigError::Invalid(format!("{flag} {url}: {e}")));
            }
        }
        Ok(Some(FleetConfig {
            cache_url,
            jobs_url,
            claim_idle: CLAIM_IDLE,
            max_deliveries: self.max_deliveries,
            part_points: PART_POINTS,
            shared_cache_bytes: self.redis_cache_bytes,
        }))
    }
}
