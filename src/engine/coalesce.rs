//! Identical concurrent misses share one solve: the first caller for a key starts it, the
//! others wait for the same future. Whatever cache is behind the engine, a burst of the same
//! request solves once.

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use futures_util::future::{BoxFuture, FutureExt, Shared, WeakShared};

use super::bounded::KeyHasher;
use super::cache::Solved;
use super::error::EngineError;
use super::lock;

pub type Solving = BoxFuture<'static, Result<Arc<Solved>, EngineError>>;

/// The solves in flight, by cache key. Entries are weak: when every caller waiting for a
/// solve has gone (clients hung up), the solve is dropped, and with it cancelled.
#[derive(Default)]
pub struct Coalescer {
    /// Hashed as the engine's other maps are ([`KeyHasher`]: SipHash was 1,300 of an
    /// uncached request's instructions here).
    in_flight: Mutex<HashMap<String, WeakShared<Solving>, KeyHasher>>,
}

impl Coalescer {
    /// The result of the solve of `key`: one already in flight, or `start()`. The flag says
    /// whether this call started it.
    pub async fn run(
        &self,
        key: &str,
        start: impl FnOnce() -> Solving,
    ) -> (Result<Arc<Solved>, EngineError>, bool) {
        // Declared first, dropped last: after this caller's handle on the solve.
        let _forget = Forget {
            coalescer: self,
            key,
        };
        let (solving, started) = {
            let mut in_flight = lock(&self.in_flight);
            match in_flight.get(key).and_then(WeakShared::upgrade) {
                Some(solving) => (solving, false),
                None => {
                    let solving = start().shared();
                    if let Some(weak) = solving.downgrade() {
                        in_flight.insert(key.to_string(), weak);
                    }
                    (solving, true)
                }
            }
        };
        (solving.await, started)
    }
}

/// Forgets a key's entry once its solve is done or abandoned (by whichever waiter leaves last).
struct Forget<'a> {
    coalescer: &'a Coalescer,
    key: &'a str,
}

impl Drop for Forget<'_> {
    fn drop(&mut self) {
        let mut in_flight = lock(&self.coalescer.in_flight);
        let done = in_flight
            .get(self.key)
            .is_some_and(|weak| weak.upgrade().is_none_or(|s| Shared::peek(&s).is_some()));
        if done {
            in_flight.remove(self.key);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};

    #[tokio::test]
    async fn a_burst_of_one_key_solves_once_and_then_forgets_it() {
        let coalescer = Coalescer::default();
        let starts = AtomicUsize::new(0);
        let start = || -> Solving {
            starts.fetch_add(1, Ordering::SeqCst);
            async {
                tokio::time::sleep(std::time::Duration::from_millis(20)).await;
                Err(EngineError::Overloaded)
            }
            .boxed()
        };
        let calls = (0..10).map(|_| coalescer.run("k", start));
        let results = futures_util::future::join_all(calls).await;
        assert_eq!(starts.load(Ordering::SeqCst), 1);
        assert_eq!(results.iter().filter(|(_, started)| *started).count(), 1);
        assert!(results
            .iter()
            .all(|(r, _)| matches!(r, Err(EngineError::Overloaded))));
        assert!(lock(&coalescer.in_flight).is_empty());
    }

    #[tokio::test]
    async fn an_abandoned_solve_is_dropped_and_forgotten() {
        let coalescer = Coalescer::default();
        let dropped = Arc::new(AtomicUsize::new(0));
        struct Flag(Arc<AtomicUsize>);
        impl Drop for Flag {
            fn drop(&mut self) {
                self.0.fetch_add(1, Ordering::SeqCst);
            }
        }
        let flag = Flag(dropped.clone());
        let start = move || -> Solving {
            async move {
                let _flag = flag;
                std::future::pending::<()>().await;
                Err(EngineError::Overloaded)
            }
            .boxed()
        };
        let waited = tokio::time::timeout(
            std::time::Duration::from_millis(10),
            coalescer.run("k", start),
        )
        .await;
        assert!(waited.is_err());
        assert_eq!(dropped.load(Ordering::SeqCst), 1);
        assert!(lock(&coalescer.in_flight).is_empty());
    }
}
