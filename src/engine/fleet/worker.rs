//! The fleet's workers: each takes one entry of the work stream at a time (a job, or a range
//! of a sweep's points), solves it, stores the result, and only then acknowledges the entry,
//! kept its own by a heartbeat meanwhile. An entry whose process died is taken over
//! (`XAUTOCLAIM`); one delivered more than `max_deliveries` times fails its job.

use std::collections::HashMap;
use std::ops::Range;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use futures_util::future::OptionFuture;
use redis::streams::{
    StreamAutoClaimOptions, StreamAutoClaimReply, StreamClaimOptions, StreamId, StreamReadOptions,
    StreamReadReply,
};
use redis::{Cmd, Pipeline, Value};
use tokio::sync::Semaphore;
use tokio_util::sync::CancellationToken;
use tokio_util::task::AbortOnDropHandle;
use uuid::Uuid;

use super::store::{self, RedisJobStore, Runnable};
use super::{keys, placement, Failure, Fleet, Link};
use crate::engine::cache::Solved;
use crate::engine::lock;
use crate::engine::metrics as names;
use crate::engine::pool::Pool;
use crate::engine::solver::Solver;
use crate::engine::store::{JobResult, JobState, JobStatus};
use crate::job::parts::{self, RenderedPart};
use crate::job::{tenant_of, Control, Job, JobError, Keyed, Unfinished, Work};

/// How long a worker's read of the stream waits for an entry (well within a call's bound).
const WAIT: Duration = Duration::from_millis(250);
/// How often a running entry's heartbeat looks for a cancel and counts progress.
const HEARTBEAT: Duration = Duration::from_millis(200);

/// What an engine in a fleet holds, and the entries it is solving (for a late drain to stop).
pub struct Shared {
    pub fleet: Arc<Fleet>,
    pub store: Arc<RedisJobStore>,
    running: Mutex<HashMap<String, Arc<Control>>>,
    /// Seconds per point of each cost class, as this process measured them.
    rates: Mutex<HashMap<&'static str, f64>>,
}

impl Shared {
    pub fn new(fleet: Arc<Fleet>, store: Arc<RedisJobStore>) -> Shared {
        Shared {
            fleet,
            store,
            running: Mutex::default(),
            rates: Mutex::default(),
        }
    }

    /// Learns the cost per point of `class`, and tells the fleet, which splits jobs by it.
    async fn learn(&self, class: &'static str, took: Duration, points: usize) {
        let rate = {
            let mut rates = lock(&self.rates);
            let rate = placement::learn(rates.get(class).copied(), took, points);
            rates.insert(class, rate);
            rate
        };
        let mut pipe = redis::pipe();
        pipe.hset(keys::RATES, class, rate)
            .ignore()
            .pexpire(keys::RATES, placement::RATE_TTL.as_millis() as i64)
            .ignore();
        if let Err(e) = self.fleet.jobs.pipe::<()>(&pipe).await {
            tracing::debug!(error = %e, "a measured rate was not shared");
        }
    }

    /// The entries on the stream not yet finished, and the fleet's cost per point of `class`.
    pub async fn backlog_and_rate(&self, class: &str) -> Result<(usize, Option<f64>), Failure> {
        let mut pipe = redis::pipe();
        pipe.xlen(keys::STREAM).hget(keys::RATES, class);
        self.fleet.jobs.pipe(&pipe).await
    }

    /// Stops every entry this process is solving; unacknowledged, another process takes them.
    pub fn interrupt(&self) {
        for control in lock(&self.running).values() {
            control.cancel();
        }
    }
}

#[derive(Clone)]
struct Entry {
    /// The stream entry's id.
    id: String,
    job: Uuid,
    /// The part (index and points), or `None` for a job solved whole.
    part: Option<(usize, Range<usize>)>,
}

