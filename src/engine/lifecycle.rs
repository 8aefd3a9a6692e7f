//! The life of asynchronous jobs: their records, the handles of those this process runs,
//! their ids, the drain, and the fleet's work stream. They solve through the [`Solver`].

use std::collections::{HashMap, HashSet, VecDeque};
use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use metrics::Gauge;
use tokio::sync::{watch, Semaphore};
use tokio_util::sync::CancellationToken;
use tokio_util::task::TaskTracker;
use tracing::Instrument;
use uuid::Uuid;

use super::backlog::{Backlog, Ticket};
use super::cache::Solved;
use super::config::EngineConfig;
use super::error::EngineError;
use super::fleet::{placement, Health, Shared, Worker};
use super::ids::{self, JobIds, Unknown};
use super::lock;
use super::metrics::{self as names, Metrics};
use super::solver::{Solver, Stopped};
use super::store::{JobRecord, JobResult, JobState, JobStatus, JobStore, Listing, Owner, Page};
use crate::job::{Control, JobError, Keyed, Work};

/// How long a cancel waits for the job to stop (it checks between units of work, ≤ ms).
const CANCEL_WAIT: Duration = Duration::from_secs(5);

/// The handles of an asynchronous job this process runs: what its record cannot hold.
struct LiveJob {
    control: Arc<Control>,
    /// Wakes a job still waiting for a permit (the solver itself watches `control`).
    cancel: CancellationToken,
    /// Whether the shutdown, not its client, stops it.
    interrupted: AtomicBool,
    status: watch::Sender<JobStatus>,
    /// Whether no tenant owns it (callers without a key share one quota of jobs).
    anonymous: bool,
    /// How long it held a solver thread (ns; 0 until it ran): what it really cost.
    solved_in: AtomicU64,
}

/// Told a job's time on a solver thread when it ends, to true up its quota's estimate.
pub type OnEnd = Box<dyn FnOnce(Duration) + Send>;

impl LiveJob {
    fn cancel(&self) {
        self.cancel.cancel();
        self.control.cancel();
    }

    fn stopped(&self, partial: Option<JobResult>) -> JobState {
        if self.interrupted.load(Ordering::SeqCst) {
            JobState::Interrupted
        } else {
            JobState::Cancelled { partial }
        }
    }
}

/// Finished jobs no client has read finished yet, oldest first.
#[derive(Debug, Default)]
struct Uncollected {
    ids: HashSet<Uuid>,
    order: VecDeque<Uuid>,
}

impl Uncollected {
    /// Adds `id`, giving up the oldest beyond `max` (their clients are long gone).
    fn insert(&mut self, id: Uuid, max: usize) {
        self.ids.insert(id);
        self.order.push_back(id);
        while self.ids.len() > max {
            let Some(old) = self.order.pop_front() else {
                break;
            };
            self.ids.remove(&old);
        }
        // Ids read since are still in `order`: drop them when they outnumber the rest.
        if self.order.len() > 2 * self.ids.len() + 16 {
            let ids = &self.ids;
            self.order.retain(|id| ids.contains(id));
        }
    }
}

/// The asynchronous jobs of an engine.
pub struct Lifecycle {
    config: EngineConfig,
    solver: Arc<Solver>,
    jobs: Arc<dyn JobStore>,
    /// The fleet, if any: jobs then run on its work stream.
    fleet: Option<Arc<Shared>>,
    live: Mutex<HashMap<Uuid, Arc<LiveJob>>>,
    /// At most `max_jobs`, the oldest given up first.
    uncollected: Mutex<Uncollected>,
    /// The jobs unfinished or uncollected when the drain began, until their clients read
    /// them finished ([`Lifecycle::jobs_collected`]).
    owed: Mutex<HashSet<Uuid>>,
    ids: JobIds,
    /// Solver threads jobs may hold at once: all but one, kept for synchronous requests.
    job_slots: Arc<Semaphore>,
    /// The tasks of jobs (and the fleet's workers), waited for on shutdown.
    tracker: TaskTracker,
    /// Cancelled when the drain begins.
    draining: CancellationToken,
    /// Asynchronous jobs waiting for a permit.
    queued: AtomicUsize,
    backlog: Arc<Backlog>,
    jobs_queued: Gauge,
}

