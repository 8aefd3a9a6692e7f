//! Job records in Redis, so that every process answers for every job: a hash per job (its
//! state, progress, the job itself as text, its deadline), its result once it has one, and
//! the parts of a split job as they are solved. A finished state is final (a late worker
//! cannot overwrite a cancel) and starts the record's retention, after which Redis forgets
//! every key of the job.

use std::collections::HashMap;
use std::ops::Range;
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

use async_trait::async_trait;
use bytes::Bytes;
use redis::{Cmd, Script};
use uuid::Uuid;

use super::cache::millis;
use super::{keys, Failure, Fleet};
use crate::engine::cache::Solved;
use crate::engine::spill::JobResult;
use crate::engine::store::{JobRecord, JobState, JobStatus, JobStore, Refusal};
use crate::job::parts::RenderedPart;
use crate::job::registry::KindName;
use crate::job::{JobError, Work};
use std::sync::Arc;

/// Moves a job to a new state unless it has finished; a finished state keeps the result,
/// drops the parts and starts the retention of every key of the job.
const UPDATE: &str = r#"
local current = redis.call('HGET', KEYS[1], 'status')
if current ~= 'queued' and current ~= 'running' then return 0 end
redis.call('HSET', KEYS[1], 'status', ARGV[1])
if ARGV[2] ~= '' then redis.call('HSET', KEYS[1], 'done', ARGV[2]) end
if ARGV[3] ~= '' then redis.call('HSET', KEYS[1], 'error', ARGV[3]) end
if ARGV[1] ~= 'queued' and ARGV[1] ~= 'running' then
  if ARGV[4] ~= '' then redis.call('HSET', KEYS[2], 'json', ARGV[4], 'csv', ARGV[5]) end
  redis.call('HSET', KEYS[1], 'finished_at', ARGV[7])
  redis.call('DEL', KEYS[3])
  for i = 1, 4 do redis.call('PEXPIRE', KEYS[i], ARGV[6]) end
end
return 1
"#;

/// Keeps a solved part (once: a part solved twice counts once); once every part is in,
/// returns them all (to whoever stores a part then, so that a process that died while
/// assembling is replaced by the next delivery).
const PART_DONE: &str = r#"
local current = redis.call('HGET', KEYS[1], 'status')
if current ~= 'queued' and current ~= 'running' then return false end
if redis.call('HSETNX', KEYS[3], ARGV[1], ARGV[2]) == 1 then
  redis.call('HINCRBY', KEYS[1], 'parts_done', 1)
  redis.call('HINCRBY', KEYS[1], 'done', ARGV[3])
  if current == 'queued' then redis.call('HSET', KEYS[1], 'status', 'running') end
end
local parts = tonumber(redis.call('HGET', KEYS[1], 'parts'))
if tonumber(redis.call('HGET', KEYS[1], 'parts_done')) < parts then return false end
return redis.call('HGETALL', KEYS[3])
"#;

/// A job as a worker needs it.
pub struct Runnable {
    pub status: JobStatus,
    /// The job as [`crate::job::Job::to_wire`] wrote it.
    pub wire: String,
    pub key: String,
    pub deadline: Instant,
    pub parts: usize,
}

/// The records of the fleet's jobs.
pub struct RedisJobStore {
    fleet: Arc<Fleet>,
    retention: Duration,
    update: Script,
    part_done: Script,
}

impl RedisJobStore {
    pub fn new(fleet: Arc<Fleet>, retention: Duration) -> RedisJobStore {
        RedisJobStore {
            fleet,
            retention,
            update: Script::new(UPDATE),
            part_done: Script::new(PART_DONE),
        }
    }

    /// Records `record` (queued) and puts its work on the stream, one entry per range of
    /// `parts` (one entry for a job solved whole), in one transaction: a job is accepted
    /// with its work or not at all.
    pub async fn enqueue(
        &self,
        record: &JobRecord,
        wire: &str,
        key: &str,
        deadline: SystemTime,
        parts: &[Range<usize>],
    ) -> Result<(), Failure> {
        let job = keys::job(record.id);
        let id = record.id.to_string();
        let mut pipe = redis::pipe();
        // Borrowed where they can be: the job's text may be long (a fit's data).
        let (work, deadline) = (work_text(record.work), unix_millis(deadline).to_string());
        let count = parts.len().max(1).to_string();
        let fields: [(&str, &str); 9] = [
            ("kind", record.kind.name()),
            ("work", &work),
            ("status", JobStatus::Queued.as_str()),
            ("done", "0"),
            ("job", wire),
            ("key", key),
            ("deadline", &deadline),
            ("parts", &count),
            ("parts_done", "0"),
        ];
        pipe.atomic().hset_multiple(&job.record, &fields).ignore();
        if parts.is_empty() {
            pipe.xadd(keys::STREAM, "*", &[("job", &id)]).ignore();
        }
        for (index, range) in parts.iter().enumerate() {
            let (part, start, end) = (
                index.to_string(),
                range.start.to_string(),
                range.end.to_string(),
            );
            let entry: [(&str, &str); 4] = [
                ("job", &id),
                ("part", &part),
                ("start", &start),
                ("end", &end),
            ];
            pipe.xadd(keys::STREAM, "*", &entry).ignore();
        }
        self.fleet.jobs.pipe::<()>(&pipe).await
    }