impl Entry {
    fn read(entry: &StreamId) -> Option<Entry> {
        let number = |name: &str| entry.get::<usize>(name);
        let part = || Some((number("part")?, number("start")?..number("end")?));
        Some(Entry {
            id: entry.id.clone(),
            job: entry.get::<String>("job")?.parse().ok()?,
            part: part(),
        })
    }

    /// The part's name among the job's deliveries.
    fn part_name(&self) -> String {
        self.part
            .as_ref()
            .map_or_else(|| "whole".to_string(), |(i, _)| i.to_string())
    }
}

enum Outcome {
    Whole(Arc<Solved>),
    /// A job solved whole that stopped before its end, and what it finished.
    Stopped(JobError, Arc<Solved>),
    Part(RenderedPart),
}

/// One worker of the fleet's stream: the solve path, the fleet, the job slots it shares with
/// synchronous requests (if any), and the drain's signal, at which it stops taking entries.
pub struct Worker {
    pub solver: Arc<Solver>,
    pub shared: Arc<Shared>,
    pub slots: Option<Arc<Semaphore>>,
    pub draining: CancellationToken,
}

impl Worker {
    pub async fn run(self) {
        let mut looked_for_orphans = Instant::now();
        let waiting = match self.shared.fleet.jobs.dedicated() {
            Ok(link) => link,
            Err(e) => return tracing::error!(error = %e, "a worker cannot reach Redis"),
        };
        while !self.draining.is_cancelled() {
            let slot = OptionFuture::from(self.slots.clone().map(Semaphore::acquire_owned)).await;
            match next_entry(&self.shared.fleet, &waiting, &mut looked_for_orphans).await {
                Ok(Some(entry)) => self.process(entry).await,
                Ok(None) => {}
                Err(e) => {
                    tracing::debug!(error = %e, "no work from Redis");
                    tokio::time::sleep(super::link::RETRY_EVERY).await;
                }
            }
            drop(slot);
        }
    }

    /// Solves `entry` and stores its result; acknowledges it unless it should run again.
    async fn process(&self, entry: Entry) {
        let (shared, id) = (&self.shared, entry.job);
        let Some((runnable, keyed, deliveries)) = self.take(&entry).await else {
            return;
        };
        let control = Arc::new(self.solver.control(runnable.deadline));
        lock(&shared.running).insert(entry.id.clone(), control.clone());
        // Kept through assembly: the last part's entry stays pending until its job is stored.
        let beat = heartbeat(shared.clone(), entry.clone(), control.clone());
        let _heartbeat = AbortOnDropHandle::new(tokio::spawn(beat));
        tracing::info!(entry = entry.id, job = %id, part = entry.part_name(), deliveries, "solving a part");
        if runnable.status == JobStatus::Queued {
            let _ = shared.store.set_state(id, &JobState::Running, None).await;
        }
        let started = Instant::now();
        let result = self.solve(&entry, &keyed, &control).await;
        lock(&shared.running).remove(&entry.id);
        self.count(&entry, &keyed, &result, started.elapsed());
        self.settle(&entry, &keyed, &runnable, &control, result)
            .await;
    }

