//! Job records in Redis, so that every process answers for every job: a hash per job, its
//! result, and the parts of a split job as they are solved. A finished state is final (a
//! late worker cannot overwrite a cancel) and starts the retention of every key of the job.

use std::collections::HashMap;
use std::ops::Range;
use std::sync::Arc;
use std::time::{Duration, Instant, SystemTime};

use async_trait::async_trait;
use bytes::Bytes;
use redis::{Cmd, Pipeline};
use uuid::Uuid;

use super::keys::{GROUP, STREAM};
use super::link::{eval, DELETE_IF_HELD};
use super::{keys, Failure, Fleet};
use crate::engine::clock::{age, from_unix_millis, millis, unix_millis};
use crate::engine::store::{
    JobRecord, JobResult, JobState, JobStatus, JobStore, Listing, Owner, Page, Refusal,
    ResultPlace, StoredResult, Unreadable,
};
use crate::job::parts::RenderedPart;
use crate::job::registry::KindName;
use crate::job::{JobError, Work};

/// Moves a job to a new state unless it has finished. A finished state takes the result
/// staged beside the record (so that its bytes never pass through ARGV), drops the parts and
/// starts every key's retention; a success becomes its input's newest answer.
///
/// KEYS: record, result, parts, deliveries, staged result, the input's pointer. ARGV:
/// status, done, error, retention (ms), now (Unix ms), whether a staged result is whole
/// (`whole`/`partial`), its cache key, and the job's id.
const UPDATE: &str = r#"
local current = redis.call('HGET', KEYS[1], 'status')
if current ~= 'queued' and current ~= 'running' then
  redis.call('DEL', KEYS[5])
  return 0
end
redis.call('HSET', KEYS[1], 'status', ARGV[1])
if ARGV[2] ~= '' then redis.call('HSET', KEYS[1], 'done', ARGV[2]) end
if ARGV[3] ~= '' then redis.call('HSET', KEYS[1], 'error', ARGV[3]) end
if ARGV[1] ~= 'queued' and ARGV[1] ~= 'running' then
  if redis.call('EXISTS', KEYS[5]) == 1 then
    redis.call('RENAME', KEYS[5], KEYS[2])
    redis.call('HSET', KEYS[1], 'result', ARGV[6], 'key', ARGV[7])
  end
  redis.call('HSET', KEYS[1], 'finished_at', ARGV[5])
  -- The job's text (a fit's data may be long) is for its workers only: not kept for days.
  redis.call('HDEL', KEYS[1], 'job')
  redis.call('DEL', KEYS[3])
  for i = 1, 4 do redis.call('PEXPIRE', KEYS[i], ARGV[4]) end
  if ARGV[1] == 'succeeded' and ARGV[7] ~= '' then
    redis.call('SET', KEYS[6], ARGV[8], 'PX', ARGV[4])
  end
end
return 1
"#;

/// Counts a part just stored, once, and acknowledges its entry unless the job is now whole
/// (pending until the job is stored, a process dying while assembling it is replaced).
/// Returns 1 once every part is in, 0 before, -1 if the job has finished or is gone.
///
/// KEYS: record, parts, stream. ARGV: part index, its points, the Unix ms at which the parts
/// expire, the stream's group, the entry's id.
const PART_IN: &str = r#"
local function acknowledge()
  redis.call('XACK', KEYS[3], ARGV[4], ARGV[5])
  redis.call('XDEL', KEYS[3], ARGV[5])
end
local current = redis.call('HGET', KEYS[1], 'status')
if current ~= 'queued' and current ~= 'running' then
  redis.call('DEL', KEYS[2])
  acknowledge()
  return -1
end
redis.call('PEXPIREAT', KEYS[2], ARGV[3])
if redis.call('HSETNX', KEYS[2], 'in:' .. ARGV[1], '1') == 1 then
  redis.call('HINCRBY', KEYS[1], 'parts_done', 1)
  redis.call('HINCRBY', KEYS[1], 'done', ARGV[2])
  if current == 'queued' then redis.call('HSET', KEYS[1], 'status', 'running') end
