//! The job store of a process on its own: the records in memory while their clients collect
//! them ([`MemoryJobStore`], bounded, fast), and every job in the database of saved analyses
//! ([`Archive`]) from its acceptance to the end of the history's retention, across restarts.
//! A job that memory has forgotten is read from the database.

use std::sync::Arc;

use async_trait::async_trait;
use uuid::Uuid;

use super::archive::Archive;
use super::store::{JobRecord, JobState, JobStore, Listing, MemoryJobStore, Page, Refusal};

/// Why a read of the database failed, for the client (the log says more).
const UNREADABLE: &str = "the database of saved analyses cannot be read now (the log says why)";

/// A process's jobs: in memory, and in its database.
pub struct LocalJobStore {
    memory: MemoryJobStore,
    archive: Arc<Archive>,
}

impl LocalJobStore {
    pub fn new(memory: MemoryJobStore, archive: Arc<Archive>) -> LocalJobStore {
        LocalJobStore { memory, archive }
    }

    /// Runs `call` on the database off the async threads; an error is logged with `what`
    /// was being done, and read as `None` (the record in memory still answers).
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
}

#[async_trait]
impl JobStore for LocalJobStore {
    async fn insert(&self, record: JobRecord) -> Result<(), Refusal> {
        self.memory.insert(record.clone()).await?;
        self.db("save a job", move |db| db.insert(&record)).await;
        Ok(())
    }

    async fn get(&self, id: Uuid) -> Option<JobRecord> {
        match self.memory.get(id).await {
            Some(record) => Some(record),
            None => self.db("read a job", move |db| db.get(id)).await.flatten(),
        }
    }

    /// The end is saved from the state as given (as memory kept it), not read back from
    /// memory, which may have forgotten the job meanwhile.
    async fn update(&self, id: Uuid, state: JobState, done: usize) {
        let status = state.status();
        let (kept, finished) = self.memory.update(id, state, done).await;
        let Some(finished) = finished else {
            self.db("record a job's start", move |db| db.set_status(id, status))
                .await;
            return;
        };
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
        self.db("save a job's end", move |db| {
            db.finish(id, &kept, done, finished, bodies)
        })
        .await;
    }

    async fn remove(&self, id: Uuid) {
        self.memory.remove(id).await;
        self.db("delete a job", move |db| db.remove(id)).await;
    }

    async fn purge_expired(&self) -> usize {
        let purged = self.db("forget expired jobs", |db| db.purge()).await;
        self.memory.purge_expired().await + purged.unwrap_or(0)
    }

    async fn list(&self, listing: &Listing) -> Result<Page, String> {
        let query = listing.clone();
        self.db("list jobs", move |db| db.list(&query))
            .await
            .ok_or_else(|| UNREADABLE.to_string())
    }

    async fn with_input(&self, input_hash: &str) -> Result<Option<JobRecord>, String> {
        let hash = input_hash.to_string();
        self.db("find an input's answer", move |db| db.with_input(&hash))
            .await
            .ok_or_else(|| UNREADABLE.to_string())
    }

    fn durable(&self) -> bool {
        self.archive.durable()
    }
}
