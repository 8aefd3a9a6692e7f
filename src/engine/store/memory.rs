//! One process's job records in memory, bounded in count and in the bytes of their results.

use std::collections::HashMap;
use std::sync::Mutex;
use std::time::{Duration, SystemTime};

use uuid::Uuid;

use super::record::{JobRecord, JobResult, JobState, Refusal};
use crate::engine::clock::age;
use crate::engine::lock;

/// Where a job's result will be kept.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Place {
    Memory,
    /// The database of saved analyses (which saves every finished job's result anyway).
    Database,
}

/// The records of one process's jobs, at most `max_jobs` of them, with the results of those
/// within their retention: in memory up to `result_bytes`, and beyond it in the database
/// (if `database` is a file: an in-memory one would hold them in memory all the same).
/// Room for a result is made when its job is accepted; a job for whose result there is no
/// room is refused then, never after its work.
#[derive(Debug)]
pub struct MemoryJobStore {
    records: Mutex<Records>,
    retention: Duration,
    max_jobs: usize,
    result_bytes: u64,
    database: bool,
}

#[derive(Debug, Default)]
struct Records {
    jobs: HashMap<Uuid, JobRecord>,
    /// Room made (bytes, and where) for the results of jobs not finished yet.
    reserved: HashMap<Uuid, (u64, Place)>,
    /// Bytes held and made room for in memory.
    memory: u64,
}

impl Records {
    fn hold(&mut self, place: Place, bytes: u64) {
        if place == Place::Memory {
            self.memory += bytes;
        }
    }

    fn free(&mut self, place: Place, bytes: u64) {
        if place == Place::Memory {
            self.memory = self.memory.saturating_sub(bytes);
        }
    }

    fn forget(&mut self, id: &Uuid) {
        if let Some(record) = self.jobs.remove(id) {
            if let Some(result) = record.state.result() {
                self.free(Place::Memory, result.weight());
            }
        }
        if let Some((bytes, place)) = self.reserved.remove(id) {
            self.free(place, bytes);
        }
    }

    fn purge(&mut self, retention: Duration, now: SystemTime) -> usize {
        let expired: Vec<Uuid> = self
            .jobs
            .values()
            .filter(|r| r.expired(retention, now))
            .map(|r| r.id)
            .collect();
        for id in &expired {
            self.forget(id);
        }
        expired.len()
    }

    /// How long until the oldest finished job expires (and makes room), at most `retention`.
    fn next_expiry(&self, retention: Duration, now: SystemTime) -> Duration {
        self.jobs
            .values()
            .filter_map(|record| record.finished_at)
            .map(|t| retention.saturating_sub(age(t, now)))
            .min()
            .unwrap_or(retention)
    }
}

impl MemoryJobStore {
    pub fn new(retention: Duration, max_jobs: usize, result_bytes: u64, database: bool) -> Self {
        MemoryJobStore {
            records: Mutex::default(),
            retention,
            max_jobs: max_jobs.max(1),
            result_bytes,
            database,
        }
    }

    /// Room for a result of `bytes`: in memory if it fits there, else in a file database.
    fn room(&self, records: &Records, bytes: u64) -> Result<Place, Refusal> {
        if records.memory.saturating_add(bytes) <= self.result_bytes {
            return Ok(Place::Memory);
        }
        if self.database {
            return Ok(Place::Database);
        }
        if bytes > self.result_bytes {
            return Err(Refusal::TooLarge {
                needed: bytes,
                limit: self.result_bytes,
            });
        }
        Err(Refusal::Full {
            what: format!(
                "the results of finished jobs within their retention ({}) take {} of {} in \
                 memory (the database is in memory too: it keeps none beyond), and this job's \
                 result may take up to {}",
                humantime::format_duration(self.retention),
                megabytes(records.memory),
                megabytes(self.result_bytes),
                megabytes(bytes),
            ),
            retry_after: records.next_expiry(self.retention, SystemTime::now()),
        })
    }

    /// Keeps job `id`'s result as `stored` in the database instead of in memory.
    pub fn store_result(&self, id: Uuid, stored: JobResult) {
        let mut records = lock(&self.records);
        let Some(record) = records.jobs.get_mut(&id) else {
            return;
        };
        let held = record.state.result().map_or(0, JobResult::weight);
        record.state = record.state.clone().with_result(stored);
        records.free(Place::Memory, held);
    }

