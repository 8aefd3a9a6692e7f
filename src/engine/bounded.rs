//! The engine's in-process stores (cached answers, the input memo, solved sweep points) as one
//! kind of map: keyed by text, bounded in bytes and in time.
//!
//! Under traffic where every input is new, every answer is inserted and soon pushed out, so
//! the map's insert and eviction are on every uncached request's path. quick_cache does them
//! inline under a shard's lock, with no background bookkeeping. With moka in its place, the
//! insert, its housekeeping and rehashing cost about a quarter of an uncached rolling
//! request's server CPU (BENCHMARKS.md, issue 12).
//!
//! Entries expire lazily: a read of an entry past its time removes it and finds nothing, and
//! entries never read again leave when the byte bound pushes them out. The bytes held stay
//! within the bound either way.

use std::time::{Duration, Instant};

use quick_cache::sync::Cache;
use quick_cache::{OptionsBuilder, Weighter};

use super::budget;

/// The hasher of the engine's in-process maps (answers, input keys, sweep points, solves in
/// flight) and of the doorkeeper. Their keys churn at the request rate: with SipHash,
/// hashing was a tenth of an uncached request's CPU (under moka, which rehashed its table as
/// entries came and went). foldhash is seeded per process, so keys cannot be chosen to
/// collide without knowing the seed.
pub(super) type KeyHasher = foldhash::fast::RandomState;

/// Shards of a map, at most, each with its own lock and an equal share of the bytes (a small
/// map has fewer: quick_cache gives a shard at least 32 typical entries). An entry heavier
/// than most of a share is not kept: with 4 shards, one heavier than about a quarter of the
/// whole bound (keeping it would push out most of the rest anyway).
const SHARDS: usize = 4;

/// A map from text keys to values of `V`, holding at most about `max_bytes` (as weighed by
/// its weigher, plus [`budget::ENTRY_OVERHEAD`] per entry), each entry for at most its TTL.
pub struct Bounded<V> {
    map: Cache<String, Timed<V>, Weigh<V>, KeyHasher>,
    ttl: Duration,
}

/// A value and when it expires.
#[derive(Clone)]
struct Timed<V> {
    value: V,
    expires: Instant,
}

/// The bytes an entry holds beyond its key: a function of the value.
#[derive(Clone)]
struct Weigh<V>(fn(&V) -> u64);

impl<V> Weighter<String, Timed<V>> for Weigh<V> {
    fn weight(&self, key: &String, timed: &Timed<V>) -> u64 {
        (key.len() as u64 + (self.0)(&timed.value)).saturating_add(budget::ENTRY_OVERHEAD)
    }
}

impl<V: Clone> Bounded<V> {
    /// A map of at most about `max_bytes`, entries kept for at most `ttl`. `typical_bytes`,
    /// the weight of a typical entry, sizes the map's tables; `weigh` gives a value's bytes.
    pub fn new(max_bytes: u64, ttl: Duration, typical_bytes: u64, weigh: fn(&V) -> u64) -> Self {
        let entries = max_bytes / typical_bytes.max(1);
        let options = OptionsBuilder::new()
            .shards(SHARDS)
            .estimated_items_capacity(usize::try_from(entries).unwrap_or(usize::MAX))
            .weight_capacity(max_bytes)
            .build()
            .expect("the options are all set and in range");
        Bounded {
            map: Cache::with_options(
                options,
                Weigh(weigh),
                Default::default(),
                Default::default(),
            ),
            ttl,
        }
    }

    /// The value under `key`, unless absent or expired.
    pub fn get(&self, key: &str) -> Option<V> {
        let timed = self.map.get(key)?;
        let now = Instant::now();
        if timed.expires > now {
            return Some(timed.value);
        }
        self.map.remove_if(key, |timed| timed.expires <= now);
        None
    }

    /// Keeps `value` under `key` for the map's TTL (unless it weighs more than a shard holds).
    pub fn insert(&self, key: String, value: V) {
        let expires = Instant::now() + self.ttl;
        self.map.insert(key, Timed { value, expires });
    }

    /// Entries held, expired ones included.
    pub fn len(&self) -> usize {
        self.map.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn map(max_bytes: u64, ttl: Duration) -> Bounded<Vec<u8>> {
        Bounded::new(max_bytes, ttl, 1 << 10, |value: &Vec<u8>| {
            value.len() as u64
        })
    }

    #[test]
    fn it_keeps_within_its_bytes() {
        let map = map(1 << 20, Duration::from_secs(60));
        for i in 0..10_000 {
            map.insert(i.to_string(), vec![0; 1000]);
        }
        assert!(map.map.weight() <= 1 << 20, "{}", map.map.weight());
        // Each entry weighs 1,000 bytes, its key and the overhead: about 820 fit.
        assert!(map.len() > 700, "{}", map.len());
        assert_eq!(map.get("9999").map(|v| v.len()), Some(1000));
    }

    #[test]
    fn an_entry_expires() {
        let map = map(1 << 20, Duration::from_millis(20));
        map.insert("a".into(), vec![1]);
        assert_eq!(map.get("a"), Some(vec![1]));
        std::thread::sleep(Duration::from_millis(30));
        assert_eq!(map.get("a"), None);
        assert_eq!(map.len(), 0);
    }

    #[test]
    fn an_entry_heavier_than_a_shard_is_not_kept() {
        let map = map(1 << 20, Duration::from_secs(60));
        map.insert("big".into(), vec![0; 300 << 10]);
        assert_eq!(map.get("big"), None);
        map.insert("fits".into(), vec![0; 200 << 10]);
        assert!(map.get("fits").is_some());
    }
}
