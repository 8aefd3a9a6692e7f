//! Work done off the request path ([`crate::job::Later`]): one thread, one piece at a time,
//! a short bounded queue. Today it builds the similarity table a single rolling answer
//! would have used (≈ 5 ms, against ≈ 22 µs for the exact solve that answered meanwhile),
//! so that the next answers on that layer take the table.
//!
//! Bounded on purpose: a client sending a new layer with every request costs at most this
//! one thread, a few queued pieces and the tables the model keeps (a bounded number); what
//! does not fit in the queue is dropped, never waited for.

use std::collections::HashSet;
use std::fmt;
use std::sync::mpsc::{sync_channel, SyncSender, TrySendError};
use std::sync::{Arc, Mutex, MutexGuard};
use std::thread;

use crate::job::Later;

/// Pieces waiting at most; more are dropped.
const QUEUED: usize = 4;

type Piece = (String, Box<dyn FnOnce() + Send>);

/// The background thread's queue. The thread ends when this is dropped.
pub struct Background {
    queue: Mutex<SyncSender<Piece>>,
    /// Keys queued or running, so that one piece is not queued twice.
    pending: Arc<Mutex<HashSet<String>>>,
}

impl Background {
    /// Starts the thread.
    pub fn start() -> std::io::Result<Arc<Background>> {
        let (queue, pieces) = sync_channel::<Piece>(QUEUED);
        let pending: Arc<Mutex<HashSet<String>>> = Arc::default();
        let done = pending.clone();
        thread::Builder::new()
            .name("thirdbody-background".to_string())
            .spawn(move || {
                super::heavy::lower_priority();
                for (key, work) in pieces {
                    // A panic in one piece must not end the thread nor leave its key pending.
                    let _ = std::panic::catch_unwind(std::panic::AssertUnwindSafe(work));
                    lock(&done).remove(&key);
                }
            })?;
        Ok(Arc::new(Background {
            queue: Mutex::new(queue),
            pending,
        }))
    }
}

impl Later for Background {
    fn offer(&self, key: String, work: Box<dyn FnOnce() + Send>) {
        if !lock(&self.pending).insert(key.clone()) {
            return;
        }
        match lock(&self.queue).try_send((key.clone(), work)) {
            Ok(()) => {}
            Err(TrySendError::Full(_) | TrySendError::Disconnected(_)) => {
                lock(&self.pending).remove(&key);
            }
        }
    }
}

impl fmt::Debug for Background {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Background")
            .field("pending", &lock(&self.pending).len())
            .finish()
    }
}

/// The queue and the key set stay consistent through a panic elsewhere.
fn lock<T>(mutex: &Mutex<T>) -> MutexGuard<'_, T> {
    mutex.lock().unwrap_or_else(|p| p.into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};
    use std::sync::mpsc::channel;
    use std::time::Duration;

    #[test]
    fn pieces_run_once_per_key_and_a_full_queue_drops_rather_than_waits() {
        let background = Background::start().unwrap();
        let runs = Arc::new(AtomicUsize::new(0));
        // Hold the thread on a first piece until the queue has been filled and overfilled.
        let (release, hold) = channel::<()>();
        background.offer(
            "hold".to_string(),
            Box::new(move || {
                let _ = hold.recv();
            }),
        );
        for i in 0..(QUEUED + 3) {
            for _ in 0..2 {
                let runs = runs.clone();
                background.offer(
                    format!("piece {i}"),
                    Box::new(move || {
                        runs.fetch_add(1, Ordering::SeqCst);
                    }),
                );
            }
        }
        release.send(()).unwrap();
        let start = std::time::Instant::now();
        while !lock(&background.pending).is_empty() {
            assert!(
                start.elapsed() < Duration::from_secs(5),
                "pieces still pending"
            );
            thread::sleep(Duration::from_millis(1));
        }
        // The first piece may have been taken off the queue before the others came: then
        // QUEUED of them fit, else QUEUED − 1; duplicates never run.
        let ran = runs.load(Ordering::SeqCst);
        assert!((QUEUED - 1..=QUEUED).contains(&ran), "{ran} pieces ran");
    }
}