end
local parts = tonumber(redis.call('HGET', KEYS[1], 'parts'))
if tonumber(redis.call('HGET', KEYS[1], 'parts_done')) < parts then
  acknowledge()
  return 0
end
return 1
"#;

/// The most jobs of one owner listed: the newest.
const LISTED: isize = 10_000;

pub struct Runnable {
    pub status: JobStatus,
    /// The job as [`crate::job::Job::to_wire`] wrote it.
    pub wire: String,
    pub key: String,
    pub deadline: Instant,
    /// When every key of the job expires at the latest (Unix ms): deadline plus retention.
    pub expires: u64,
    pub parts: usize,
}

pub struct RedisJobStore {
    fleet: Arc<Fleet>,
    retention: Duration,
    /// The longest a job of this process may be kept: its deadline and its retention.
    lifetime: Duration,
}

impl RedisJobStore {
    pub fn new(fleet: Arc<Fleet>, retention: Duration, deadline: Duration) -> RedisJobStore {
        RedisJobStore {
            fleet,
            retention,
            lifetime: deadline + retention,
        }
    }

    /// Records `record` (queued) and puts its work on the stream, one entry per range of
    /// `parts`, in one transaction: a job is accepted with its work or not at all.
    pub async fn enqueue(
        &self,
        record: &JobRecord,
        wire: &str,
        key: &str,
        deadline: SystemTime,
        parts: &[Range<usize>],
    ) -> Result<(), Failure> {
        let deadline = unix_millis(deadline);
        let (deadline_text, count) = (deadline.to_string(), parts.len().max(1).to_string());
        // Borrowed: the job's text may be long (a fit's data).
        let fields = [
            ("status", JobStatus::Queued.as_str()),
            ("job", wire),
            ("key", key),
            ("deadline", &deadline_text),
            ("parts", &count),
        ];
        let mut pipe = self.new_record(record, &fields);
        pipe.cmd("PEXPIREAT")
            .arg(keys::job(record.id).record)
            .arg(deadline + millis(self.retention))
            .ignore();
        if parts.is_empty() {
            add_entry(&mut pipe, record.id, None);
        }
        for part in parts.iter().enumerate() {
            add_entry(&mut pipe, record.id, Some(part));
        }
        self.fleet.jobs.pipe::<()>(&pipe).await
    }

    /// A transaction writing `record` with `fields` besides those every record has, and its
    /// place in its owner's list, which lives as long as its newest job may.
    fn new_record(&self, record: &JobRecord, fields: &[(&str, &str)]) -> redis::Pipeline {
        let key = keys::job(record.id).record;
        let submitted = unix_millis(record.submitted_at);
        let work = match record.work {
            Work::Known(n) => n.to_string(),
            Work::Unknown => String::new(),
        };
        let submitted_text = submitted.to_string();
        let owner = record.owner.as_ref().map_or("", Owner::as_str);
        let bytes = record.result_bytes.to_string();
        let common = [
            ("kind", record.kind.name()),
            ("work", &work),
            ("done", "0"),
            ("parts_done", "0"),
            ("owner", owner),
            ("submitted", &submitted_text),
            ("bytes", &bytes),
        ];
        let mut pipe = redis::pipe();
        let all = [&common[..], fields].concat();
        pipe.atomic().hset_multiple(&key, &all).ignore();
        if let Some(owner) = &record.owner {
            // Scored in µs (exact in a double until 2255), so that jobs submitted in the same
            // ms keep their order; places of jobs older than a job may be kept are dropped.
            let list = keys::owner(owner.as_str());
            let micros = |t: Duration| u64::try_from(t.as_micros()).unwrap_or(u64::MAX);
            let since_epoch = age(std::time::UNIX_EPOCH, record.submitted_at);
            let (score, oldest) = (
                micros(since_epoch),
                micros(since_epoch.saturating_sub(self.lifetime)),
            );
            pipe.zadd(&list, record.id.to_string(), score)
                .ignore()
                .zrembyscore(&list, "-inf", format!("({oldest}"))
                .ignore()
                .pexpire(&list, millis(self.lifetime) as i64)
                .ignore();
        }
        pipe
    }