    /// The status of job `id`; `None` if it is gone (deleted or expired). A running part's
    /// heartbeat asks it five times a second, so it reads that one field only.
    pub async fn status(&self, id: Uuid) -> Result<Option<JobStatus>, Failure> {
        let cmd = Cmd::hget(keys::job(id).record, "status");
        let status: Option<String> = self.fleet.jobs.query(&cmd).await?;
        Ok(status.as_deref().map(parse_status))
    }

    /// The job `id` as a worker runs it; `None` if it is gone (deleted or expired).
    pub async fn runnable(&self, id: Uuid) -> Result<Option<Runnable>, Failure> {
        let fields = ["status", "job", "key", "deadline", "parts"];
        let cmd = Cmd::hmget(keys::job(id).record, &fields[..]);
        type Fields = (
            Option<String>,
            Option<String>,
            Option<String>,
            Option<u64>,
            Option<usize>,
        );
        let fields: Fields = self.fleet.jobs.query(&cmd).await?;
        let (Some(status), Some(wire), Some(key), Some(deadline), Some(parts)) = fields else {
            return Ok(None);
        };
        Ok(Some(Runnable {
            status: parse_status(&status),
            wire,
            key,
            deadline: instant_of(deadline),
            parts,
        }))
    }

    /// Counts a delivery of part `part` of job `id`; returns the deliveries so far.
    pub async fn delivered(&self, id: Uuid, part: &str) -> Result<u64, Failure> {
        let cmd = Cmd::hincr(keys::job(id).deliveries, part, 1);
        self.fleet.jobs.query(&cmd).await
    }

    /// Keeps part `index` (of `points` points) of job `id`; once every part is in, returns
    /// them all, in order.
    pub async fn part_done(
        &self,
        id: Uuid,
        index: usize,
        part: &RenderedPart,
        points: usize,
    ) -> Result<Option<Vec<RenderedPart>>, Failure> {
        let job = keys::job(id);
        let text = serde_json::to_string(part).expect("a rendered part is JSON");
        let index_text = index.to_string();
        let points_text = points.to_string();
        let all: Option<Vec<(usize, String)>> = self
            .fleet
            .jobs
            .script(
                &self.part_done,
                &job.all(),
                &[
                    index_text.as_bytes(),
                    text.as_bytes(),
                    points_text.as_bytes(),
                ],
            )
            .await?;
        let Some(mut all) = all else {
            return Ok(None);
        };
        all.sort_by_key(|(i, _)| *i);
        let parts = all
            .into_iter()
            .map(|(_, text)| serde_json::from_str(&text))
            .collect::<Result<Vec<RenderedPart>, _>>()
            .map_err(|e| Failure::new(format!("a stored part is unreadable: {e}")))?;
        Ok(Some(parts))
    }

    /// Moves job `id` to `state` with `done` units done (`None`: as counted so far), unless
    /// it has finished.
    pub async fn set_state(
        &self,
        id: Uuid,
        state: &JobState,
        done: Option<usize>,
    ) -> Result<(), Failure> {
        let job = keys::job(id);
        let error = match state {
            JobState::Failed { error, .. } => {
                serde_json::to_vec(error).expect("a job error is JSON")
            }
            _ => Vec::new(),
        };
        let (json, csv) = match state.result() {
            Some(result) => result
                .bodies()
                .await
                .map_err(|e| Failure::new(format!("cannot render the result: {e}")))?,
            None => (Bytes::new(), Bytes::new()),
        };
        let status = state.status().as_str();
        let done = done.map(|n| n.to_string()).unwrap_or_default();
        let retention = millis(self.retention).to_string();
        let now = unix_millis(SystemTime::now()).to_string();
        self.fleet
            .jobs
            .script::<i64>(
                &self.update,
                &job.all(),
                &[
                    status.as_bytes(),
                    done.as_bytes(),
                    &error,
                    &json,
                    &csv,
                    retention.as_bytes(),
                    now.as_bytes(),
                ],
            )
            .await
            .map(drop)
    }

