//! Answers shared by the fleet: this process's memory first (L1), then Redis (L2), by the
//! same content key, for the same time to live. A miss is claimed in Redis before it is
//! solved, so that identical misses on several processes solve once: the others wait for
//! the answer to appear (or for the claim to lapse, if its holder died).

use std::sync::Arc;
use std::time::{Duration, Instant};

use async_trait::async_trait;
use bytes::Bytes;
use redis::{Cmd, ExistenceCheck, Script, SetExpiry, SetOptions};
use uuid::Uuid;

use super::{keys, Fleet, Health};
use crate::engine::cache::{Claim, MemoryCache, ResultCache, Solved};
use crate::engine::clock::millis;
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

/// Bounds the answers' bytes on a server shared with the jobs: records the answer just
/// written (its key and size), then drops the oldest answers while the total is over the
/// bound. The index itself expires with the answers, when no answer is written for as long.
///
/// KEYS: answers by age, their sizes, the answer. ARGV: now (ms), its bytes, the bound, the
/// answers' time to live (ms).
const BOUND: &str = r#"
redis.call('ZADD', KEYS[1], ARGV[1], KEYS[3])
local before = tonumber(redis.call('HGET', KEYS[2], KEYS[3]) or '0')
redis.call('HSET', KEYS[2], KEYS[3], ARGV[2])
local total = redis.call('HINCRBY', KEYS[2], 'total', tonumber(ARGV[2]) - before)
local dropped = 0
while total > tonumber(ARGV[3]) do
  local oldest = redis.call('ZPOPMIN', KEYS[1])
  if #oldest == 0 then break end
  local size = tonumber(redis.call('HGET', KEYS[2], oldest[1]) or '0')
  redis.call('HDEL', KEYS[2], oldest[1])
  redis.call('DEL', oldest[1])
  total = redis.call('HINCRBY', KEYS[2], 'total', -size)
  dropped = dropped + 1
end
redis.call('PEXPIRE', KEYS[1], ARGV[4])
redis.call('PEXPIRE', KEYS[2], ARGV[4])
return dropped
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

    /// The answer under `key` in Redis, if there (and Redis reachable): its texts, or the
    /// job whose stored result it is (on the same server).
    async fn shared(&self, key: &str) -> Option<Arc<Solved>> {
        let link = &self.fleet.cache;
        if !link.is_quick() {
            return None;
        }
        let cmd = Cmd::hmget(keys::answer(key), &["json", "csv", "kind", "job"][..]);
        type Fields = (
            Option<Vec<u8>>,
            Option<Vec<u8>>,
            Option<String>,
            Option<String>,
        );
        let (json, csv, kind, job): Fields = link.query(&cmd).await.ok()?;
        let kind = KindName::find(&kind?).ok()?;
        let (json, csv) = match (json, csv, job) {
            (Some(json), Some(csv), _) => (json, csv),
            (_, _, Some(job)) => {
                let result = keys::job(job.parse().ok()?).result;
                let cmd = Cmd::hmget(result, &["json", "csv"][..]);
                let (json, csv): (Option<Vec<u8>>, Option<Vec<u8>>) =
                    link.query(&cmd).await.ok()?;
                (json?, csv?)
            }
            _ => return None,
        };
        let solved = Arc::new(Solved::rendered(
            key.to_string(),
            kind,
            Bytes::from(json),
            Bytes::from(csv),
        ));
        self.l1.insert(solved.clone()).await;
        Some(solved)
    }

    /// The answer's time to live in Redis, in ms.
    fn ttl_millis(&self) -> i64 {
        i64::try_from(millis(self.ttl)).unwrap_or(i64::MAX)
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
        if link.health() != Health::Up {
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
            .pexpire(&key, self.ttl_millis())
            .ignore();
        if self.fleet.one_server() {
            let bytes = (solved.json().len() + csv.len() + key.len()).to_string();
            let now = crate::engine::clock::unix_millis(std::time::SystemTime::now()).to_string();
            let bound = self.fleet.cache_bytes().to_string();
            let ttl = self.ttl_millis().to_string();
            pipe.add_command(super::link::eval(
                BOUND,
                &[keys::ANSWERS_BY_AGE, keys::ANSWER_SIZES, &key],
                &[
                    now.as_bytes(),
                    bytes.as_bytes(),
                    bound.as_bytes(),
                    ttl.as_bytes(),
                ],
            ))
            .ignore();
        }
        if let Err(e) = link.pipe::<()>(&pipe).await {
            tracing::warn!(error = %e, "an answer was not shared");
        }
    }

    /// On one server with the job store, the answer is a reference to the job's result,
    /// written once there; on a server of its own, a copy.
    async fn insert_result_of(&self, solved: Arc<Solved>, job: Uuid) {
        if !self.fleet.one_server() {
            return self.insert(solved).await;
        }
        self.l1.insert(solved.clone()).await;
        let link = &self.fleet.cache;
        if link.health() != Health::Up {
            return;
        }
        let key = keys::answer(&solved.key);
        let job = job.to_string();
        let fields: [(&str, &str); 2] = [("kind", solved.kind.name()), ("job", &job)];
        let mut pipe = redis::pipe();
        pipe.atomic()
            .hset_multiple(&key, &fields)
            .ignore()
            .pexpire(&key, self.ttl_millis())
            .ignore();
        if let Err(e) = link.pipe::<()>(&pipe).await {
            tracing::warn!(error = %e, "an answer was not shared");
        }
    }

    async fn claim(&self, key: &str, deadline: Instant) -> Result<Claim, JobError> {
        let link = &self.fleet.cache;
        let claim = keys::solving(key);
        loop {
            if link.health() != Health::Up {
                // Alone for now (Redis away, slow or full): solve here.
                return Ok(Claim::Mine);
            }
            let lapse = deadline.saturating_duration_since(Instant::now()) + Duration::from_secs(1);
            let only_new = SetOptions::default()
                .conditional_set(ExistenceCheck::NX)
                .with_expiration(SetExpiry::PX(millis(lapse)));
            let taken = Cmd::set_options(&claim, &self.fleet.consumer, only_new);
            match link.query::<Option<String>>(&taken).await {
                Ok(Some(_)) => {
                    // Solved by another between the lookup and the claim?
                    if let Some(solved) = self.shared(key).await {
                        self.release(key).await;
                        return Ok(Claim::Solved(solved));
                    }
                    return Ok(Claim::Mine);
                }
                // Held by another process: wait for its answer.
                Ok(None) => {}
                // No claim can be made (Redis full, or away): solve here.
                Err(_) => return Ok(Claim::Mine),
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
        if link.is_quick() {
            let claim = keys::solving(key);
            let _ = link
                .script::<i64>(&self.release, &[&claim], &[self.fleet.consumer.as_bytes()])
                .await;
        }
    }
}