impl Lifecycle {
    pub(super) fn new(
        config: EngineConfig,
        metrics: &Metrics,
        solver: Arc<Solver>,
        jobs: Arc<dyn JobStore>,
        fleet: Option<Arc<Shared>>,
    ) -> Lifecycle {
        let job_threads = config.pool_size.saturating_sub(1).max(1);
        Lifecycle {
            solver,
            jobs,
            fleet,
            live: Mutex::default(),
            uncollected: Mutex::default(),
            owed: Mutex::default(),
            ids: JobIds::default(),
            job_slots: Arc::new(Semaphore::new(job_threads)),
            backlog: Backlog::new(job_threads, config.job_deadline),
            tracker: TaskTracker::new(),
            draining: CancellationToken::new(),
            queued: AtomicUsize::new(0),
            jobs_queued: metrics.gauge(names::JOBS_QUEUED, &[]),
            config,
        }
    }

    /// Starts `loops` workers on the fleet's stream (none without a fleet), until the drain.
    /// With `share_with_requests` (a process that also serves HTTP) they take the job slots,
    /// so that a synchronous request always finds a solver thread.
    pub fn start_workers(&self, loops: usize, share_with_requests: bool) {
        let Some(shared) = self.fleet.clone() else {
            return;
        };
        let watcher = shared.fleet.clone();
        tokio::spawn(async move { watcher.watch().await });
        let slots = share_with_requests.then(|| self.job_slots.clone());
        for _ in 0..loops.max(1) {
            let worker = Worker {
                solver: self.solver.clone(),
                shared: shared.clone(),
                slots: slots.clone(),
                draining: self.draining.clone(),
            };
            self.tracker.spawn(worker.run());
        }
    }

    /// Queues `keyed` to run in the background; returns its record. Refused when the queue
    /// is full or there is no room to keep the job's result. `on_end` is told what the job
    /// cost if it ends here (not a job the fleet's workers run).
    pub(super) async fn submit(
        self: &Arc<Self>,
        keyed: Keyed,
        owner: Option<Owner>,
        on_end: Option<OnEnd>,
    ) -> Result<JobRecord, EngineError> {
        self.store_reachable()?;
        let (kind, work) = (keyed.job().kind(), keyed.job().work());
        let queued = |id| {
            JobRecord::queued(id, kind, work, keyed.key())
                .owned_by(owner.clone())
                .holding(keyed.job().result_bytes())
        };
        // A job whose answer is cached is answered at once: it takes no place in the queue.
        if let Some(solved) = self.solver.cached(keyed.key()).await {
            let record = queued(self.ids.next()).holding(solved.weight());
            return self.answered(record, solved, work).await;
        }
        if let Some(shared) = &self.fleet {
            let record = queued(self.ids.next());
            return self.enqueue(shared, keyed, record).await;
        }
        let ticket = self.take_place(&keyed)?;
        let record = queued(self.ids.next());
        if let Err(refusal) = self.jobs.insert(record.clone()).await {
            self.queued.fetch_sub(1, Ordering::SeqCst);
            return Err(refusal.into());
        }
        self.jobs_queued.increment(1.0);
        let anonymous = owner.as_ref().is_none_or(|o| !o.is_tenant());
        self.spawn(record.id, keyed, ticket, anonymous, on_end);
        Ok(record)
    }

    /// Records `record`, whose answer was cached, as succeeded at once.
    async fn answered(
        &self,
        mut record: JobRecord,
        solved: Arc<Solved>,
        work: Work,
    ) -> Result<JobRecord, EngineError> {
        let done = match work {
            Work::Known(total) => total,
            Work::Unknown => 0,
        };
        self.jobs.insert(record.clone()).await?;
        let state = JobState::Succeeded(JobResult::Ready(solved));
        self.jobs.update(record.id, state.clone(), done).await;
        lock(&self.uncollected).insert(record.id, self.config.max_jobs);
        record.state = state;
        record.done = done;
        Ok(record)
    }

    /// A place in this process's queue for `keyed`, and its turn in the backlog.
    fn take_place(&self, keyed: &Keyed) -> Result<Ticket, EngineError> {
        let max = self.config.max_queued_jobs;
        let room = |n| (n < max).then_some(n + 1);
        self.queued
            .fetch_update(Ordering::SeqCst, Ordering::SeqCst, room)
            .map_err(|_| EngineError::Overloaded)?;
        let work = keyed.job().work();
        self.backlog
            .admit(keyed.job().cost_class(), work.units())
            .map_err(|backlogged| {
                self.queued.fetch_sub(1, Ordering::SeqCst);
                EngineError::Backlogged(backlogged)
            })
    }

