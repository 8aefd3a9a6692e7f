//! Several processes on one Redis (opt-in, `--redis-url`): a shared answer cache, job records
//! any process answers for, and the work on a Redis Stream read by a consumer group, taken
//! over from a process that died (solves are pure: solving a part twice is harmless). Two
//! roles, one server or two: the cache (evicting) and the jobs (no eviction, persisted), so
//! that a full cache never loses an accepted job.

mod cache;
pub mod link;
pub mod placement;
mod store;
pub mod worker;

use std::collections::HashMap;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Duration;

pub use cache::TieredCache;
pub use link::{Failure, Health, Link, LinkError};
pub use store::RedisJobStore;
pub use worker::{Shared, Worker};

#[derive(Clone, Debug, PartialEq)]
pub struct FleetConfig {
    /// The Redis holding answers (`allkeys-lru`).
    pub cache_url: String,
    /// The Redis holding job records and the work stream (`noeviction`, AOF).
    pub jobs_url: String,
    /// How long a taken part may go without its heartbeat before another process takes it.
    pub claim_idle: Duration,
    /// Deliveries of one part before its job fails (its processes died on each).
    pub max_deliveries: u32,
    /// Points per part of a sweep whose cost per point is not measured yet.
    pub part_points: usize,
    /// Bytes the cached answers may take on the jobs' server, at most ([`cache_share`]).
    pub shared_cache_bytes: u64,
}

/// How often the server's maxmemory is read again (it may change, or the server be replaced).
const MAXMEMORY_EVERY: Duration = Duration::from_secs(60);

/// What a Redis server says of its memory limit.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Maxmemory {
    /// `maxmemory`, in bytes.
    Limit(u64),
    /// `maxmemory 0`: the server takes what the machine has.
    Unlimited,
    /// Neither `CONFIG GET` nor `INFO memory` says (managed servers may refuse both).
    Unknown,
}

/// The bytes cached answers may take on a server shared with the jobs: `given`, but at most
/// half its maxmemory, so that they leave the jobs room (a 32 MB server under the 64 MiB
/// default refused every submission once anonymous solves had filled it).
pub fn cache_share(given: u64, maxmemory: Maxmemory) -> u64 {
    match maxmemory {
        Maxmemory::Limit(limit) => given.min(limit / 2),
        Maxmemory::Unlimited | Maxmemory::Unknown => given,
    }
}

/// The Redis keys, all under `thirdbody:`.
mod keys {
    use uuid::Uuid;

    /// The work stream and its consumer group.
    pub const STREAM: &str = "thirdbody:work";
    /// When the job store's data began (Unix ms): a store restarted without it gets a new one.
    pub const EPOCH: &str = "thirdbody:epoch";
    /// Seconds per point of each cost class, as measured by the workers.
    pub const RATES: &str = "thirdbody:rates";
    pub const GROUP: &str = "workers";

    pub fn answer(key: &str) -> String {
        format!("thirdbody:answer:{key}")
    }

    /// On a server shared with the jobs: the answers by age, and their sizes (and `total`).
    pub const ANSWERS_BY_AGE: &str = "thirdbody:answers:by-age";
    pub const ANSWER_SIZES: &str = "thirdbody:answers:sizes";

    /// The jobs of an owner (its hash), scored by their submission (Unix ms).
    pub fn owner(owner: &str) -> String {
        format!("thirdbody:owner:{owner}")
    }

    /// The newest job that succeeded on the input whose hash is `input_hash`.
    pub fn input(input_hash: &str) -> String {
        format!("thirdbody:input:{input_hash}")
    }

    /// The fleet-wide claim on solving `key`.
    pub fn solving(key: &str) -> String {
        format!("thirdbody:solving:{key}")
    }

    pub struct Job {
        pub record: String,
        pub result: String,
        /// Solved parts, by index.
        pub parts: String,
        /// Deliveries of each part, by index.
        pub deliveries: String,
        /// A result on its way to `result`, renamed there once the job's state allows.
        pub staged: String,
    }

    impl Job {
        pub fn all(&self) -> [&str; 4] {
            [&self.record, &self.result, &self.parts, &self.deliveries]
        }
    }

    pub fn job(id: Uuid) -> Job {
        let record = format!("thirdbody:job:{id}");
        Job {
            result: format!("{record}:result"),
            parts: format!("{record}:parts"),
            deliveries: format!("{record}:deliveries"),
            staged: format!("{record}:staged"),
            record,
        }
    }
}

/// This process's links to the two Redis roles, and its name as a consumer of the stream.
pub struct Fleet {
    pub config: FleetConfig,
    pub cache: Link,
    pub jobs: Link,
    /// Unique to this process: host name, process id and random bits.
    pub consumer: String,
    /// The bytes cached answers may take on a server shared with the jobs ([`cache_share`]).
    cache_bytes: AtomicU64,
}

