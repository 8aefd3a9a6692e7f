//! Answers shared by the fleet: this process's memory first (L1), then Redis (L2), by the
//! same content key, for the same time to live. A miss is claimed in Redis before it is
//! solved, so that identical misses on several processes solve once: the others wait for
//! the answer to appear (or for the claim to lapse, if its holder died).

use std::sync::Arc;
use std::time::{Duration, Instant};

use async_trait::async_trait;
use bytes::Bytes;
use redis::{Cmd, ExistenceCheck, Script, SetExpiry, SetOptions};

use super::{keys, Fleet};
use crate::engine::cache::{Claim, MemoryCache, ResultCache, Solved};
use crate::job::registry::KindName;
use crate::job::JobError;
use crate::render::Format;

/// How often a process waiting for another's solve looks for the answer.
const LOOK_EVERY: Duration = Duration::from_millis(5);

/// Deletes a claim only if it is still the caller's (it may have lapsed and been taken).
const RELEASE: &str = r#"
if redis.call('GET', KEYS[1]) == ARGV[1] then
  return redis.call('DEL', KEYS[1])
end
return 0
"#;

/// This process's cache in front of the fleet's.
pub struct TieredCache {
    l1: MemoryCache,
    fleet: Arc<Fleet>,
    ttl: Duration,
    release: Script,
}

impl TieredCache {
    pub fn new(l1: MemoryCache, fleet: Arc<Fleet>, ttl: Duration) -> TieredCache {
        TieredCache {
            l1,
            fleet,
            ttl,
            release: Script::new(RELEASE),
        }
    }

    /// The answer under `key` in Redis, if there (and Redis reachable).
    async fn shared(&self, key: &str) -> Option<Arc<Solved>> {
        let link = &self.fleet.cache;
        if !link.is_up() {
            return None;
        }
        let cmd = Cmd::hmget(keys::answer(key), &["json", "csv", "kind"][..]);
        type Fields = (Option<Vec<u8>>, Option<Vec<u8>>, Option<String>);
        let (json, csv, kind): Fields = link.query(&cmd).await.ok()?;
        let kind = KindName::find(&kind?).ok()?;
        let solved = Arc::new(Solved::rendered(
            key.to_string(),
            kind,
            Bytes::from(json?),
            Bytes::from(csv?),
        ));
        self.l1.insert(solved.clone()).await;
        Some(solved)
    }
}

#[async_trait]
impl ResultCache for TieredCache {
    async fn get(&self, key: &str) -> Option<Arc<Solved>> {
        match self.l1.get(key).await {
            Some(solved) => Some(solved),
            None => self.shared(key).await,
        }
    }

    async fn insert(&self, solved: Arc<Solved>) {
        self.l1.insert(solved.clone()).await;
        let link = &self.fleet.cache;
        if !link.is_up() {
            return;
        }
        let Ok(csv) = solved.body(Format::Csv) else {
            return;
        };
        let key = keys::answer(&solved.key);
        let mut pipe = redis::pipe();
        let fields: [(&str, &[u8]); 3] = [
            ("json", solved.json()),
            ("csv", &csv),
            ("kind", solved.kind.name().as_bytes()),
        ];
        pipe.atomic()
            .hset_multiple(&key, &fields)
            .ignore()
            .pexpire(&key, i64::try_from(millis(self.ttl)).unwrap_or(i64::MAX))
            .ignore();
        if let Err(e) = link.pipe::<()>(&pipe).await {
            tracing::warn!(error = %e, "an answer was not shared");
        }
    }

    async fn claim(&self, key: &str, deadline: Instant) -> Result<Claim, JobError> {
        let link = &self.fleet.cache;
        let claim = keys::solving(key);
        loop {
            if !link.is_up() {
                // Alone for now: solve here.
                return Ok(Claim::Mine);
            }
            let lapse = deadline.saturating_duration_since(Instant::now()) + Duration::from_secs(1);
            let only_new = SetOptions::default()
                .conditional_set(ExistenceCheck::NX)
                .with_expiration(SetExpiry::PX(millis(lapse)));
            let taken = Cmd::set_options(&claim, &self.fleet.consumer, only_new);
            if let Ok(Some(_)) = link.query::<Option<String>>(&taken).await {
                // Solved by another between the lookup and the claim?
                if let Some(solved) = self.shared(key).await {
                    self.release(key).await;
                    return Ok(Claim::Solved(solved));
                }
                return Ok(Claim::Mine);
            }
            if Instant::now() >= deadline {
                return Err(JobError::DeadlineExceeded);
            }
            tokio::time::sleep(LOOK_EVERY).await;
            if let Some(solved) = self.shared(key).await {
                return Ok(Claim::Solved(solved));
            }
        }
    }

    async fn release(&self, key: &str) {
        let link = &self.fleet.cache;
        if link.is_up() {
            let claim = keys::solving(key);
            let _ = link
                .script::<i64>(&self.release, &[&claim], &[self.fleet.consumer.as_bytes()])
                .await;
        }
    }
}

/// `duration` in whole milliseconds, at least one.
pub fn millis(duration: Duration) -> u64 {
    u64::try_from(duration.as_millis())
        .unwrap_or(u64::MAX)
        .max(1)
}