    /// The status of job `id`; `None` if it is gone. A part's heartbeat asks it five times a
    /// second, so it reads that one field only.
    pub async fn status(&self, id: Uuid) -> Result<Option<JobStatus>, Failure> {
        let cmd = Cmd::hget(keys::job(id).record, "status");
        let status: Option<String> = self.fleet.jobs.query(&cmd).await?;
        Ok(status.as_deref().map(parse_status))
    }

    /// Takes part `part` of job `id` for a worker: the job (`None` if it is gone) and the
    /// part's deliveries, counting this one.
    pub async fn take(&self, id: Uuid, part: &str) -> Result<(Option<Runnable>, u64), Failure> {
        let keys = keys::job(id);
        let fields = ["status", "job", "key", "deadline", "parts"];
        let mut pipe = redis::pipe();
        pipe.hmget(&keys.record, &fields[..])
            .hincr(&keys.deliveries, part, 1)
            // As long as a job of this process may be kept; a job's end sets its retention.
            .pexpire(&keys.deliveries, millis(self.lifetime) as i64)
            .ignore();
        type Text = Option<String>;
        type Fields = (Text, Text, Text, Option<u64>, Option<usize>);
        let (fields, deliveries): (Fields, u64) = self.fleet.jobs.pipe(&pipe).await?;
        let (Some(status), Some(wire), Some(key), Some(deadline), Some(parts)) = fields else {
            return Ok((None, deliveries));
        };
        let runnable = Runnable {
            status: parse_status(&status),
            wire,
            key,
            deadline: instant_of(deadline),
            expires: deadline + millis(self.retention),
            parts,
        };
        Ok((Some(runnable), deliveries))
    }

    /// Takes back the delivery of a part handed back unfinished by a drain: a process that
    /// stopped on purpose is not one that died on the part.
    pub async fn undelivered(&self, id: Uuid, part: &str) -> Result<(), Failure> {
        let deliveries = keys::job(id).deliveries;
        let mut pipe = redis::pipe();
        pipe.atomic()
            .hincr(&deliveries, part, -1)
            .ignore()
            // Recreated if the job was deleted meanwhile: it expires all the same.
            .pexpire(&deliveries, millis(self.lifetime) as i64)
            .ignore();
        self.fleet.jobs.pipe::<()>(&pipe).await
    }

    /// Keeps part `index` (of `points` points) of `job` ([`PART_IN`]): whether every part is
    /// in (`None`: the job finished or is gone).
    pub async fn part_done(
        &self,
        id: Uuid,
        job: &Runnable,
        (index, points): (usize, usize),
        part: &RenderedPart,
        entry: &str,
    ) -> Result<Option<bool>, Failure> {
        let keys = keys::job(id);
        let summary = serde_json::to_vec(&part.summary).expect("a summary is JSON");
        let fields: [(String, &[u8]); 3] = [
            (format!("json:{index}"), part.json.as_bytes()),
            (format!("csv:{index}"), part.csv.as_bytes()),
            (format!("summary:{index}"), &summary),
        ];
        let mut pipe = redis::pipe();
        pipe.atomic().hset_multiple(&keys.parts, &fields).ignore();
        eval(&mut pipe, PART_IN, &[&keys.record, &keys.parts, STREAM])
            .arg(index)
            .arg(points)
            .arg(job.expires)
            .arg(GROUP)
            .arg(entry);
        let (all,): (i64,) = self.fleet.jobs.pipe(&pipe).await?;
        Ok((all >= 0).then_some(all == 1))
    }

