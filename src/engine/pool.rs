//! Admission control for the compute threads: one permit per solver thread, sized to the
//! cores, and the working memory a solve holds, set aside from the memory budget's share
//! before it allocates ([`crate::job::Cost::bytes`]: a continuum answer holds up to 34 MB).
//! A synchronous request that finds no thread or not memory enough free is refused at once
//! (the caller answers 429) rather than queued without bound; an asynchronous job waits for
//! both in the job store's bounded queue.

use std::sync::Arc;

use tokio::sync::{OwnedSemaphorePermit, Semaphore};

use crate::job::{Control, JobError};

/// The permits of the solver threads, and of the working memory, in KiB.
#[derive(Clone, Debug)]
pub struct Pool {
    permits: Arc<Semaphore>,
    memory: Arc<Semaphore>,
    memory_kib: u32,
}

/// A solve's right to run: its thread, and its working memory (none when it holds little).
#[derive(Debug)]
pub struct Permit {
    _thread: OwnedSemaphorePermit,
    _memory: Option<OwnedSemaphorePermit>,
}

impl Pool {
    pub fn new(size: usize, memory: u64) -> Self {
        let memory_kib = u32::try_from(memory >> 10).unwrap_or(u32::MAX).max(1);
        Pool {
            permits: Arc::new(Semaphore::new(size.max(1))),
            memory: Arc::new(Semaphore::new(memory_kib as usize)),
            memory_kib,
        }
    }

    /// The memory permits for `bytes`: all of them for a solve larger than the share (alone).
    fn kib(&self, bytes: u64) -> u32 {
        u32::try_from(bytes.div_ceil(1024))
            .unwrap_or(u32::MAX)
            .min(self.memory_kib)
    }

    pub fn try_acquire(&self, bytes: u64) -> Option<Permit> {
        let thread = self.permits.clone().try_acquire_owned().ok()?;
        let memory = match self.kib(bytes) {
            0 => None,
            kib => Some(self.memory.clone().try_acquire_many_owned(kib).ok()?),
        };
        Some(Permit {
            _thread: thread,
            _memory: memory,
        })
    }

    /// Waits for a thread, then for `bytes` of working memory (first come, first served).
    pub async fn acquire(&self, bytes: u64) -> Permit {
        let closed = "the pool's semaphores are never closed";
        let thread = self.permits.clone().acquire_owned().await.expect(closed);
        let memory = self.memory.clone();
        let memory = match self.kib(bytes) {
            0 => None,
            kib => Some(memory.acquire_many_owned(kib).await.expect(closed)),
        };
        Permit {
            _thread: thread,
            _memory: memory,
        }
    }

    /// Threads to lend a running job beside its permit, at most `threads`, each with
    /// `bytes` of working memory, as much as is free now (never waiting). They are counted
    /// in memory only: a lent thread runs in the idle class ([`super::heavy::lent_thread`]),
    /// and the caller leaves one of the pool's threads to requests.
    pub fn lend(&self, threads: usize, bytes: u64) -> Lent {
        let kib = self.kib(bytes);
        let mut memory = Vec::new();
        while memory.len() < threads && kib > 0 {
            match self.memory.clone().try_acquire_many_owned(kib) {
                Ok(permit) => memory.push(permit),
                Err(_) => break,
            }
        }
        Lent {
            threads: if kib == 0 { threads } else { memory.len() },
            _memory: memory,
        }
    }

    /// Runs `work` holding `permit` on a [`super::heavy`] thread, in the caller's span. If the
    /// caller stops waiting (a client hung up, a request timed out), `control` is cancelled:
    /// the solver stops at its next check instead of burning a core for nobody.
    pub async fn run<T, F>(permit: Permit, control: Arc<Control>, work: F) -> Result<T, JobError>
    where
        T: Send + 'static,
        F: FnOnce(&Control) -> Result<T, JobError> + Send + 'static,
    {
        let mut guard = CancelOnDrop(Some(control.clone()));
        let span = tracing::Span::current();
        let result = super::heavy::run(move || {
            let _permit = permit;
            span.in_scope(|| work(&control))
        })
        .await;
        guard.0 = None;
        result.map_err(|e| JobError::Internal(format!("the solver thread failed: {e}")))?
    }
}

/// Threads lent to a running job ([`Pool::lend`]), and their memory until dropped.
#[derive(Debug)]
pub struct Lent {
    pub threads: usize,
    _memory: Vec<OwnedSemaphorePermit>,
}

/// Cancels a job when the future waiting for it is dropped before it finished.
struct CancelOnDrop(Option<Arc<Control>>);

impl Drop for CancelOnDrop {
    fn drop(&mut self) {
        if let Some(control) = &self.0 {
            control.cancel();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A solve holds its working memory until it ends: another that would pass the share
    /// waits (or, synchronous, is refused); one larger than the whole share runs alone; one
    /// that holds little needs only a thread.
    #[test]
    fn solves_hold_their_working_memory_within_the_share() {
        let pool = Pool::new(4, 10 << 20);
        let big = pool.try_acquire(6 << 20).expect("room for 6 MiB");
        assert!(pool.try_acquire(5 << 20).is_none(), "6 + 5 MiB passes 10");
        let small = pool.try_acquire(4 << 20).expect("6 + 4 MiB fits");
        let light = pool.try_acquire(0).expect("no memory: a thread is enough");
        drop((big, small, light));
        let alone = pool
            .try_acquire(1 << 30)
            .expect("larger than the share: all of it");
        assert!(pool.try_acquire(1).is_none(), "the share is taken whole");
        assert!(
            pool.try_acquire(0).is_some(),
            "a thread without memory still runs"
        );
        drop(alone);
        assert!(pool.try_acquire(10 << 20).is_some());
    }

    /// Threads are lent while their memory fits beside the solves', never past it; a job
    /// that holds little memory gets them all.
    #[test]
    fn lent_threads_hold_memory_within_the_share() {
        let pool = Pool::new(2, 10 << 20);
        let running = pool.try_acquire(4 << 20).expect("room for 4 MiB");
        let lent = pool.lend(3, 4 << 20);
        assert_eq!(lent.threads, 1, "4 + 4 MiB fit in 10, not 4 + 8");
        assert!(
            pool.try_acquire(4 << 20).is_none(),
            "the lent memory is held"
        );
        drop(lent);
        assert_eq!(pool.lend(3, 0).threads, 3);
        drop(running);
    }
}
