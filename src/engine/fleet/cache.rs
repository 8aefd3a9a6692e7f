//! Answers shared by the fleet: this process's memory first (L1), then Redis (L2), by the
//! same key and time to live. A miss is claimed in Redis before it is solved, so that
//! identical misses solve once: the others wait for the answer (or for the claim to lapse).

use std::sync::atomic::Ordering;
use std::sync::Arc;
use std::time::{Duration, Instant};

use async_trait::async_trait;
use redis::{Cmd, ExistenceCheck, SetExpiry, SetOptions};
use uuid::Uuid;

use super::link::eval;
use super::{keys, Fleet, Health};
use crate::engine::cache::{Claim, MemoryCache, ResultCache, Solved};
use crate::engine::clock::millis;
use crate::job::registry::KindName;
use crate::job::JobError;
use crate::render::Format;

/// How often a process waiting for another's solve looks for the answer.
const LOOK_EVERY: Duration = Duration::from_millis(5);

/// Bounds the answers' bytes on a server shared with the jobs: records the answer just
/// written, then drops the oldest while the total is over the bound.
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
}

impl TieredCache {
    pub fn new(l1: MemoryCache, fleet: Arc<Fleet>, ttl: Duration) -> TieredCache {
        TieredCache { l1, fleet, ttl }
    }

    /// The answer under `key` in Redis: its texts, or the job whose stored result it is.
    async fn shared(&self, key: &str) -> Option<Arc<Solved>> {
        let link = &self.fleet.cache;
        if !link.is_quick() {
            return None;
        }
        let cmd = Cmd::hmget(keys::answer(key), &["json", "csv", "kind", "job"][..]);
        let [json, csv, kind, job]: [Option<Vec<u8>>; 4] = link.query(&cmd).await.ok()?;
        let kind = KindName::find(std::str::from_utf8(&kind?).ok()?).ok()?;
        let (json, csv) = match (json, csv, job) {
            (Some(json), Some(csv), _) => (json, csv),
            (_, _, Some(job)) => {
                let id = std::str::from_utf8(&job).ok()?.parse().ok()?;
                let cmd = Cmd::hmget(keys::job(id).result, &["json", "csv"][..]);
                let [json, csv]: [Option<Vec<u8>>; 2] = link.query(&cmd).await.ok()?;
                (json?, csv?)
            }
            _ => return None,
        };
        let solved = Arc::new(Solved::rendered(key.into(), kind, json.into(), csv.into()));
        self.l1.insert(solved.clone()).await;
        Some(solved)
    }

    /// Keeps `solved` here, and in Redis if up: its texts, or a reference to the result of
    /// `job` (on the job store's server, so that it is written once).
    async fn share(&self, solved: Arc<Solved>, job: Option<Uuid>) {
        self.l1.insert(solved.clone()).await;
        let link = &self.fleet.cache;
        if link.health() != Health::Up {
            return;
        }
        let (key, job) = (keys::answer(&solved.key), job.map(|id| id.to_string()));
        let ttl = i64::try_from(millis(self.ttl)).unwrap_or(i64::MAX);
        let kind = solved.kind.name().as_bytes();
        let csv;
        let (fields, bytes): (Vec<(&str, &[u8])>, _) = match &job {
            Some(job) => (vec![("kind", kind), ("job", job.as_bytes())], None),
            None => {
                let Ok(body) = solved.body(Format::Csv) else {
                    return;
                };
                csv = body;
                let bytes = solved.json().len() + csv.len() + key.len();
                let fields: Vec<(&str, &[u8])> =
                    vec![("json", solved.json()), ("csv", &csv), ("kind", kind)];
                (fields, Some(bytes))
            }
        };
        let mut pipe = redis::pipe();
        pipe.atomic()
            .hset_multiple(&key, &fields)
            .ignore()
            .pexpire(&key, ttl)
            .ignore();
        if let Some(bytes) = bytes.filter(|_| self.fleet.one_server()) {
            let now = crate::engine::clock::unix_millis(std::time::SystemTime::now());
            let bound = self.fleet.cache_bytes.load(Ordering::Relaxed);
            let index = [keys::ANSWERS_BY_AGE, keys::ANSWER_SIZES, &key];
            eval(&mut pipe, BOUND, &index)
                .arg(now)
                .arg(bytes)
                .arg(bound)
                .arg(ttl)
                .ignore();
        }
        if let Err(e) = link.pipe::<()>(&pipe).await {
            tracing::warn!(error = %e, "an answer was not shared");
        }
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
        self.share(solved, None).await
    }

    async fn insert_result_of(&self, solved: Arc<Solved>, job: Uuid) {
        let job = self.fleet.one_server().then_some(job);
        self.share(solved, job).await
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
            let _ = link
                .delete_if_held(&keys::solving(key), &self.fleet.consumer)
                .await;
        }
    }
}
