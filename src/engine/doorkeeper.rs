//! A doorkeeper in front of the input memo: an input is remembered from its second sighting
//! on. Under traffic where every input is new (a sweep scripted as single requests, a load
//! test), remembering each one cost a map insert, its eviction and the map's rehashing: about
//! a fifth of an uncached request's CPU, for entries never read. An input sent twice is
//! remembered the second time; until then it is validated again, which costs less than the
//! insert did.
//!
//! The doorkeeper is one bit per hash slot. A collision only remembers an input early, which
//! is harmless. It forgets everything once an eighth of its bits are set, so that collisions
//! stay rare and its window, in first sightings, is about the memo's own capacity.

use std::hash::BuildHasher;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};

use super::bounded::KeyHasher;

pub struct Doorkeeper {
    bits: Box<[AtomicU64]>,
    /// First sightings since the last reset.
    marked: AtomicUsize,
    hasher: KeyHasher,
}

impl Doorkeeper {
    /// For a memo of about `entries` inputs: `8 × entries` bits (at least 4,096), rounded up
    /// to a power of two.
    pub fn new(entries: u64) -> Doorkeeper {
        let bits = usize::try_from(entries.saturating_mul(8))
            .unwrap_or(usize::MAX)
            .clamp(1 << 12, 1 << 30)
            .next_power_of_two();
        Doorkeeper {
            bits: (0..bits / 64).map(|_| AtomicU64::new(0)).collect(),
            marked: AtomicUsize::new(0),
            hasher: KeyHasher::default(),
        }
    }

    /// Whether `input` was seen since the last reset; marks it seen.
    pub fn seen_before(&self, input: &str) -> bool {
        let slot = self.hasher.hash_one(input) as usize & (self.bits.len() * 64 - 1);
        let bit = 1u64 << (slot % 64);
        if self.bits[slot / 64].fetch_or(bit, Ordering::Relaxed) & bit != 0 {
            return true;
        }
        if self.marked.fetch_add(1, Ordering::Relaxed) + 1 >= self.bits.len() * 8 {
            self.marked.store(0, Ordering::Relaxed);
            for word in self.bits.iter() {
                word.store(0, Ordering::Relaxed);
            }
        }
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_input_is_seen_from_its_second_sighting() {
        let doorkeeper = Doorkeeper::new(1000);
        assert!(!doorkeeper.seen_before("rolling\n{\"load\":1e-9}"));
        assert!(doorkeeper.seen_before("rolling\n{\"load\":1e-9}"));
        assert!(!doorkeeper.seen_before("rolling\n{\"load\":2e-9}"));
    }

    #[test]
    fn it_forgets_once_an_eighth_of_its_bits_are_set() {
        let doorkeeper = Doorkeeper::new(512);
        let bits = doorkeeper.bits.len() * 64;
        assert_eq!(bits, 4096);
        assert!(!doorkeeper.seen_before("first"));
        // Distinct inputs until a reset: the first input is forgotten by then.
        let mut fresh = 0;
        for i in 0.. {
            if !doorkeeper.seen_before(&i.to_string()) {
                fresh += 1;
            }
            if doorkeeper.marked.load(Ordering::Relaxed) == 0 {
                break;
            }
        }
        assert_eq!(fresh, bits / 8 - 1);
        assert!(!doorkeeper.seen_before("first"));
    }
}