impl Fleet {
    pub fn open(config: FleetConfig) -> Result<Fleet, LinkError> {
        let cache = Link::open("cache", &config.cache_url)?;
        let jobs = Link::open("jobs", &config.jobs_url)?;
        let host = std::env::var("HOSTNAME").unwrap_or_else(|_| "thirdbody".to_string());
        let tag = uuid::Uuid::new_v4().simple().to_string();
        let consumer = format!("{host}-{}-{}", std::process::id(), &tag[..8]);
        Ok(Fleet {
            cache_bytes: AtomicU64::new(config.shared_cache_bytes),
            config,
            cache,
            jobs,
            consumer,
        })
    }

    pub fn one_server(&self) -> bool {
        self.config.cache_url == self.config.jobs_url
    }

    pub fn health(&self) -> [(&'static str, Health); 2] {
        [
            (self.cache.role, self.cache.health()),
            (self.jobs.role, self.jobs.health()),
        ]
    }

    /// Keeps trying unreachable servers until dropped ([`Link::watch`]), and marks the
    /// beginning of the job store's data when it finds none (as after a restart without it).
    pub async fn watch(&self) {
        let epoch = async {
            loop {
                let now = crate::engine::clock::unix_millis(std::time::SystemTime::now());
                let mark = redis::Cmd::set_options(
                    keys::EPOCH,
                    now,
                    redis::SetOptions::default().conditional_set(redis::ExistenceCheck::NX),
                );
                let _ = self.jobs.query::<Option<String>>(&mark).await;
                tokio::time::sleep(link::RETRY_EVERY).await;
            }
        };
        tokio::join!(
            self.cache.watch(),
            self.jobs.watch(),
            epoch,
            self.size_cache()
        );
    }

    /// On a server shared with the jobs, bounds the cached answers by its maxmemory
    /// ([`cache_share`]), read every minute, and logs each new bound and why.
    async fn size_cache(&self) {
        if !self.one_server() {
            return;
        }
        let given = self.config.shared_cache_bytes;
        let mut known = None;
        loop {
            let Some(maxmemory) = maxmemory(&self.cache).await else {
                tokio::time::sleep(link::RETRY_EVERY).await; // unreachable
                continue;
            };
            if known.replace(maxmemory) != Some(maxmemory) {
                let bytes = cache_share(given, maxmemory);
                self.cache_bytes.store(bytes, Ordering::Relaxed);
                match maxmemory {
                    Maxmemory::Limit(limit) if bytes < given => tracing::warn!(
                        maxmemory = limit,
                        redis_cache_bytes = given,
                        cache_bytes = bytes,
                        "cached answers take at most half of Redis's maxmemory, less than \
                         --redis-cache-bytes, so that jobs keep room on the server they share"
                    ),
                    Maxmemory::Limit(limit) => tracing::info!(
                        maxmemory = limit,
                        cache_bytes = bytes,
                        "cached answers take at most --redis-cache-bytes of Redis"
                    ),
                    Maxmemory::Unlimited => tracing::info!(
                        cache_bytes = bytes,
                        "Redis has no maxmemory: cached answers take at most --redis-cache-bytes"
                    ),
                    Maxmemory::Unknown => tracing::warn!(
                        cache_bytes = bytes,
                        "Redis does not say its maxmemory (CONFIG GET and INFO refused): cached \
                         answers take at most --redis-cache-bytes; keep it under half of the \
                         server's memory"
                    ),
                }
            }
            tokio::time::sleep(MAXMEMORY_EVERY).await;
        }
    }

    pub async fn epoch(&self) -> Option<u64> {
        self.jobs
            .query(&redis::Cmd::get(keys::EPOCH))
            .await
            .ok()
            .flatten()
    }
}

/// What the server says of its memory limit: `CONFIG GET maxmemory`, or where that is
/// refused (managed servers often forbid CONFIG) `INFO memory`; `None` if unreachable.
async fn maxmemory(link: &Link) -> Option<Maxmemory> {
    let said = |bytes: u64| match bytes {
        0 => Maxmemory::Unlimited,
        limit => Maxmemory::Limit(limit),
    };
    let config = redis::cmd("CONFIG").arg("GET").arg("maxmemory").clone();
    if let Ok(values) = link.query::<HashMap<String, u64>>(&config).await {
        if let Some(&bytes) = values.get("maxmemory") {
            return Some(said(bytes));
        }
    }
    let info = redis::cmd("INFO").arg("memory").clone();
    match link.query::<String>(&info).await {
        Ok(text) => Some(
            text.lines()
                .find_map(|line| line.strip_prefix("maxmemory:")?.trim().parse().ok())
                .map_or(Maxmemory::Unknown, said),
        ),
        // Reached, and refused both: the server does not say.
        Err(_) if link.is_up() => Some(Maxmemory::Unknown),
        Err(_) => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn answers_take_at_most_half_of_a_servers_maxmemory() {
        let flag = 64 << 20;
        assert_eq!(cache_share(flag, Maxmemory::Limit(32 << 20)), 16 << 20);
        assert_eq!(cache_share(flag, Maxmemory::Limit(1 << 30)), flag);
        assert_eq!(cache_share(flag, Maxmemory::Unlimited), flag);
        assert_eq!(cache_share(flag, Maxmemory::Unknown), flag);
    }
}