    /// The job of `entry` and the entry's deliveries; `None` if the job is gone or finished
    /// (the entry acknowledged), Redis is away (taken over later), or it was failed here.
    async fn take(&self, entry: &Entry) -> Option<(Runnable, Keyed, u64)> {
        let shared = &self.shared;
        let (runnable, deliveries) = match shared.store.take(entry.job, &entry.part_name()).await {
            Ok((Some(r), deliveries)) if !r.status.is_finished() => (r, deliveries),
            Ok(_) => {
                acknowledge(&shared.fleet, entry).await;
                return None;
            }
            Err(_) => return None,
        };
        if deliveries > 1 {
            self.solver
                .metrics()
                .counter(names::REDELIVERIES, &[])
                .increment(1);
        }
        let runs = || {
            if deliveries > u64::from(shared.fleet.config.max_deliveries) {
                let times = match deliveries - 1 {
                    1 => "once".to_string(),
                    n => format!("{n} times"),
                };
                return Err(JobError::Abandoned(format!(
                    "part {} of the job was delivered {times} and every worker that took it \
                     stopped before finishing it (killed, or out of memory): the job is given up",
                    entry.part_name(),
                )));
            }
            // Kept among its tenant's answers, as it was accepted ([`Keyed::scoped`]).
            let keyed = Job::from_wire(&runnable.wire)?
                .keyed()
                .scoped(tenant_of(&runnable.key));
            if keyed.key() != runnable.key {
                return Err(JobError::Internal(
                    "the job read back from the job store is not the job accepted".to_string(),
                ));
            }
            Ok(keyed)
        };
        match runs() {
            Ok(keyed) => Some((runnable, keyed, deliveries)),
            Err(error) => {
                self.finish(entry, JobState::failed(error), None).await;
                None
            }
        }
    }

    /// Solves `entry`'s part (or the whole job) on a solver thread, the CSV rendered there too.
    async fn solve(
        &self,
        entry: &Entry,
        keyed: &Keyed,
        control: &Arc<Control>,
    ) -> Result<Outcome, JobError> {
        let permit = self.solver.pool.acquire(keyed.job().cost().bytes).await;
        let _running = self.solver.running();
        let part = entry.part.clone();
        let (solving, meta, key) = keyed.clone().into_parts();
        let kind = solving.kind();
        let kept = |solved: Solved| {
            solved
                .kept()
                .map(Arc::new)
                .map_err(|e| JobError::Internal(format!("cannot render the answer: {e}")))
        };
        Pool::run(permit, control.clone(), move |control| match part {
            None => match solving.run_keeping(meta, control) {
                Ok(answer) => Ok(Outcome::Whole(kept(Solved::new(key, kind, answer)?)?)),
                // What a job past its deadline finished is kept with its failure.
                Err(Unfinished {
                    error: error @ JobError::DeadlineExceeded,
                    partial: Some(answer),
                }) => Ok(Outcome::Stopped(
                    error,
                    kept(Solved::partial(key, kind, answer)?)?,
                )),
                Err(unfinished) => Err(unfinished.error),
            },
            Some((_, range)) => Ok(Outcome::Part(parts::render(
                &solving.run_points(meta, range, control)?,
            )?)),
        })
        .await
    }

    /// Counts the part's outcome, and tells the fleet what a point of its kind cost.
    fn count(
        &self,
        entry: &Entry,
        keyed: &Keyed,
        result: &Result<Outcome, JobError>,
        took: Duration,
    ) {
        let outcome = match result {
            Ok(_) => "succeeded",
            Err(JobError::Cancelled) => "cancelled",
            Err(_) => "failed",
        };
        self.solver
            .metrics()
            .counter(names::PARTS, &[("outcome", outcome)])
            .increment(1);
        if result.is_ok() {
            let points = match &entry.part {
                Some((_, range)) => range.len(),
                None => keyed.job().points().unwrap_or(1),
            };
            let (shared, class) = (self.shared.clone(), keyed.job().cost_class());
            tokio::spawn(async move { shared.learn(class, took, points).await });
        }
    }

