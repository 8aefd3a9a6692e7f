//! What each open connection is doing, so that the accept loop, when the connections run
//! out, closes the one that serves nobody: an idle keep-alive connection first, then one
//! whose request head is unfinished, then one whose client stopped reading its answer, then
//! one whose request body crawls. A connection whose request is being worked on, or whose
//! answer is flowing, is never closed to make room.

use std::sync::atomic::{AtomicBool, AtomicU32, AtomicU64, Ordering::Relaxed};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::Instant;

use tokio::sync::OwnedSemaphorePermit;
use tokio::task::AbortHandle;

/// How long a write may wait, or a body crawl, before its connection counts as stalled for
/// eviction (the send and body timeouts close it later anyway), and how long a connection
/// just opened or answered has to begin its request: a client on a slow link keeps its place
/// through short waits. Longer is not kinder: while a burst of newcomers is all within it,
/// nothing may go, the accept loop waits and their SYNs queue (200 ms cost a /healthz probe
/// a 1 s retransmit under 1,100 slowloris connections).
const STALL_GRACE_MS: u64 = 50;

/// A monotonic clock in milliseconds that atomics can hold; 0 means "never".
#[derive(Clone, Copy, Debug)]
pub struct Clock(Instant);

impl Clock {
    pub fn new() -> Self {
        Clock(Instant::now())
    }

    /// Milliseconds since the clock started, plus one (so never 0).
    pub fn now(&self) -> u64 {
        u64::try_from(self.0.elapsed().as_millis()).unwrap_or(u64::MAX - 1) + 1
    }
}

/// One connection's state. Its transport ([`super::io::Watched`]), its requests and their
/// bodies write it; the accept loop reads it.
#[derive(Debug)]
pub struct Activity {
    clock: Clock,
    /// Requests whose answer has not been wholly handed to the connection.
    requests: AtomicU32,
    /// When the connection last had no request: opened, or an answer ended.
    idle_since: AtomicU64,
    /// Whether bytes arrived since then: a request head has begun.
    heard: AtomicBool,
    /// Whether a request has been answered on it (a keep-alive connection).
    answered: AtomicBool,
    /// Since when a write has waited for the client to read; 0 while none waits.
    stalled_since: AtomicU64,
    /// Since when a request body has been arriving; 0 while none is.
    receiving_since: AtomicU64,
}

/// Why a connection may be closed to make room, the most dispensable first.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Dispensable {
    /// No request since its last answer: an idle keep-alive connection.
    Idle,
    /// A request head begun and not finished (slowloris), or none begun on a connection
    /// that has not been answered yet: a silent newcomer is no more dispensable than a
    /// slowloris that sent a byte (a /healthz probe whose request was late went first).
    HeadUnfinished,
    /// Its client has not read the answer for a while.
    NotReading,
    /// Its request body has been arriving for a while.
    SlowBody,
}

impl Activity {
    pub fn new(clock: Clock) -> Self {
        Activity {
            clock,
            requests: AtomicU32::new(0),
            idle_since: AtomicU64::new(clock.now()),
            heard: AtomicBool::new(false),
            answered: AtomicBool::new(false),
            stalled_since: AtomicU64::new(0),
            receiving_since: AtomicU64::new(0),
        }
    }

    /// A request head arrived; the returned guard ends the request when dropped (with the
    /// answer's body, once hyper has taken all of it).
    pub fn request(self: &Arc<Self>) -> RequestGuard {
        self.requests.fetch_add(1, Relaxed);
        self.heard.store(false, Relaxed);
        RequestGuard(self.clone())
    }

    /// Bytes arrived from the client.
    pub fn heard(&self) {
        if self.requests.load(Relaxed) == 0 {
            self.heard.store(true, Relaxed);
        }
    }

    /// A write waits for the client to read (kept from the first wait).
    pub fn write_waits(&self) {
        let _ = self
            .stalled_since
            .compare_exchange(0, self.clock.now(), Relaxed, Relaxed);
    }

    /// A write went through.
    pub fn write_moved(&self) {
        self.stalled_since.store(0, Relaxed);
    }

    /// A request body began (`true`) or ended (`false`) arriving.
    pub fn receiving(&self, receiving: bool) {
        let since = if receiving { self.clock.now() } else { 0 };
        self.receiving_since.store(since, Relaxed);
    }

