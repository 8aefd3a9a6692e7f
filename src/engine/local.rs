//! The job store of a process on its own: the records in memory while their clients collect
//! them ([`MemoryJobStore`], bounded, fast), and every job in the database of saved analyses
//! ([`Archive`]) from its acceptance to the end of the history's retention, across restarts.
//! A job that memory has forgotten is read from the database.
//!
//! A job is accepted only once its record is written there: a database that cannot be
//! written (a full disk, a damaged file) or no longer is the file at its path refuses
//! submissions, and says why in `/readyz`, until a write succeeds again. (Before, the
//! failure was only logged: after a restart 235 of 250 jobs accepted on a full disk were
//! unknown.) A job whose end cannot be saved stays in memory, marked unsaved.

use std::sync::{Arc, Mutex};
use std::time::SystemTime;

use async_trait::async_trait;
use uuid::Uuid;

use super::archive::Archive;
use super::lock;
use super::store::memory::Place;
use super::store::{
    JobRecord, JobState, JobStore, Listing, MemoryJobStore, Page, Refusal, Unreadable,
};

/// Why a write to the database failed, for the client (the log says more).
#[derive(Clone, Debug, thiserror::Error)]
#[error(
    "the database of saved analyses cannot be written now (the log says why: a full disk?), \
     so the job is not accepted, that none is lost; it is retried with every submission"
)]
struct Unwritable;

pub struct LocalJobStore {
    memory: MemoryJobStore,
    archive: Arc<Archive>,
    /// Why the last write to the database failed; none since one succeeded.
    failing: Mutex<Option<String>>,
    /// Finished jobs whose end could not be saved (memory holds them).
    unsaved: Mutex<Vec<Uuid>>,
}

impl LocalJobStore {
    pub fn new(memory: MemoryJobStore, archive: Arc<Archive>) -> LocalJobStore {
        LocalJobStore {
            memory,
            archive,
            failing: Mutex::new(None),
            unsaved: Mutex::new(Vec::new()),
        }
    }

    /// [`LocalJobStore::db`], remembering whether writes fail.
    async fn write(
        &self,
        what: &'static str,
        call: impl FnOnce(&Arc<Archive>) -> rusqlite::Result<()> + Send + 'static,
    ) -> Result<(), Unwritable> {
        let outcome = self.db(what, call).await.ok_or(Unwritable);
        *lock(&self.failing) = outcome.as_ref().err().map(Unwritable::to_string);
        outcome
    }

    /// Runs `call` on the database off the async threads; an error is logged (with `what`)
    /// and read as `None` (the record in memory still answers).
    async fn db<T: Send + 'static>(
        &self,
        what: &'static str,
        call: impl FnOnce(&Arc<Archive>) -> rusqlite::Result<T> + Send + 'static,
    ) -> Option<T> {
        let archive = self.archive.clone();
        let outcome = match super::heavy::run(move || call(&archive)).await {
            Ok(done) => done.map_err(|e| e.to_string()),
            Err(e) => Err(e.to_string()),
        };
        outcome
            .inspect_err(
                |e| tracing::error!(error = %e, "the database of saved analyses failed to {what}"),
            )
            .ok()
    }

    /// Saves the end of job `id`, its final state as memory `kept` it.
    async fn save_end(
        &self,
        id: Uuid,
        kept: JobState,
        done: usize,
        finished: SystemTime,
    ) -> Result<(), Unwritable> {
        let bodies = match kept.result() {
            Some(result) => match result.bodies().await {
                Ok(bodies) => Some(bodies),
                Err(e) => {
                    tracing::error!(error = %e, %id, "a job's result could not be read to save it");
                    None
                }
            },
            None => None,
        };
        self.write("save a job's end", move |db| {
            db.finish(id, &kept, done, finished, bodies)
        })
        .await
    }

    /// Saves the ends not saved before, of the jobs memory still holds (a full disk may have
    /// room again). Tried after every write that succeeds, and at every purge.
    async fn save_unsaved(&self) {
        let pending = std::mem::take(&mut *lock(&self.unsaved));
        for id in pending {
            let Some(record) = self.memory.get(id).await else {
                continue;
            };
            let Some(finished) = record.finished_at else {
                continue;
            };
            match self.save_end(id, record.state, record.done, finished).await {
                Ok(()) => self.memory.mark_unsaved(id, false),
                Err(_) => lock(&self.unsaved).push(id),
            }
        }
    }
}

