//! The solved points of sweeps, kept within their share of the memory budget: a sweep that
//! runs past its deadline leaves what it solved for its retry, and sweeps that share points
//! share their solves.

use std::time::Duration;

use super::bounded::Bounded;
use crate::job::{Kept, Memo};

/// Solved points by key, bounded in bytes and in time.
pub struct PointMemo {
    points: Bounded<(Kept, u32)>,
}

impl std::fmt::Debug for PointMemo {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PointMemo")
            .field("entries", &self.points.len())
            .finish()
    }
}

impl PointMemo {
    pub fn new(max_bytes: u64, ttl: Duration) -> Self {
        // A point of a rolling sweep, the commonest, weighs about 1 kB.
        let weigh = |(_, bytes): &(Kept, u32)| u64::from(*bytes);
        PointMemo {
            points: Bounded::new(max_bytes, ttl, 1 << 10, weigh),
        }
    }
}

impl Memo for PointMemo {
    fn recall(&self, key: &str) -> Option<Kept> {
        self.points.get(key).map(|(kept, _)| kept)
    }

    fn keep(&self, key: String, value: Kept, bytes: usize) {
        let bytes = u32::try_from(bytes).unwrap_or(u32::MAX);
        self.points.insert(key, (value, bytes));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::job::Control;
    use std::sync::Arc;

    #[test]
    fn units_recalled_from_the_memo_are_counted_apart_from_those_solved() {
        let memo = Arc::new(PointMemo::new(1 << 20, Duration::from_secs(60)));
        let control = Control::new(None, 1).with_memo(memo);
        let solved = std::sync::atomic::AtomicUsize::new(0);
        let square = control.kept(
            |x: &u32| x.to_string(),
            |_| 8,
            |x: &u32| {
                solved.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                Ok::<u32, ()>(x * x)
            },
        );
        assert_eq!([2, 3, 2, 2].map(|x| square(&x).unwrap()), [4, 9, 4, 4]);
        drop(square);
        assert_eq!(solved.into_inner(), 2);
        assert_eq!(control.recalled(), 2);
    }
}