    /// Stores the job's end, or its part (and the job once every part is in); a part the
    /// drain stopped is handed back.
    async fn settle(
        &self,
        entry: &Entry,
        keyed: &Keyed,
        runnable: &Runnable,
        control: &Control,
        result: Result<Outcome, JobError>,
    ) {
        let shared = &self.shared;
        match result {
            Ok(Outcome::Whole(solved)) => self.succeed(entry, keyed, solved, control.done()).await,
            Ok(Outcome::Stopped(error, partial)) => {
                let state = JobState::Failed {
                    error,
                    partial: Some(JobResult::Ready(partial)),
                };
                self.finish(entry, state, Some(control.done())).await;
            }
            Ok(Outcome::Part(rendered)) => {
                let part = entry.part.as_ref().map_or((0, 0), |(i, r)| (*i, r.len()));
                let stored = shared
                    .store
                    .part_done(entry.job, runnable, part, &rendered, &entry.id);
                // Acknowledged with the part, unless it was the last: then once assembled.
                if let Ok(Some(true)) = stored.await {
                    self.assemble(entry, keyed, runnable).await;
                }
            }
            // Stopped by the drain: handed back at once, its delivery not counted.
            Err(JobError::Cancelled) if self.draining.is_cancelled() => {
                hand_back(shared, entry).await
            }
            Err(JobError::Cancelled) => acknowledge(&shared.fleet, entry).await,
            Err(e) => {
                self.finish(entry, JobState::failed(e), Some(control.done()))
                    .await;
            }
        }
    }

    /// Assembles the split job from all its parts and finishes it. A process that dies here
    /// leaves the entry to the next delivery, which finds every part in.
    async fn assemble(&self, entry: &Entry, keyed: &Keyed, runnable: &Runnable) {
        let Ok(all) = self.shared.store.parts(entry.job, runnable.parts).await else {
            return; // taken over later
        };
        match parts::assemble(keyed.meta(), &all) {
            Ok(assembled) => {
                let (json, csv) = (assembled.json.into(), assembled.csv.into());
                let solved = Solved::rendered(keyed.key().into(), keyed.job().kind(), json, csv);
                self.succeed(entry, keyed, Arc::new(solved), runnable.parts)
                    .await;
            }
            Err(e) => {
                self.finish(entry, JobState::failed(e), None).await;
            }
        }
    }

    /// Finishes the job of `entry` with its answer `solved` (its work done, or `counted` if
    /// unknown), then caches it, unless the job had ended otherwise meanwhile.
    async fn succeed(&self, entry: &Entry, keyed: &Keyed, solved: Arc<Solved>, counted: usize) {
        let total = match keyed.job().work() {
            Work::Known(total) => total,
            Work::Unknown => counted,
        };
        let state = JobState::Succeeded(JobResult::Ready(solved.clone()));
        if self.finish(entry, state, Some(total)).await {
            self.solver.cache.insert_result_of(solved, entry.job).await;
        }
    }

    /// Stores the job's final `state`, then acknowledges the entry (unless the state could
    /// not be stored); returns whether the job ended so (not if it ended otherwise first).
    async fn finish(&self, entry: &Entry, state: JobState, done: Option<usize>) -> bool {
        state.log_end(entry.job);
        let shared = &self.shared;
        match shared.store.set_state(entry.job, &state, done).await {
            Ok(moved) => {
                acknowledge(&shared.fleet, entry).await;
                moved
            }
            Err(e) => {
                tracing::warn!(error = %e, job = %entry.job, "a job's end was not stored: it runs again");
                false
            }
        }
    }
}

/// The next entry: one whose worker went silent for the idle bound (looked for every half of
/// it), else a new one, waited for on the worker's own link `waiting`.
async fn next_entry(
    fleet: &Fleet,
    waiting: &Link,
    looked: &mut Instant,
) -> Result<Option<Entry>, Failure> {
    let idle = fleet.config.claim_idle;
    if looked.elapsed() >= idle / 2 {
        let claim = Cmd::xautoclaim_options(
            keys::STREAM,
            keys::GROUP,
            &fleet.consumer,
            crate::engine::clock::millis(idle),
            "0-0",
            StreamAutoClaimOptions::default().count(1),
        );
        match fleet.jobs.query::<StreamAutoClaimReply>(&claim).await {
            Ok(reply) => {
                if let Some(entry) = reply.claimed.first().and_then(Entry::read) {
                    tracing::info!(entry = entry.id, job = %entry.job, "took over an entry");
                    return Ok(Some(entry));
                }
                *looked = Instant::now();
            }
            Err(e) if e.is("NOGROUP") => create_group(fleet).await?,
            Err(e) => return Err(e),
        }
    }
    let read = Cmd::xread_options(
        &[keys::STREAM],
        &[">"],
        &StreamReadOptions::default()
            .group(keys::GROUP, &fleet.consumer)
            .count(1)
            .block(WAIT.as_millis() as usize),
    );
    match waiting.query::<Option<StreamReadReply>>(&read).await {
        Ok(reply) => Ok(reply
            .and_then(|r| r.keys.into_iter().next())
            .and_then(|k| k.ids.first().and_then(Entry::read))),
        Err(e) if e.is("NOGROUP") => create_group(fleet).await.map(|()| None),
        Err(e) => Err(e),
    }
}