    pub async fn insert(&self, record: JobRecord) -> Result<(), Refusal> {
        let result_bytes = record.result_bytes;
        let now = SystemTime::now();
        let mut records = lock(&self.records);
        records.purge(self.retention, now);
        if records.jobs.len() >= self.max_jobs {
            return Err(Refusal::Full {
                what: format!(
                    "it keeps {} jobs, the most it may, for their retention ({})",
                    records.jobs.len(),
                    humantime::format_duration(self.retention)
                ),
                retry_after: records.next_expiry(self.retention, now),
            });
        }
        let place = self.room(&records, result_bytes)?;
        records.hold(place, result_bytes);
        records.reserved.insert(record.id, (result_bytes, place));
        records.jobs.insert(record.id, record);
        Ok(())
    }

    pub async fn get(&self, id: Uuid) -> Option<JobRecord> {
        let mut records = lock(&self.records);
        let record = records.jobs.get(&id)?;
        if record.expired(self.retention, SystemTime::now()) {
            records.forget(&id);
            return None;
        }
        Some(record.clone())
    }

    /// Moves job `id` to `state`, a job finishing now taken to have finished at `now`;
    /// returns where room was made for its result (the database: the caller moves it there,
    /// [`MemoryJobStore::store_result`], once saved).
    pub async fn update(&self, id: Uuid, state: JobState, done: usize, now: SystemTime) -> Place {
        let finishing = state.status().is_finished();
        let mut records = lock(&self.records);
        // The room made for the result, taken once: by the update that finishes the job.
        let reservation = finishing.then(|| records.reserved.remove(&id)).flatten();
        if let Some((bytes, place)) = reservation {
            records.free(place, bytes);
            if let Some(result) = state.result() {
                records.hold(Place::Memory, result.weight());
                if result.weight() > bytes {
                    tracing::warn!(
                        %id, estimate = bytes, weight = result.weight(),
                        "a result weighs more than the room made for it"
                    );
                }
            }
        }
        let place = reservation.map_or(Place::Memory, |(_, place)| place);
        let Some(record) = records.jobs.get_mut(&id) else {
            return place;
        };
        if finishing {
            record.finished_at.get_or_insert(now);
        }
        record.state = state;
        record.done = done;
        place
    }

    pub async fn remove(&self, id: Uuid) {
        lock(&self.records).forget(&id);
    }

    /// Marks job `id` as kept in memory only (its end could not be saved), or no longer.
    pub fn mark_unsaved(&self, id: Uuid, unsaved: bool) {
        if let Some(record) = lock(&self.records).jobs.get_mut(&id) {
            record.unsaved = unsaved;
        }
    }

    pub async fn purge_expired(&self) -> usize {
        lock(&self.records).purge(self.retention, SystemTime::now())
    }
}