    /// Every part of job `id` (of `parts`), in order, read once to assemble its answer.
    pub async fn parts(&self, id: Uuid, parts: usize) -> Result<Vec<RenderedPart>, Failure> {
        let cmd = Cmd::hgetall(keys::job(id).parts);
        let mut fields: HashMap<String, Vec<u8>> = self.fleet.jobs.query(&cmd).await?;
        let unreadable =
            |what: String| Failure::new(format!("a stored part is unreadable: {what}"));
        let mut text = |name: String| {
            let bytes = fields
                .remove(&name)
                .ok_or_else(|| unreadable(format!("no {name}")))?;
            String::from_utf8(bytes).map_err(|e| unreadable(e.to_string()))
        };
        (0..parts)
            .map(|i| {
                Ok(RenderedPart {
                    json: text(format!("json:{i}"))?,
                    csv: text(format!("csv:{i}"))?,
                    summary: serde_json::from_str(&text(format!("summary:{i}"))?)
                        .map_err(|e| unreadable(e.to_string()))?,
                })
            })
            .collect()
    }

    /// Moves job `id` to `state` with `done` units done (`None`: as counted), unless it has
    /// finished ([`UPDATE`]); returns whether it moved. A result is written once.
    pub async fn set_state(
        &self,
        id: Uuid,
        state: &JobState,
        done: Option<usize>,
    ) -> Result<bool, Failure> {
        let job = keys::job(id);
        let error = match state {
            JobState::Failed { error, .. } => {
                serde_json::to_vec(error).expect("a job error is JSON")
            }
            _ => Vec::new(),
        };
        let mut pipe = redis::pipe();
        pipe.atomic();
        let (mut whole, mut key) = ("", "");
        if let Some(result) = state
            .result()
            .filter(|r| !matches!(r, JobResult::Stored(_)))
        {
            key = result.key();
            let (json, csv) = result
                .bodies()
                .await
                .map_err(|e| Failure::new(format!("cannot render the result: {e}")))?;
            let fields: [(&str, &[u8]); 2] = [("json", &json), ("csv", &csv)];
            pipe.hset_multiple(&job.staged, &fields).ignore();
            whole = result.form();
        }
        let [record, result, parts, deliveries] = job.all();
        let input = keys::input(key);
        let all = [record, result, parts, deliveries, &job.staged, &input];
        eval(&mut pipe, UPDATE, &all)
            .arg(state.status().as_str())
            .arg(done.map(|n| n.to_string()).unwrap_or_default())
            .arg(error)
            .arg(millis(self.retention))
            .arg(unix_millis(SystemTime::now()))
            .arg(whole)
            .arg(key)
            .arg(id.to_string());
        let (moved,): (i64,) = self.fleet.jobs.pipe(&pipe).await?;
        Ok(moved == 1)
    }

    /// The fields a status needs: not the job's text, which may be long (a fit's data).
    const FIELDS: [&'static str; 12] = [
        "kind",
        "work",
        "status",
        "done",
        "key",
        "result",
        "error",
        "finished_at",
        "owner",
        "submitted",
        "deadline",
        "bytes",
    ];

    /// The record of job `id`, its result left in Redis ([`StoredResult`]); `None` if gone.
    pub async fn record(&self, id: Uuid) -> Result<Option<JobRecord>, Failure> {
        self.records(&[id]).await?.pop().unwrap_or(Ok(None))
    }

    /// The records of jobs `ids`, in one round trip (`None` for those gone).
    async fn records(
        &self,
        ids: &[Uuid],
    ) -> Result<Vec<Result<Option<JobRecord>, Failure>>, Failure> {
        // An empty pipeline is an error to Redis's client ("empty command").
        if ids.is_empty() {
            return Ok(Vec::new());
        }
        let mut pipe = redis::pipe();
        for id in ids {
            pipe.hmget(keys::job(*id).record, &Self::FIELDS[..]);
        }
        let all: Vec<Vec<Option<Vec<u8>>>> = self.fleet.jobs.pipe(&pipe).await?;
        let mut records = Vec::with_capacity(ids.len());
        for (id, values) in ids.iter().zip(all) {
            records.push(self.parse(*id, values).await);
        }
        Ok(records)
    }