    /// Why this connection may be closed now, and since when; `None` while it serves.
    fn dispensable(&self, now: u64) -> Option<(Dispensable, u64)> {
        let waited = |since: u64| since != 0 && now.saturating_sub(since) >= STALL_GRACE_MS;
        let stalled = self.stalled_since.load(Relaxed);
        if waited(stalled) {
            return Some((Dispensable::NotReading, stalled));
        }
        if self.requests.load(Relaxed) == 0 {
            let since = self.idle_since.load(Relaxed);
            // A connection just opened (or just answered) has a moment to send its request:
            // else a client's fresh connection, idle until its head arrives, was the first
            // to go when another came at the cap, ahead of 511 crawling bodies (a /healthz
            // probe failed so, once in a few hundred).
            if !waited(since) {
                return None;
            }
            let why = if self.heard.load(Relaxed) || !self.answered.load(Relaxed) {
                Dispensable::HeadUnfinished
            } else {
                Dispensable::Idle
            };
            return Some((why, since));
        }
        let receiving = self.receiving_since.load(Relaxed);
        waited(receiving).then_some((Dispensable::SlowBody, receiving))
    }

    /// How long it has had no request and heard nothing, if so.
    fn idle_for(&self, now: u64) -> Option<u64> {
        let idle = self.requests.load(Relaxed) == 0
            && !self.heard.load(Relaxed)
            && self.stalled_since.load(Relaxed) == 0;
        idle.then(|| now.saturating_sub(self.idle_since.load(Relaxed)))
    }
}

/// A request in flight on a connection; dropping it ends the request.
#[derive(Debug)]
pub struct RequestGuard(Arc<Activity>);

impl Drop for RequestGuard {
    fn drop(&mut self) {
        let activity = &self.0;
        activity.idle_since.store(activity.clock.now(), Relaxed);
        activity.answered.store(true, Relaxed);
        activity.requests.fetch_sub(1, Relaxed);
    }
}

/// Removes a connection from the registry when dropped ([`Connections::on_drop_close`]).
pub struct Closing(Connections, u64);

impl Drop for Closing {
    fn drop(&mut self) {
        self.0.closed(self.1);
    }
}

/// An open connection, as the accept loop sees it.
struct Open {
    id: u64,
    activity: Arc<Activity>,
    task: AbortHandle,
    /// Its place under the connection cap, given back when it leaves the registry.
    slot: OwnedSemaphorePermit,
}

/// The open connections.
#[derive(Clone)]
pub struct Connections {
    clock: Clock,
    open: Arc<Mutex<Vec<Open>>>,
    next: Arc<AtomicU64>,
}

impl Connections {
    pub fn new(clock: Clock) -> Self {
        Connections {
            clock,
            open: Arc::default(),
            next: Arc::default(),
        }
    }

    fn open(&self) -> MutexGuard<'_, Vec<Open>> {
        self.open.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// Registers a connection holding `slot`, about to be served by the task `spawn` starts
    /// (given the id to pass to [`Connections::closed`]), under the lock, so that its removal
    /// always follows its entry.
    pub fn add(
        &self,
        activity: Arc<Activity>,
        slot: OwnedSemaphorePermit,
        spawn: impl FnOnce(u64) -> AbortHandle,
    ) {
        let id = self.next.fetch_add(1, Relaxed);
        let mut open = self.open();
        let task = spawn(id);
        open.push(Open {
            id,
            activity,
            task,
            slot,
        });
    }

    pub fn closed(&self, id: u64) {
        self.open().retain(|c| c.id != id);
    }

    /// A guard that calls [`Connections::closed`] for `id` when dropped.
    pub fn on_drop_close(&self, id: u64) -> Closing {
        Closing(self.clone(), id)
    }

    /// Closes the most dispensable connection (the one waiting longest among those) and
    /// hands its slot over at once; None if every connection is serving a request.
    ///
    /// The slot does not wait for the closed connection's task to be dropped: under a burst
    /// of newcomers the accept loop would otherwise wait for a busy worker thread once per
    /// newcomer (a /healthz probe queued behind 100 such newcomers waited 240 ms). The
    /// aborted tasks' sockets close moments later, so the open sockets may briefly exceed
    /// the cap by the evictions still in flight.
    pub fn evict(&self) -> Option<OwnedSemaphorePermit> {
        let now = self.clock.now();
        let mut open = self.open();
        let chosen = open
            .iter()
            .enumerate()
            .filter_map(|(i, c)| c.activity.dispensable(now).map(|key| (key, i)))
            .min();
        let (_, index) = chosen?;
        let evicted = open.swap_remove(index);
        evicted.task.abort();
        Some(evicted.slot)
    }