    /// The record of job `id`; `None` if unknown or expired.
    pub async fn record(&self, id: Uuid) -> Result<Option<JobRecord>, Failure> {
        let job = keys::job(id);
        let mut pipe = redis::pipe();
        pipe.hgetall(&job.record)
            .hmget(&job.result, &["json", "csv"][..]);
        type Fields = (HashMap<String, Vec<u8>>, (Option<Vec<u8>>, Option<Vec<u8>>));
        let (fields, (json, csv)): Fields = self.fleet.jobs.pipe(&pipe).await?;
        if fields.is_empty() {
            return Ok(None);
        }
        let text = |name: &str| {
            fields
                .get(name)
                .map(|v| String::from_utf8_lossy(v).into_owned())
                .unwrap_or_default()
        };
        let kind = KindName::find(&text("kind"))
            .map_err(|e| Failure::new(format!("a stored job is unreadable: {e}")))?;
        let work = text("work").parse().map_or(Work::Unknown, Work::Known);
        // A result of a cancelled or failed job is what it finished before it stopped.
        let result = |complete: bool| match (&json, &csv) {
            (Some(json), Some(csv)) => {
                let mut solved = Solved::rendered(
                    text("key"),
                    kind,
                    Bytes::from(json.clone()),
                    Bytes::from(csv.clone()),
                );
                solved.complete = complete;
                Some(JobResult::Ready(Arc::new(solved)))
            }
            _ => None,
        };
        let state = match parse_status(&text("status")) {
            JobStatus::Queued => JobState::Queued,
            JobStatus::Running => JobState::Running,
            JobStatus::Cancelled => JobState::Cancelled {
                partial: result(false),
            },
            JobStatus::Interrupted => JobState::Interrupted,
            JobStatus::Failed => JobState::Failed {
                error: serde_json::from_slice(fields.get("error").map_or(&[][..], Vec::as_slice))
                    .unwrap_or_else(|e| {
                        JobError::Internal(format!("the job's error is unreadable: {e}"))
                    }),
                partial: result(false),
            },
            JobStatus::Succeeded => match result(true) {
                Some(result) => JobState::Succeeded(result),
                None => JobState::failed(JobError::Internal(
                    "the job's result was lost from the job store".to_string(),
                )),
            },
        };
        let finished_at = text("finished_at").parse().ok().map(instant_of);
        Ok(Some(JobRecord {
            id,
            kind,
            work,
            state,
            done: text("done").parse().unwrap_or(0),
            finished_at,
        }))
    }
}

#[async_trait]
impl JobStore for RedisJobStore {
    /// The results are kept in Redis, whose memory bounds them (its `maxmemory`): no room
    /// is made here.
    async fn insert(&self, record: JobRecord, _result_bytes: u64) -> Result<(), Refusal> {
        let fields = [
            ("kind", record.kind.name().to_string()),
            ("work", work_text(record.work)),
            ("status", record.state.status().as_str().to_string()),
            ("done", record.done.to_string()),
            ("parts", "1".to_string()),
            ("parts_done", "0".to_string()),
        ];
        let cmd = Cmd::hset_multiple(keys::job(record.id).record, &fields);
        if let Err(e) = self.fleet.jobs.query::<()>(&cmd).await {
            tracing::warn!(error = %e, id = %record.id, "a job record was not stored");
        }
        Ok(())
    }

    async fn get(&self, id: Uuid) -> Option<JobRecord> {
        self.record(id).await.ok().flatten()
    }

    async fn update(&self, id: Uuid, state: JobState, done: usize) {
        if let Err(e) = self.set_state(id, &state, Some(done)).await {
            tracing::warn!(error = %e, %id, "a job's state was not stored");
        }
    }

    async fn remove(&self, id: Uuid) {
        let cmd = Cmd::del(&keys::job(id).all()[..]);
        let _ = self.fleet.jobs.query::<i64>(&cmd).await;
    }

    /// Redis forgets expired jobs by itself.
    async fn purge_expired(&self) -> usize {
        0
    }

    fn shared(&self) -> bool {
        true
    }
}

fn work_text(work: Work) -> String {
    match work {
        Work::Known(n) => n.to_string(),
        Work::Unknown => String::new(),
    }
}

fn parse_status(text: &str) -> JobStatus {
    [
        JobStatus::Queued,
        JobStatus::Running,
        JobStatus::Succeeded,
        JobStatus::Failed,
        JobStatus::Cancelled,
        JobStatus::Interrupted,
    ]
    .into_iter()
    .find(|s| s.as_str() == text)
    .unwrap_or(JobStatus::Failed)
}

fn unix_millis(time: SystemTime) -> u64 {
    millis(time.duration_since(UNIX_EPOCH).unwrap_or_default())
}

/// The instant of this process at the Unix time `unix_ms` (clocks of the fleet's machines
/// are assumed in step, as NTP keeps them).
fn instant_of(unix_ms: u64) -> Instant {
    let now = unix_millis(SystemTime::now());
    let nowi = Instant::now();
    if unix_ms >= now {
        nowi + Duration::from_millis(unix_ms - now)
    } else {
        nowi.checked_sub(Duration::from_millis(now - unix_ms))
            .unwrap_or(nowi)
    }
}
