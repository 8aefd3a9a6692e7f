//! Results too large for the memory budget, kept on disk: a directory of this process's own
//! (made at start, removed at exit), bounded in bytes by the job store's reservations. A
//! result spilled is its JSON and its CSV, two files named by the job's id; the files go
//! when the last handle on them does (the record forgotten, and no response still reading
//! them).

use std::fs;
use std::io;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use bytes::Bytes;
use uuid::Uuid;

use async_trait::async_trait;

use super::cache::Solved;
use crate::job::registry::KindName;
use crate::render::Format;

/// The directory results are spilled to.
#[derive(Debug)]
pub struct SpillDir {
    path: PathBuf,
    /// Bytes the directory may hold.
    pub limit: u64,
}

impl SpillDir {
    /// A new directory under `parent` for this process, holding at most `limit` bytes.
    pub fn create(parent: &Path, limit: u64) -> io::Result<SpillDir> {
        let path = parent.join(format!(
            "thirdbody-results-{}-{}",
            std::process::id(),
            &Uuid::new_v4().simple().to_string()[..8]
        ));
        fs::create_dir_all(&path)?;
        Ok(SpillDir { path, limit })
    }

    /// Writes the result `solved` of job `id` (its JSON and CSV, rendered); blocking.
    pub fn write(&self, id: Uuid, solved: &Solved) -> io::Result<Spilled> {
        let csv = solved
            .body(Format::Csv)
            .map_err(|e| io::Error::other(e.to_string()))?;
        let spilled = Spilled {
            key: solved.key.clone(),
            kind: solved.kind,
            complete: solved.complete,
            json: self.path.join(format!("{id}.json")),
            csv: self.path.join(format!("{id}.csv")),
            bytes: (solved.json().len() + csv.len()) as u64,
        };
        fs::write(&spilled.json, solved.json())?;
        fs::write(&spilled.csv, &csv)?;
        Ok(spilled)
    }
}

impl Drop for SpillDir {
    /// The directory goes with the process's store (its results with their records).
    fn drop(&mut self) {
        let _ = fs::remove_dir_all(&self.path);
    }
}

/// A result kept on disk.
#[derive(Debug)]
pub struct Spilled {
    /// The job's cache key.
    pub key: String,
    /// The job's kind (which draws its picture).
    pub kind: KindName,
    /// Whether the answer is whole (see [`Solved::complete`]).
    pub complete: bool,
    json: PathBuf,
    csv: PathBuf,
    /// The bytes of both files.
    pub bytes: u64,
}

impl Spilled {
    /// The file holding the answer in `format` (JSON or CSV; a picture is drawn from the
    /// JSON).
    pub fn file(&self, format: Format) -> &Path {
        match format {
            Format::Csv => &self.csv,
            Format::Json | Format::Svg => &self.json,
        }
    }

    /// Reads the answer's JSON back.
    pub async fn json(&self) -> io::Result<Bytes> {
        tokio::fs::read(&self.json).await.map(Bytes::from)
    }
}

impl Drop for Spilled {
    fn drop(&mut self) {
        let _ = fs::remove_file(&self.json);
        let _ = fs::remove_file(&self.csv);
    }
}

/// Where a result kept outside this process's memory is: the fleet's Redis, or the database
/// of saved analyses.
#[async_trait]
pub trait ResultPlace: Send + Sync {
    /// The answer as JSON (`json`) or CSV (`csv`).
    async fn body(&self, field: &str) -> io::Result<Bytes>;
}

/// A finished job's result kept outside this process's memory: status reads never carry it;
/// a client asking for it gets the one form it asks for.
#[derive(Clone)]
pub struct StoredResult {
    /// The job's cache key.
    pub key: String,
    /// The job's kind (which draws its picture).
    pub kind: KindName,
    /// Whether the answer is whole (see [`Solved::complete`]).
    pub complete: bool,
    place: Arc<dyn ResultPlace>,
}

impl StoredResult {
    pub fn new(
        key: String,
        kind: KindName,
        complete: bool,
        place: Arc<dyn ResultPlace>,
    ) -> StoredResult {
        StoredResult {
            key,
            kind,
            complete,
            place,
        }
    }

    /// The answer as JSON (`json`) or CSV (`csv`).
    pub async fn body(&self, field: &str) -> io::Result<Bytes> {
        self.place.body(field).await
    }
}

impl std::fmt::Debug for StoredResult {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("StoredResult")
            .field("key", &self.key)
            .field("complete", &self.complete)
            .finish()
    }
}

/// Where a job's result is: in memory, spilled to disk, or stored (in the fleet's Redis or
/// the database of saved analyses).
#[derive(Clone, Debug)]
pub enum JobResult {
    Ready(Arc<Solved>),
    Spilled(Arc<Spilled>),
    Stored(Arc<StoredResult>),
}

impl JobResult {
    /// Whether the answer is whole (else what a stopped job finished).
    pub fn complete(&self) -> bool {
        match self {
            JobResult::Ready(solved) => solved.complete,
            JobResult::Spilled(spilled) => spilled.complete,
            JobResult::Stored(stored) => stored.complete,
        }
    }

    /// How stores name the result's completeness: `whole` or `partial`.
    pub fn form(&self) -> &'static str {
        if self.complete() {
            "whole"
        } else {
            "partial"
        }
    }

    /// The answer's JSON and CSV (a CSV rendered now is rendered off the async threads: a
    /// large sweep's takes tens of milliseconds).
    pub async fn bodies(&self) -> io::Result<(Bytes, Bytes)> {
        match self {
            JobResult::Ready(solved) => {
                let rendering = solved.clone();
                let csv = super::heavy::run(move || rendering.body(Format::Csv))
                    .await
                    .map_err(io::Error::other)?
                    .map_err(|e| io::Error::other(e.to_string()))?;
                Ok((solved.json().clone(), csv))
            }
            JobResult::Spilled(spilled) => {
                let csv = tokio::fs::read(&spilled.csv).await?;
                Ok((spilled.json().await?, Bytes::from(csv)))
            }
            JobResult::Stored(stored) => {
                Ok((stored.body("json").await?, stored.body("csv").await?))
            }
        }
    }

    /// The answer's cache key.
    pub fn key(&self) -> &str {
        match self {
            JobResult::Ready(solved) => &solved.key,
            JobResult::Spilled(spilled) => &spilled.key,
            JobResult::Stored(stored) => &stored.key,
        }
    }

    /// Bytes held in memory, or on disk (none for a result in Redis).
    pub fn weight(&self) -> u64 {
        match self {
            JobResult::Ready(solved) => solved.weight(),
            JobResult::Spilled(spilled) => spilled.bytes,
            JobResult::Stored(_) => 0,
        }
    }
}