    /// Closes the connections that have been idle (no request, nothing heard) for at least
    /// `limit_ms`: the keep-alive timeout.
    pub fn close_idle(&self, limit_ms: u64) {
        let now = self.clock.now();
        self.open().retain(|c| match c.activity.idle_for(now) {
            Some(idle) if idle >= limit_ms => {
                c.task.abort();
                false
            }
            _ => true,
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(now: u64) -> Activity {
        let activity = Activity::new(Clock::new());
        activity.idle_since.store(now, Relaxed);
        activity
    }

    #[test]
    fn idle_connections_go_first_then_unfinished_heads_then_stalled_readers_then_slow_bodies() {
        let now = 100_000;
        let idle = Arc::new(at(5_000));
        drop(idle.request());
        let head = Arc::new(at(1_000));
        head.heard.store(true, Relaxed);
        let reader = Arc::new(at(1_000));
        let _request = reader.request();
        reader.stalled_since.store(now - 2_000, Relaxed);
        let body = Arc::new(at(1_000));
        let _upload = body.request();
        body.receiving_since.store(now - 50_000, Relaxed);
        let working = Arc::new(at(1_000));
        let _solve = working.request();
        let ranked: Vec<_> = [&idle, &head, &reader, &body, &working]
            .iter()
            .map(|a| a.dispensable(now).map(|(why, _)| why))
            .collect();
        assert_eq!(
            ranked,
            [
                Some(Dispensable::Idle),
                Some(Dispensable::HeadUnfinished),
                Some(Dispensable::NotReading),
                Some(Dispensable::SlowBody),
                None
            ]
        );
        assert!(ranked[0] < ranked[1] && ranked[1] < ranked[2] && ranked[2] < ranked[3]);
    }

    #[tokio::test]
    async fn an_evicted_connection_hands_its_slot_over_at_once() {
        let slots = Arc::new(tokio::sync::Semaphore::new(2));
        // A clock a second old, so that a connection idle since its start may go.
        let clock = Clock(Instant::now() - std::time::Duration::from_secs(1));
        let connections = Connections::new(clock);
        let open = |activity: Arc<Activity>| {
            let slot = slots.clone().try_acquire_owned().expect("a free slot");
            let task = tokio::spawn(std::future::pending::<()>());
            connections.add(activity, slot, |_| task.abort_handle());
            task
        };
        let idle = open(Arc::new(at(1)));
        let busy = Arc::new(Activity::new(Clock::new()));
        let _request = busy.request();
        let _working = open(busy);
        assert_eq!(slots.available_permits(), 0);
        let handed = connections.evict().expect("the idle connection goes");
        // The slot is the newcomer's now, before the closed connection's task has gone.
        assert_eq!(slots.available_permits(), 0);
        drop(handed);
        assert_eq!(slots.available_permits(), 1);
        assert!(idle.await.unwrap_err().is_cancelled());
        assert!(connections.evict().is_none(), "the other serves a request");
    }

    #[test]
    fn a_connection_just_opened_has_a_moment_to_send_its_request() {
        let now = 100_000;
        let fresh = Arc::new(at(now - 10));
        assert_eq!(fresh.dispensable(now), None);
        let body = Arc::new(at(1_000));
        let _upload = body.request();
        body.receiving_since.store(now - 50_000, Relaxed);
        assert_eq!(
            body.dispensable(now).map(|(why, _)| why),
            Some(Dispensable::SlowBody),
            "a crawling body goes before it"
        );
        // Then, silent, it ranks with unfinished heads, after those that have waited longer
        // (a slowloris that sent a byte), and after idle keep-alive connections.
        let later = now + STALL_GRACE_MS;
        let slowloris = Arc::new(at(2_000));
        slowloris.heard();
        let keep_alive = Arc::new(at(1_000));
        drop(keep_alive.request());
        let mut ranked: Vec<_> = [&fresh, &slowloris, &keep_alive]
            .iter()
            .enumerate()
            .filter_map(|(i, a)| a.dispensable(later).map(|key| (key, i)))
            .collect();
        ranked.sort();
        assert_eq!(
            ranked.iter().map(|(_, i)| *i).collect::<Vec<_>>(),
            [2, 1, 0]
        );
        assert_eq!(ranked[2].0 .0, Dispensable::HeadUnfinished);
    }

    #[test]
    fn a_short_wait_to_write_or_receive_is_not_a_stall() {
        let now = 100_000;
        let reader = Arc::new(at(1_000));
        let _request = reader.request();
        reader.stalled_since.store(now - 10, Relaxed);
        reader.receiving_since.store(now - 10, Relaxed);
        assert_eq!(reader.dispensable(now), None);
    }

    #[test]
    fn an_answered_request_leaves_the_connection_idle_from_then() {
        let activity = Arc::new(Activity::new(Clock::new()));
        let request = activity.request();
        assert_eq!(activity.idle_for(activity.clock.now()), None);
        activity.heard();
        drop(request);
        assert!(activity.idle_for(activity.clock.now()).is_some());
        activity.heard();
        assert_eq!(
            activity.idle_for(activity.clock.now()),
            None,
            "a head has begun"
        );
    }
}