    /// Runs job `id` on a task of its own, then records its end.
    fn spawn(
        self: &Arc<Self>,
        id: Uuid,
        keyed: Keyed,
        ticket: Ticket,
        anonymous: bool,
        on_end: Option<OnEnd>,
    ) {
        let (kind, work) = (keyed.job().kind(), keyed.job().work());
        let deadline = Instant::now() + self.config.job_deadline;
        let live = Arc::new(LiveJob {
            control: Arc::new(self.solver.control(deadline)),
            cancel: CancellationToken::new(),
            interrupted: AtomicBool::new(false),
            status: watch::Sender::new(JobStatus::Queued),
            anonymous,
            solved_in: AtomicU64::new(0),
        });
        lock(&self.live).insert(id, live.clone());
        let span = tracing::info_span!("job", id = %id, kind = %kind);
        let lifecycle = self.clone();
        self.tracker.spawn(
            async move {
                let state = lifecycle.run_job(&live, id, keyed, &ticket).await;
                drop(ticket);
                if let Some(on_end) = on_end {
                    on_end(Duration::from_nanos(live.solved_in.load(Ordering::Relaxed)));
                }
                let status = state.status();
                let done = match (status, work) {
                    (JobStatus::Succeeded, Work::Known(total)) => total,
                    _ => live.control.done(),
                };
                state.log_end(id);
                // Owed to its client, and no longer running, before anyone can read it
                // finished: a drain begun in between would otherwise count it owed (as
                // running, or unread) after its client had read it, and wait for it forever.
                lock(&lifecycle.uncollected).insert(id, lifecycle.config.max_jobs);
                lock(&lifecycle.live).remove(&id);
                lifecycle.jobs.update(id, state, done).await;
                // Its end saved where the next process reads it: a drain begun while it ran
                // owes its client nothing more (one Ctrl-C waited out its timeout for it).
                if lifecycle.kept_for_good(id).await {
                    lock(&lifecycle.owed).remove(&id);
                }
                live.status.send_replace(status);
            }
            .instrument(span),
        );
    }

    /// Puts `job` on the fleet's work stream, in parts; refused when the stream holds more
    /// than 64 entries per queued job allowed.
    async fn enqueue(
        &self,
        shared: &Shared,
        keyed: Keyed,
        record: JobRecord,
    ) -> Result<JobRecord, EngineError> {
        let unavailable = |e: super::fleet::Failure| EngineError::Unavailable(e.why);
        let job = keyed.job();
        let (backlog, rate) = shared
            .backlog_and_rate(job.cost_class())
            .await
            .map_err(unavailable)?;
        if backlog >= self.config.max_queued_jobs.saturating_mul(64) {
            return Err(EngineError::Overloaded);
        }
        let estimate = job.cost().seconds() / job.points().unwrap_or(1).max(1) as f64;
        let parts = placement::plan(
            job.points(),
            rate,
            estimate,
            shared.fleet.config.part_points,
        );
        let deadline = std::time::SystemTime::now() + self.config.job_deadline;
        shared
            .store
            .enqueue(&record, &job.to_wire(), keyed.key(), deadline, &parts)
            .await
            .map_err(unavailable)?;
        Ok(record)
    }

    /// `Unavailable` while the fleet's job store cannot be reached.
    pub fn store_reachable(&self) -> Result<(), EngineError> {
        match &self.fleet {
            Some(shared) if !shared.fleet.jobs.is_up() => {
                let jobs = &shared.fleet.jobs;
                let why = match jobs.health() {
                    Health::Denied => Health::Denied.reason(jobs.role).unwrap_or_default(),
                    _ => "Redis (jobs) cannot be reached: no answer at the last try".to_string(),
                };
                Err(EngineError::Unavailable(why))
            }
            _ => Ok(()),
        }
    }

    /// The jobs no tenant owns that this process runs or queues.
    pub fn unfinished_anonymous(&self) -> usize {
        lock(&self.live)
            .values()
            .filter(|job| job.anonymous)
            .count()
    }

    /// See [`JobStore::problem`].
    pub fn store_problem(&self) -> Option<String> {
        self.jobs.problem()
    }