/// Creates the stream and its consumer group, once in the fleet.
async fn create_group(fleet: &Fleet) -> Result<(), Failure> {
    let create = Cmd::xgroup_create_mkstream(keys::STREAM, keys::GROUP, "0");
    match fleet.jobs.query::<()>(&create).await {
        Err(e) if !e.is("BUSYGROUP") => Err(e),
        _ => Ok(()),
    }
}

/// Acknowledges `entry` in `pipe`, and deletes it from the stream (whose length is then the
/// backlog).
fn acknowledged<'a>(pipe: &'a mut Pipeline, entry: &Entry) -> &'a mut Pipeline {
    let ids = [&entry.id];
    pipe.xack(keys::STREAM, keys::GROUP, &ids)
        .ignore()
        .xdel(keys::STREAM, &ids)
        .ignore()
}

async fn acknowledge(fleet: &Fleet, entry: &Entry) {
    let mut pipe = redis::pipe();
    if let Err(e) = fleet.jobs.pipe::<()>(acknowledged(&mut pipe, entry)).await {
        tracing::warn!(error = %e, "an entry was not acknowledged: it will run again");
    }
}

/// Hands `entry`, stopped by a drain, back at once: a new entry with the same work replaces
/// it (no wait for the idle bound) and its delivery is taken back; the parts in stay.
async fn hand_back(shared: &Shared, entry: &Entry) {
    let _ = shared
        .store
        .undelivered(entry.job, &entry.part_name())
        .await;
    let mut pipe = redis::pipe();
    acknowledged(pipe.atomic(), entry);
    let part = entry.part.as_ref().map(|(index, range)| (*index, range));
    store::add_entry(&mut pipe, entry.job, part);
    match shared.fleet.jobs.pipe::<()>(&pipe).await {
        Ok(()) => tracing::info!(job = %entry.job, part = entry.part_name(), "handed a part back"),
        Err(e) => tracing::warn!(error = %e, "a part was not handed back: it is taken over later"),
    }
}

/// While an entry runs: keeps it this worker's (well within the idle bound), stops the solver
/// if the job was cancelled or finished elsewhere, and counts a whole job's progress.
async fn heartbeat(shared: Arc<Shared>, entry: Entry, control: Arc<Control>) {
    let (fleet, store, id) = (&shared.fleet, &shared.store, entry.job);
    let keep_every = (fleet.config.claim_idle / 3).max(HEARTBEAT);
    let mut kept = Instant::now();
    loop {
        tokio::time::sleep(HEARTBEAT).await;
        if matches!(store.status(id).await, Ok(s) if s.is_none_or(JobStatus::is_finished)) {
            control.cancel();
        }
        if entry.part.is_none() {
            let _ = store
                .set_state(id, &JobState::Running, Some(control.done()))
                .await;
        }
        if kept.elapsed() >= keep_every {
            let keep = Cmd::xclaim_options(
                keys::STREAM,
                keys::GROUP,
                &fleet.consumer,
                0,
                &[&entry.id],
                StreamClaimOptions::default().with_justid(),
            );
            if fleet.jobs.query::<Value>(&keep).await.is_ok() {
                kept = Instant::now();
            }
        }
    }
}
