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
mod link;
mod store;
pub mod worker;

use std::sync::Arc;
use std::time::Duration;

pub use cache::TieredCache;
pub use link::{Failure, Link};
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
    /// Points per part of a sweep.
    pub part_points: usize,
}

/// The Redis keys, all under `thirdbody:`.
mod keys {
    use uuid::Uuid;

    /// The work stream and its consumer group.
    pub const STREAM: &str = "thirdbody:work";
    pub const GROUP: &str = "workers";

    pub fn answer(key: &str) -> String {
        format!("thirdbody:answer:{key}")
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

    /// Each link's reachability, by role.
    pub fn health(&self) -> [(&'static str, bool); 2] {
        [
            (self.cache.role, self.cache.is_up()),
            (self.jobs.role, self.jobs.is_up()),
        ]
    }

    /// Keeps trying unreachable servers until dropped (see [`Link::watch`]).
    pub async fn watch(&self) {
        tokio::join!(self.cache.watch(), self.jobs.watch());
    }
}

/// An engine's storage in the fleet of `fleet`: this process's memory in front of Redis for
/// answers, Redis for jobs and their work.
pub fn storage(config: &EngineConfig, fleet: FleetConfig) -> Result<Storage, String> {
    let fleet = Arc::new(Fleet::open(fleet)?);
    let l1 = MemoryCache::for_engine(config);
    let store = Arc::new(RedisJobStore::new(fleet.clone(), config.job_retention));
    Ok(Storage {
        cache: Arc::new(TieredCache::new(l1, fleet.clone(), config.cache_ttl)),
        jobs: store.clone(),
        fleet: Some(Arc::new(Shared::new(fleet, store))),
    })
}
