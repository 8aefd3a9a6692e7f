//! Ids of asynchronous jobs, which say where they came from, so that what became of a job no
//! store knows can be told truly ([`Unknown`]).
//!
//! An id is a UUID (version 7: its first 48 bits are the Unix time in ms of its issue), with
//! a tag of the process that issued it and a 16-bit check over the rest: a random or
//! mistyped id passes the check once in 65,536.

use std::time::SystemTime;

use uuid::Uuid;

use super::clock::unix_millis;

/// Where the tag of the issuing process is, and where the check is.
const TAG: std::ops::Range<usize> = 9..12;
const CHECK: std::ops::Range<usize> = 14..16;

/// What can be told of a job id that the job store does not know.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Unknown {
    /// No run of the service gave it out.
    NeverIssued,
    /// Issued, then deleted, or expired after its retention.
    Gone,
    /// Issued by an earlier run of a process that kept its jobs in memory (its shutdown
    /// interrupted them, unless they had finished and been collected).
    EarlierRun,
    /// Issued before the job store (Redis) restarted without its data, at `since` (Unix ms).
    LostWithStore { since: u64 },
}

/// The ids one process issues.
#[derive(Clone, Copy, Debug)]
pub struct JobIds {
    tag: [u8; 3],
}

impl Default for JobIds {
    fn default() -> Self {
        let mut tag = [0; 3];
        tag.copy_from_slice(&Uuid::new_v4().as_bytes()[..3]);
        JobIds { tag }
    }
}

impl JobIds {
    pub fn next(&self) -> Uuid {
        let now = unix_millis(SystemTime::now());
        let mut bytes = *Uuid::new_v4().as_bytes();
        bytes[..6].copy_from_slice(&now.to_be_bytes()[2..]);
        bytes[6] = 0x70 | (bytes[6] & 0x0f);
        bytes[TAG].copy_from_slice(&self.tag);
        let check = check(&bytes);
        bytes[CHECK].copy_from_slice(&check);
        Uuid::from_bytes(bytes)
    }

    pub fn issued_here(&self, id: Uuid) -> bool {
        is_ours(id) && id.as_bytes()[TAG] == self.tag
    }
}

/// Whether `id` was issued by some run of the service.
pub fn is_ours(id: Uuid) -> bool {
    let bytes = id.as_bytes();
    id.get_version_num() == 7 && bytes[CHECK] == check(bytes)
}

/// When `id` was issued, in Unix ms.
pub fn issued_at(id: Uuid) -> u64 {
    let mut time = [0; 8];
    time[2..].copy_from_slice(&id.as_bytes()[..6]);
    u64::from_be_bytes(time)
}

/// FNV-1a over the bytes before the check.
fn check(bytes: &[u8; 16]) -> [u8; 2] {
    let hash = bytes[..CHECK.start]
        .iter()
        .fold(0xcbf2_9ce4_8422_2325_u64, |h, &b| {
            (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
        });
    let folded = (hash ^ (hash >> 16) ^ (hash >> 32) ^ (hash >> 48)) as u16;
    folded.to_be_bytes()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Another process's id is ours too, but not issued here.
    #[test]
    fn an_id_is_a_version_7_uuid_with_its_time_tag_and_a_check_strangers_fail() {
        let (ids, other) = (JobIds::default(), JobIds::default());
        let before = unix_millis(SystemTime::now());
        let id = ids.next();
        let after = unix_millis(SystemTime::now());
        assert_eq!(id.get_version_num(), 7);
        assert_eq!(id.get_variant(), uuid::Variant::RFC4122);
        assert!((before..=after).contains(&issued_at(id)));
        assert!(is_ours(id) && ids.issued_here(id));
        assert_ne!(id, ids.next());
        let id = other.next();
        assert!(is_ours(id));
        assert!(!ids.issued_here(id));
        // A random or mistyped id is not ours.
        assert!(!is_ours(Uuid::nil()));
        assert!(!is_ours(
            "00000000-0000-4000-8000-000000000000".parse().unwrap()
        ));
        // A digit mistyped passes once in 65,536, as a random 16-bit check would.
        let mistyped = (0..1000)
            .filter(|i| {
                let mut bytes = *ids.next().as_bytes();
                bytes[10 + i % 4] ^= 1 << (i % 8);
                is_ours(Uuid::from_bytes(bytes))
            })
            .count();
        assert!(mistyped <= 1, "{mistyped} of 1000 mistyped ids passed");
        let strangers = (0..10_000).filter(|_| is_ours(Uuid::new_v4())).count();
        assert_eq!(strangers, 0, "version 4 ids are never ours");
    }
}
