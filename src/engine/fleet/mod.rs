//! Several processes on one Redis (opt-in, `--redis-url`): answers shared through a Redis
//! cache behind each process's own ([`TieredCache`]), with identical misses solved once in
//! the fleet; job records in Redis ([`RedisJobStore`]), so that any process answers for any
//! job; and the work itself on a Redis Stream read by a consumer group ([`worker`]): a job
//! is one entry, or a sweep one entry per range of points, taken by whichever process is
//! free, acknowledged only once its result is stored, and taken over from a process that
//! died after an idle bound. Solves are pure, so solving a part twice is harmless.
//!
//! Two Redis roles, one server or two: the cache (evicting, no persistence needed) and the
//! jobs (no eviction, persisted), so that a full cache never loses an accepted job.

mod cache;
pub mod link;
pub mod placement;
mod store;
pub mod worker;

use std::sync::Arc;
use std::time::Duration;

pub use cache::TieredCache;
pub use link::{Failure, Health, Link};
pub use store::RedisJobStore;
pub use worker::{Shared, Worker};

use super::cache::MemoryCache;
use super::{EngineConfig, Storage};

/// How the fleet's processes share work through Redis.
#[derive(Clone, Debug, PartialEq)]
pub struct FleetConfig {
    /// The Redis holding answers (`allkeys-lru`).
    pub cache_url: String,
    /// The Redis holding job records and the work stream (`noeviction`, AOF).
    pub jobs_url: String,
    /// How long a taken part may go without its process's heartbeat before another
    /// process takes it over.
    pub claim_idle: Duration,
    /// Deliveries of one part before its job fails (its processes died on each).
    pub max_deliveries: u32,
    /// Points per part of a sweep whose cost per point is not measured yet.
    pub part_points: usize,
    /// Bytes the cached answers may take when the cache shares the jobs' server.
    pub shared_cache_bytes: u64,
}

/// The Redis keys, all under `thirdbody:`.
mod keys {
    use uuid::Uuid;

    /// The work stream and its consumer group.
    pub const STREAM: &str = "thirdbody:work";
    /// When the job store's data began (Unix ms), set by the first process to find it
    /// missing: a store restarted without its data gets a new one.
    pub const EPOCH: &str = "thirdbody:epoch";
    /// Seconds per point of each cost class, as measured by the workers.
    pub const RATES: &str = "thirdbody:rates";
    pub const GROUP: &str = "workers";

    pub fn answer(key: &str) -> String {
        format!("thirdbody:answer:{key}")
    }

    /// On a server shared with the jobs: the cached answers by age, and their sizes (with
    /// their total under `total`), which bound the cache's share of the server.
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

    /// A job's keys.
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

/// This process's place in the fleet: its links to the two Redis roles and its name as a
/// consumer of the work stream.
pub struct Fleet {
    pub config: FleetConfig,
    pub cache: Link,
    pub jobs: Link,
    /// Unique to this process: host name, process id and random bits.
    pub consumer: String,
}

impl Fleet {
    /// Links to the servers of `config` (connected at the first call).
    pub fn open(config: FleetConfig) -> Result<Fleet, String> {
        let cache = Link::open("cache", &config.cache_url)?;
        let jobs = Link::open("jobs", &config.jobs_url)?;
        let host = std::env::var("HOSTNAME").unwrap_or_else(|_| "thirdbody".to_string());
        let tag = uuid::Uuid::new_v4().simple().to_string();
        let consumer = format!("{host}-{}-{}", std::process::id(), &tag[..8]);
        Ok(Fleet {
            config,
            cache,
            jobs,
            consumer,
        })
    }

    /// Whether the cache and the jobs are on one server.
    pub fn one_server(&self) -> bool {
        self.config.cache_url == self.config.jobs_url
    }

    /// Each link's health, by role.
    pub fn health(&self) -> [(&'static str, Health); 2] {
        [
            (self.cache.role, self.cache.health()),
            (self.jobs.role, self.jobs.health()),
        ]
    }

    /// Keeps trying unreachable servers until dropped (see [`Link::watch`]), and marks the
    /// beginning of the job store's data when it finds none (within half a second of a
    /// restart of Redis without its data).
    pub async fn watch(&self) {
        let epoch = async {
            loop {
                let now = store::unix_millis(std::time::SystemTime::now());
                let mark = redis::Cmd::set_options(
                    keys::EPOCH,
                    now,
                    redis::SetOptions::default().conditional_set(redis::ExistenceCheck::NX),
                );
                let _ = self.jobs.query::<Option<String>>(&mark).await;
                tokio::time::sleep(link::RETRY_EVERY).await;
            }
        };
        tokio::join!(self.cache.watch(), self.jobs.watch(), epoch);
    }

    /// When the job store's data began (Unix ms), if known.
    pub async fn epoch(&self) -> Option<u64> {
        self.jobs
            .query(&redis::Cmd::get(keys::EPOCH))
            .await
            .ok()
            .flatten()
    }
}

/// An engine's storage in the fleet of `fleet`: this process's memory in front of Redis for
/// answers, Redis for jobs and their work.
pub fn storage(config: &EngineConfig, fleet: FleetConfig) -> Result<Storage, String> {
    let fleet = Arc::new(Fleet::open(fleet)?);
    let l1 = MemoryCache::for_engine(config);
    // A fleet's finished jobs are its history: kept in Redis for the history's retention.
    let store = Arc::new(RedisJobStore::new(
        fleet.clone(),
        config.history_retention,
        config.job_deadline,
    ));
    Ok(Storage {
        cache: Arc::new(TieredCache::new(l1, fleet.clone(), config.cache_ttl)),
        jobs: store.clone(),
        fleet: Some(Arc::new(Shared::new(fleet, store))),
    })
}