    /// The record of job `id` from the values of [`Self::FIELDS`].
    async fn parse(
        &self,
        id: Uuid,
        values: Vec<Option<Vec<u8>>>,
    ) -> Result<Option<JobRecord>, Failure> {
        let fields: HashMap<&str, Vec<u8>> = Self::FIELDS
            .into_iter()
            .zip(values)
            .filter_map(|(name, value)| Some((name, value?)))
            .collect();
        if !fields.contains_key("status") {
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
        let status = parse_status(&text("status"));
        let form = match fields.get("result") {
            Some(form) => String::from_utf8_lossy(form).into_owned(),
            // A record of the version before `result` was kept: its result hash tells.
            None if status.is_finished() => {
                let cmd = Cmd::hexists(keys::job(id).result, "json");
                let stored: bool = self.fleet.jobs.query(&cmd).await?;
                let form = match (stored, status) {
                    (false, _) => "",
                    (true, JobStatus::Succeeded) => "whole",
                    (true, _) => "partial",
                };
                form.to_string()
            }
            None => String::new(),
        };
        // A result of a cancelled or failed job is what it finished before it stopped.
        let result = || match form.as_str() {
            form @ ("whole" | "partial") => Some(JobResult::Stored(Arc::new(StoredResult {
                key: text("key"),
                kind,
                complete: form == "whole",
                place: Arc::new(InRedis {
                    fleet: self.fleet.clone(),
                    id,
                }),
            }))),
            _ => None,
        };
        let state = JobState::restored(status, result(), || {
            serde_json::from_slice(fields.get("error").map_or(&[][..], Vec::as_slice))
                .unwrap_or_else(|e| {
                    JobError::Internal(format!("the job's error is unreadable: {e}"))
                })
        });
        let time = |name: &str| text(name).parse().ok().map(from_unix_millis);
        let owner = Some(text("owner")).filter(|o| !o.is_empty());
        Ok(Some(JobRecord {
            id,
            kind,
            work,
            state,
            done: text("done").parse().unwrap_or(0),
            input_hash: text("key"),
            owner: owner.map(Owner::stored),
            // A record of the version before submissions were timed: its deadline orders it.
            submitted_at: time("submitted")
                .or_else(|| time("deadline"))
                .unwrap_or(std::time::UNIX_EPOCH),
            finished_at: time("finished_at"),
            // A record of the version before results were bounded: nothing counted.
            result_bytes: text("bytes").parse().unwrap_or(0),
            unsaved: false,
        }))
    }
}

/// A finished job's result, left in Redis.
struct InRedis {
    fleet: Arc<Fleet>,
    id: Uuid,
}

#[async_trait]
impl ResultPlace for InRedis {
    async fn body(&self, field: &str) -> std::io::Result<Bytes> {
        let cmd = Cmd::hget(keys::job(self.id).result, field);
        let lost = "the job's result expired, or was lost from the job store";
        match self.fleet.jobs.query::<Option<Vec<u8>>>(&cmd).await {
            Ok(body) => body
                .map(Bytes::from)
                .ok_or_else(|| std::io::Error::other(lost)),
            Err(e) => Err(std::io::Error::other(e.why)),
        }
    }
}

#[async_trait]
impl JobStore for RedisJobStore {
    /// The results are kept in Redis, whose `maxmemory` bounds them: no room is made here.
    async fn insert(&self, record: JobRecord) -> Result<(), Refusal> {
        let fields = [
            ("status", record.state.status().as_str()),
            ("key", &record.input_hash),
            ("parts", "1"),
        ];
        let mut pipe = self.new_record(&record, &fields);
        pipe.pexpire(keys::job(record.id).record, millis(self.lifetime) as i64)
            .ignore();
        if let Err(e) = self.fleet.jobs.pipe::<()>(&pipe).await {
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

    /// Forgets the job's keys, its place in its owner's list, and its input's pointer to it.
    async fn remove(&self, id: Uuid) {
        let (job, jobs) = (keys::job(id), &self.fleet.jobs);
        let removed = async {
            let (owner, input): (Option<String>, Option<String>) = jobs
                .query(&Cmd::hmget(&job.record, &["owner", "key"][..]))
                .await?;
            let id_text = id.to_string();
            let mut pipe = redis::pipe();
            pipe.atomic().del(&job.all()[..]).ignore();
            if let Some(owner) = owner.filter(|o| !o.is_empty()) {
                pipe.zrem(keys::owner(&owner), &id_text).ignore();
            }
            if let Some(input) = input {
                // Unless the input's pointer points to another job since.
                eval(&mut pipe, DELETE_IF_HELD, &[&keys::input(&input)])
                    .arg(&id_text)
                    .ignore();
            }
            jobs.pipe::<()>(&pipe).await
        };
        if let Err(e) = removed.await {
            tracing::warn!(error = %e, %id, "a job was not deleted");
        }
    }

    async fn purge_expired(&self) -> usize {
        0
    }

    /// Reads every job in the owner's list (the newest [`LISTED`]), so that the filters and
    /// the total are exact; jobs expired since are dropped from the list.
    async fn list(&self, listing: &Listing) -> Result<Page, Unreadable> {
        let list = keys::owner(listing.owner.as_str());
        let ids: Vec<String> = self
            .fleet
            .jobs
            .query(&Cmd::zrevrange(&list, 0, LISTED - 1))
            .await?;
        let ids: Vec<Uuid> = ids.iter().filter_map(|id| id.parse().ok()).collect();
        let (mut matching, mut gone) = (Vec::new(), Vec::new());
        for (id, record) in ids.iter().zip(self.records(&ids).await?) {
            match record {
                Ok(Some(record)) if record.listed_in(listing) => matching.push(record),
                Ok(Some(_)) => {}
                Ok(None) => gone.push(id.to_string()),
                // One this version cannot read (another version's kind) is left out, not fatal.
                Err(e) => tracing::warn!(error = %e, %id, "a listed job is unreadable"),
            }
        }
        if !gone.is_empty() {
            let _ = self.fleet.jobs.query::<i64>(&Cmd::zrem(&list, gone)).await;
        }
        Ok(Page::of(matching, listing))
    }

    async fn with_input(&self, input_hash: &str) -> Result<Option<JobRecord>, Unreadable> {
        let cmd = Cmd::get(keys::input(input_hash));
        let id: Option<String> = self.fleet.jobs.query(&cmd).await?;
        let Some(id) = id.and_then(|id| id.parse().ok()) else {
            return Ok(None);
        };
        Ok(self
            .record(id)
            .await?
            .filter(|r| matches!(r.state, JobState::Succeeded(_))))
    }

    fn shared(&self) -> bool {
        true
    }

    fn durable(&self) -> bool {
        true
    }
}

/// The status stored as `text`; failed for one this version does not know.
fn parse_status(text: &str) -> JobStatus {
    JobStatus::parse(text).unwrap_or(JobStatus::Failed)
}

/// The instant of this process at the Unix time `unix_ms` (clocks are in step, by NTP).
fn instant_of(unix_ms: u64) -> Instant {
    let (now, instant) = (unix_millis(SystemTime::now()), Instant::now());
    let later = instant + Duration::from_millis(unix_ms.saturating_sub(now));
    later
        .checked_sub(Duration::from_millis(now.saturating_sub(unix_ms)))
        .unwrap_or(instant)
}

impl From<Failure> for Unreadable {
    fn from(e: Failure) -> Unreadable {
        Unreadable::Redis(e.why)
    }
}

/// Adds to `pipe` a stream entry for `job` or its part (index and points): [`super::worker`]'s `Entry::read`.
pub(super) fn add_entry(pipe: &mut Pipeline, job: Uuid, part: Option<(usize, &Range<usize>)>) {
    let mut fields = vec![("job", job.to_string())];
    if let Some((index, range)) = part {
        fields.push(("part", index.to_string()));
        fields.push(("start", range.start.to_string()));
        fields.push(("end", range.end.to_string()));
    }
    pipe.xadd(keys::STREAM, "*", &fields).ignore();
}