/// `n` bytes in MB, for people.
fn megabytes(n: u64) -> String {
    format!("{:.1} MB", n as f64 / 1e6)
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::*;
    use crate::engine::archive::{Archive, IN_MEMORY};
    use crate::engine::cache::Solved;
    use crate::job::registry::KindName;
    use crate::job::{RollingJob, Work};

    /// A result whose JSON and CSV take `bytes` together, as a job keeps it.
    fn kept(bytes: usize) -> JobState {
        let (kind, half) = (KindName::of::<RollingJob>(), vec![b'x'; bytes / 2]);
        let solved = Solved::rendered("k".into(), kind, half.clone().into(), half.into());
        JobState::Succeeded(JobResult::Ready(Arc::new(solved)))
    }

    /// A job just accepted whose result may take `bytes`.
    fn record(bytes: u64) -> JobRecord {
        let kind = KindName::of::<RollingJob>();
        JobRecord::queued(Uuid::new_v4(), kind, Work::Known(1), "k").holding(bytes)
    }

    /// Inserts `n` jobs whose results may take `bytes`, ending each in `end` if given.
    async fn admit(
        store: &MemoryJobStore,
        n: usize,
        bytes: u64,
        end: Option<JobState>,
    ) -> Vec<Uuid> {
        let mut ids = Vec::new();
        for _ in 0..n {
            let record = record(bytes);
            let id = record.id;
            store.insert(record).await.unwrap();
            if let Some(end) = end.clone() {
                store.update(id, end, 1, SystemTime::now()).await;
            }
            ids.push(id);
        }
        ids
    }

    #[tokio::test]
    async fn a_result_is_kept_whole_for_its_retention_and_a_job_without_room_is_refused_before_its_work(
    ) {
        let store = MemoryJobStore::new(Duration::from_secs(60), 100, 10_000, false);
        let ids = admit(&store, 3, 3_000, None).await;
        // Room for three results of 3 kB is made: a fourth does not fit, now.
        match store.insert(record(3_000)).await {
            Err(Refusal::Full { what, retry_after }) => {
                assert!(
                    what.contains("in memory (the database is in memory too"),
                    "{what}"
                );
                assert!(retry_after <= Duration::from_secs(60));
            }
            other => panic!("{other:?}"),
        }
        // Too large for an empty store: said so, with both numbers.
        assert_eq!(
            store.insert(record(20_000)).await,
            Err(Refusal::TooLarge {
                needed: 20_000,
                limit: 10_000
            })
        );
        for id in &ids {
            store.update(*id, kept(2_500), 1, SystemTime::now()).await;
        }
        // Every result is still there, whole.
        for id in &ids {
            let state = store.get(*id).await.unwrap().state;
            assert!(matches!(state, JobState::Succeeded(JobResult::Ready(_))));
        }
        // A result that weighs less than its room gives the rest back: one more 1 kB job fits.
        store.insert(record(1_000)).await.unwrap();
        // Forgetting a job makes room.
        store.remove(ids[0]).await;
        store.insert(record(3_000)).await.unwrap();
    }

    #[tokio::test]
    async fn results_beyond_the_memory_budget_are_left_to_a_file_database() {
        let store = MemoryJobStore::new(Duration::from_secs(60), 100, 4_000, true);
        let (small, large) = (record(3_000), record(100_000));
        let (small_id, large_id) = (small.id, large.id);
        store.insert(small).await.unwrap();
        store.insert(large).await.unwrap();
        let now = SystemTime::now();
        let small_end = store.update(small_id, kept(2_000), 1, now).await;
        assert_eq!(small_end, Place::Memory);
        let large_end = store.update(large_id, kept(90_000), 1, now).await;
        assert_eq!(large_end, Place::Database);
        // Once saved there, memory holds the small result alone: room for another.
        let JobState::Succeeded(large) = store.get(large_id).await.unwrap().state else {
            panic!("the large job did not succeed");
        };
        let archive = Archive::open(IN_MEMORY, Duration::from_secs(60)).unwrap();
        store.store_result(large_id, archive.saved(large_id, &large));
        assert!(matches!(
            store.get(large_id).await.unwrap().state,
            JobState::Succeeded(JobResult::Stored(_))
        ));
        let memory = lock(&store.records).memory;
        assert!(memory < 4_000, "{memory}");
        store.insert(record(1_500)).await.unwrap();
    }

    #[tokio::test]
    async fn at_most_max_jobs_records_are_kept_and_more_are_refused_until_one_is_forgotten() {
        let store = MemoryJobStore::new(Duration::from_secs(60), 3, 1 << 20, false);
        let cancelled = JobState::Cancelled { partial: None };
        let ids = admit(&store, 3, 100, Some(cancelled)).await;
        assert!(matches!(
            store.insert(record(100)).await,
            Err(Refusal::Full { .. })
        ));
        for id in &ids {
            assert!(store.get(*id).await.is_some());
        }
        store.remove(ids[0]).await;
        store.insert(record(100)).await.unwrap();
    }

    #[tokio::test]
    async fn expired_jobs_make_room() {
        let store = MemoryJobStore::new(Duration::from_millis(20), 1, 1 << 20, false);
        let id = admit(&store, 1, 100, Some(kept(50))).await[0];
        assert!(store.insert(record(100)).await.is_err());
        tokio::time::sleep(Duration::from_millis(30)).await;
        store.insert(record(100)).await.unwrap();
        assert!(store.get(id).await.is_none());
    }
}