    /// The reachability of each Redis role, when the engine works in a fleet.
    pub fn fleet_health(&self) -> Option<[(&'static str, Health); 2]> {
        self.fleet.as_ref().map(|shared| shared.fleet.health())
    }

    /// The job `id`, unless unknown or expired, with its progress up to now if it runs here.
    pub async fn job(&self, id: Uuid) -> Option<JobRecord> {
        let mut record = self.jobs.get(id).await?;
        if record.state.status().is_finished() {
            self.collected(id);
        } else if let Some(live) = lock(&self.live).get(&id) {
            record.done = live.control.done();
        }
        Some(record)
    }

    /// The jobs of `listing`'s owner, newest first, filtered and paged (progress as `job`).
    pub async fn list(&self, listing: &Listing) -> Result<Page, EngineError> {
        self.store_reachable()?;
        let mut page = self.jobs.list(listing).await?;
        let live = lock(&self.live);
        for record in &mut page.jobs {
            if let Some(job) = live.get(&record.id) {
                record.done = job.control.done();
            }
        }
        Ok(page)
    }

    /// The newest job that succeeded on the input whose hash is `input_hash`.
    pub async fn with_input(&self, input_hash: &str) -> Result<Option<JobRecord>, EngineError> {
        self.store_reachable()?;
        Ok(self.jobs.with_input(input_hash).await?)
    }

    /// What can be told of a job `id` that the job store does not know.
    pub async fn unknown(&self, id: Uuid) -> Unknown {
        if !ids::is_ours(id) {
            return Unknown::NeverIssued;
        }
        match &self.fleet {
            Some(shared) => match shared.fleet.epoch().await {
                Some(since) if ids::issued_at(id) < since => Unknown::LostWithStore { since },
                _ => Unknown::Gone,
            },
            // Every job accepted is in a durable store (the database) from its acceptance
            // until deleted or expired, whichever run accepted it.
            None if self.jobs.durable() || self.ids.issued_here(id) => Unknown::Gone,
            None => Unknown::EarlierRun,
        }
    }

    /// A receiver of the status changes of the job `id`, if this process runs it.
    pub fn watch(&self, id: Uuid) -> Option<watch::Receiver<JobStatus>> {
        lock(&self.live)
            .get(&id)
            .map(|live| live.status.subscribe())
    }

    /// Cancels the job `id` (a running one stops at the solver's next check), and returns it
    /// after waiting a little for it to stop. A finished job is left as it is.
    pub async fn cancel(&self, id: Uuid) -> Option<JobRecord> {
        let before = self.job(id).await?;
        let live = lock(&self.live).get(&id).cloned();
        if live.is_none() && self.jobs.shared() && !before.state.status().is_finished() {
            // Run by a worker of the fleet: it sees the cancel at its next heartbeat.
            let state = JobState::Cancelled { partial: None };
            self.jobs.update(id, state, before.done).await;
        }
        if let Some(live) = live {
            live.cancel();
            let mut status = live.status.subscribe();
            // Still running after the wait: the answer says so, and the job stops soon after.
            let _ = tokio::time::timeout(CANCEL_WAIT, status.wait_for(|s| s.is_finished())).await;
        }
        Some(self.job(id).await.unwrap_or(before))
    }

    /// Cancels the job `id` ([`Lifecycle::cancel`]) and forgets it; returns it as it ended.
    pub async fn delete(&self, id: Uuid) -> Option<JobRecord> {
        let record = self.cancel(id).await?;
        self.jobs.remove(id).await;
        Some(record)
    }

    pub async fn purge_expired_jobs(&self) -> usize {
        self.jobs.purge_expired().await
    }

    /// Stops taking work; the jobs accepted go on ([`Lifecycle::finish_jobs`],
    /// [`Lifecycle::jobs_collected`]). The jobs finished before the drain and not read are
    /// owed to their clients only if the store would lose them with the process (in memory,
    /// or a database that cannot be written): a durable store gives them to the next
    /// process, and a client that never comes back made every drain wait its whole timeout.
    pub fn begin_drain(&self) {
        self.draining.cancel();
        let unfinished: Vec<Uuid> = lock(&self.live).keys().copied().collect();
        let kept = self.jobs.durable() && self.jobs.problem().is_none();
        let uncollected: Vec<Uuid> = match kept {
            true => Vec::new(),
            false => lock(&self.uncollected).ids.iter().copied().collect(),
        };
        lock(&self.owed).extend(unfinished.into_iter().chain(uncollected));
    }

    /// Whether job `id` is kept where the next process reads it (a database file that can
    /// be written, its end saved there).
    async fn kept_for_good(&self, id: Uuid) -> bool {
        self.jobs.durable()
            && self.jobs.problem().is_none()
            && self.jobs.get(id).await.is_some_and(|r| !r.unsaved)
    }

    /// A client read the job `id` finished: it owes its client nothing more.
    fn collected(&self, id: Uuid) {
        lock(&self.uncollected).ids.remove(&id);
        lock(&self.owed).remove(&id);
    }

    /// Resolves when every job owed at the start of the drain has been read finished by its
    /// client, so that none of their answers is lost with the process.
    pub async fn jobs_collected(&self) {
        while !lock(&self.owed).is_empty() {
            tokio::time::sleep(Duration::from_millis(20)).await;
        }
    }

    /// Asynchronous jobs of this process queued or running: those a drain waits to finish.
    pub fn unfinished_jobs(&self) -> usize {
        lock(&self.live).len()
    }

    /// Jobs finished that no client has read yet (once the drain has begun, those it owes).
    pub fn unread_jobs(&self) -> usize {
        if self.is_draining() {
            let live: HashSet<Uuid> = lock(&self.live).keys().copied().collect();
            lock(&self.owed)
                .iter()
                .filter(|id| !live.contains(id))
                .count()
        } else {
            lock(&self.uncollected).ids.len()
        }
    }

    pub fn is_draining(&self) -> bool {
        self.draining.is_cancelled()
    }

    /// Waits (after `begin_drain`) for the jobs to finish until `end`, then interrupts the rest
    /// and gives them a second to stop; whether every job finished in time. What the store
    /// could not save before is saved then, if it now can.
    pub async fn finish_jobs(&self, end: tokio::time::Instant) -> bool {
        self.tracker.close();
        let finished = tokio::time::timeout_at(end, self.tracker.wait())
            .await
            .is_ok();
        if !finished {
            if let Some(shared) = &self.fleet {
                shared.interrupt();
            }
            for live in lock(&self.live).values() {
                live.interrupted.store(true, Ordering::SeqCst);
                live.cancel();
            }
            // They stop at their next check, microseconds to milliseconds away.
            let _ = tokio::time::timeout(Duration::from_secs(1), self.tracker.wait()).await;
        }
        self.jobs.settle().await;
        finished
    }

    /// Runs an accepted job to its end state; its solve time teaches `ticket`'s class.
    async fn run_job(&self, live: &LiveJob, id: Uuid, keyed: Keyed, ticket: &Ticket) -> JobState {
        let permit = match self.solver.cached(keyed.key()).await {
            Some(hit) => Err(JobState::Succeeded(JobResult::Ready(hit))),
            None => tokio::select! {
                () = live.cancel.cancelled() => Err(live.stopped(None)),
                permits = async {
                    let slot = self.job_slots.clone().acquire_owned().await;
                    (slot, self.solver.pool.acquire(keyed.job().cost().bytes).await)
                } => Ok(permits),
            },
        };
        self.queued.fetch_sub(1, Ordering::SeqCst);
        self.jobs_queued.decrement(1.0);
        let (_slot, permit) = match permit {
            Ok(permits) => permits,
            Err(state) => return state,
        };
        // Beside its permit, threads while cores are idle, as many as its units can use (a
        // sweep's points), held until the job ends; one of the pool's threads is always
        // left to requests. On 2 cores a thread lent beside a running sweep, even in the idle
        // class, let `/healthz` under hostile slow readers reach 30–55 ms at its slowest
        // against 1.4–4.3 ms (`reliability/hostile.py slow-readers 8`, 8 runs each).
        let job = keyed.job();
        let free = self.config.pool_size.saturating_sub(1).max(1);
        let more = job.work().units().min(free).saturating_sub(1);
        let lent = self.solver.pool.lend(more, job.cost().bytes);
        live.control.set_threads(1 + lent.threads);
        // Counted as running before anyone can read it so: a client that saw the job
        // running and then reads the gauge finds it counted.
        let _running = self.solver.running();
        self.jobs.update(id, JobState::Running, 0).await;
        live.status.send_replace(JobStatus::Running);
        let (started, work) = (Instant::now(), keyed.job().work());
        let result = self
            .solver
            .execute(permit, keyed, live.control.clone(), true)
            .await;
        // A job of unknown work (a fit) is one unit, and teaches only when it ends well;
        // units recalled from the memo (a retry's) cost nothing and teach nothing.
        let done = match (&result, work) {
            (Ok(_), _) => ticket.units(),
            (Err(_), Work::Known(_)) => live.control.done(),
            (Err(_), Work::Unknown) => 0,
        };
        let solved = done.saturating_sub(live.control.recalled());
        let took = started.elapsed();
        ticket.ran(solved, took);
        let nanos = u64::try_from(took.as_nanos()).unwrap_or(u64::MAX);
        live.solved_in.store(nanos, Ordering::Relaxed);
        // The job is still running (its status says so) while its answer is kept: the
        // guard goes with this function.
        match result {
            Ok(solved) => {
                self.solver.cache.insert(solved.clone()).await;
                JobState::Succeeded(JobResult::Ready(solved))
            }
            Err(Stopped { error, partial }) => {
                let partial = partial.map(JobResult::Ready);
                match error {
                    JobError::Cancelled => live.stopped(partial),
                    error => JobState::Failed { error, partial },
                }
            }
        }
    }
}