#[async_trait]
impl JobStore for LocalJobStore {
    async fn insert(&self, record: JobRecord) -> Result<(), Refusal> {
        if let Some(why) = self.archive.moved() {
            return Err(Refusal::Unwritable { why });
        }
        let id = record.id;
        self.memory.insert(record.clone()).await?;
        if let Err(e) = self.write("save a job", move |db| db.insert(&record)).await {
            self.memory.remove(id).await;
            return Err(Refusal::Unwritable { why: e.to_string() });
        }
        self.save_unsaved().await;
        Ok(())
    }

    async fn get(&self, id: Uuid) -> Option<JobRecord> {
        match self.memory.get(id).await {
            Some(record) => Some(record),
            None => self.db("read a job", move |db| db.get(id)).await.flatten(),
        }
    }

    /// The end is saved from the state as given (as memory kept it), not read back from
    /// memory, which may have forgotten the job meanwhile; an end not saved is kept in
    /// memory, marked so, and saved once writes succeed again.
    async fn update(&self, id: Uuid, state: JobState, done: usize) {
        let status = state.status();
        if !status.is_finished() {
            self.memory.update(id, state, done, SystemTime::now()).await;
            // A start not recorded reads as the job queued: it is not lost for that.
            let _ = self
                .write("record a job's start", move |db| db.set_status(id, status))
                .await;
            return;
        }
        // The end is saved before memory shows it: a client told that the job finished
        // finds it finished after a restart too (shown first, a kill between the two left
        // it `interrupted`). A job ends once: an end already kept keeps its time.
        let ended = self.memory.get(id).await.and_then(|job| job.finished_at);
        let now = ended.unwrap_or_else(SystemTime::now);
        let result = state.result().cloned();
        let saved = self.save_end(id, state.clone(), done, now).await;
        let place = self.memory.update(id, state, done, now).await;
        match saved {
            Ok(()) => {
                // A result beyond the memory budget is read from the database from now on.
                if let Some(result) = result.filter(|_| place == Place::Database) {
                    self.memory
                        .store_result(id, self.archive.saved(id, &result));
                }
                self.save_unsaved().await
            }
            Err(_) => {
                self.memory.mark_unsaved(id, true);
                lock(&self.unsaved).push(id);
            }
        }
    }

    async fn remove(&self, id: Uuid) {
        self.memory.remove(id).await;
        self.db("delete a job", move |db| db.remove(id)).await;
    }

    async fn purge_expired(&self) -> usize {
        self.save_unsaved().await;
        let purged = self.db("forget expired jobs", |db| db.purge()).await;
        self.memory.purge_expired().await + purged.unwrap_or(0)
    }

    async fn list(&self, listing: &Listing) -> Result<Page, Unreadable> {
        let query = listing.clone();
        self.db("list jobs", move |db| db.list(&query))
            .await
            .ok_or(Unreadable::Database)
    }

    async fn with_input(&self, input_hash: &str) -> Result<Option<JobRecord>, Unreadable> {
        let hash = input_hash.to_string();
        self.db("find an input's answer", move |db| db.with_input(&hash))
            .await
            .ok_or(Unreadable::Database)
    }

    fn durable(&self) -> bool {
        self.archive.durable()
    }

    async fn settle(&self) {
        self.save_unsaved().await;
    }

    fn problem(&self) -> Option<String> {
        let failing = lock(&self.failing).clone();
        let unsaved = lock(&self.unsaved).len();
        self.archive.moved().or(failing).or_else(|| {
            (unsaved > 0).then(|| {
                format!(
                    "{unsaved} finished jobs could not be saved in the database of saved \
                         analyses (the log says why): they are kept in memory until a write \
                         succeeds"
                )
            })
        })
    }
}
