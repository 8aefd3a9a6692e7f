//! Saved analyses: every job this process accepts, in an embedded SQLite database (a file
//! by default) from its acceptance, with its result once it finishes, kept for the
//! history's retention across restarts. The calls block: [`super::local::LocalJobStore`]
//! makes them off the async threads.
//!
//! One process per file: the database is locked for the process's life (SQLite's exclusive
//! locking mode), so that a second `serve` on the same file fails at start-up rather than
//! marking the first one's running jobs interrupted. A fleet keeps its history in Redis.

use std::path::Path;
use std::sync::{Arc, Mutex};
use std::time::{Duration, SystemTime};

use async_trait::async_trait;
use bytes::Bytes;
use rusqlite::{params, Connection, OptionalExtension, Params, Row};
use uuid::Uuid;

use super::clock::{from_unix_millis, unix_millis};
use super::lock;
use super::store::{JobRecord, JobState, JobStatus, Listing, Owner, Page};
use super::store::{JobResult, ResultPlace, StoredResult};
use crate::job::registry::KindName;
use crate::job::{JobError, Work};

/// The database path that keeps nothing past the process (SQLite's own name for it).
pub const IN_MEMORY: &str = ":memory:";

/// How to go on from a damaged database, said when it is refused at start-up.
const DAMAGED: &str = ": the database is damaged; move the file aside (its saved analyses are \
                       then not listed) or restore it from a backup, and start again";

/// The tables: jobs (small rows, listed) and their results (large, read one at a time).
const SCHEMA: &str = "
CREATE TABLE IF NOT EXISTS jobs (
    id TEXT PRIMARY KEY,
    owner TEXT,
    kind TEXT NOT NULL,
    status TEXT NOT NULL,
    done INTEGER NOT NULL,
    total INTEGER,
    input_hash TEXT NOT NULL,
    submitted INTEGER NOT NULL,
    finished INTEGER,
    error TEXT,
    result TEXT
    -- and result_bytes: see ADDED_COLUMN
);
CREATE INDEX IF NOT EXISTS jobs_by_owner ON jobs (owner, submitted DESC);
CREATE INDEX IF NOT EXISTS jobs_by_input ON jobs (input_hash, finished DESC);
CREATE INDEX IF NOT EXISTS jobs_by_end ON jobs (finished);
CREATE TABLE IF NOT EXISTS results (
    id TEXT PRIMARY KEY,
    json BLOB NOT NULL,
    csv BLOB NOT NULL
);
";

/// The column added to the jobs since their first version (a database made by that version
/// gets it when opened): the bytes a job's answer may take, which a tenant's quota counts.
const ADDED_COLUMN: &str = "result_bytes INTEGER NOT NULL DEFAULT 0";

/// The columns a record is read from, in [`Archive::record`]'s order.
const COLUMNS: &str = "id, owner, kind, status, done, total, input_hash, submitted, finished, \
                       error, result, result_bytes";

pub struct Archive {
    db: Mutex<Connection>,
    retention: Duration,
    /// The file and its identity (device, inode) when it was opened; none in memory.
    file: Option<(String, (u64, u64))>,
}

/// A file's device and inode: what tells it from another put in its place.
fn identity(path: &str) -> std::io::Result<(u64, u64)> {
    use std::os::unix::fs::MetadataExt;
    let meta = std::fs::metadata(path)?;
    Ok((meta.dev(), meta.ino()))
}

impl Archive {
    /// Opens (or creates) and readies (`prepare`) the database at `path` (a file, or
    /// [`IN_MEMORY`]), keeping finished jobs for `retention`.
    pub fn open(path: &str, retention: Duration) -> Result<Arc<Archive>, ArchiveError> {
        let error = |why: String| ArchiveError {
            path: path.to_string(),
            why,
        };
        let durable = path != IN_MEMORY;
        let parent = Path::new(path).parent();
        if let Some(dir) = parent.filter(|d| durable && !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir).map_err(|e| error(e.to_string()))?;
        }
        let db = Connection::open(path).map_err(hint).map_err(error)?;
        prepare(&db).map_err(error)?;
        let file = durable.then(|| identity(path).map(|id| (path.to_string(), id)));
        let archive = Arc::new(Archive {
            db: Mutex::new(db),
            retention,
            file: file.transpose().map_err(|e| error(e.to_string()))?,
        });
        archive.purge().map_err(hint).map_err(error)?;
        Ok(archive)
    }

    /// `result` of job `id` as the database keeps it (once its end is saved).
    pub fn saved(self: &Arc<Self>, id: Uuid, result: &JobResult) -> JobResult {
        let (key, kind) = (result.key().to_string(), result.kind());
        self.stored(id, key, kind, result.complete())
    }

    fn stored(self: &Arc<Self>, id: Uuid, key: String, kind: KindName, whole: bool) -> JobResult {
        let saved = Arc::new(Saved {
            archive: self.clone(),
            id,
        });
        JobResult::Stored(Arc::new(StoredResult {
            key,
            kind,
            complete: whole,
            place: saved,
        }))
    }

    /// Whether the database is a file (it outlives the process).
    pub fn durable(&self) -> bool {
        self.file.is_some()
    }

    /// Why what is written now would be lost at a restart, if it would: the file opened was
    /// removed or replaced while the process runs.
    pub fn moved(&self) -> Option<String> {
        let (path, opened) = self.file.as_ref()?;
        let now = identity(path);
        if now.as_ref().is_ok_and(|now| now == opened) {
            return None;
        }
        let what = if now.is_err() { "removed" } else { "replaced" };
        Some(format!(
            "the database of saved analyses {path} was {what} while the service runs: what it \
             saves now is lost at a restart; restart the service to open the file at that path"
        ))
    }

    /// The earliest end (Unix ms) of a job still within its retention.
    fn cutoff(&self) -> i64 {
        let retention = i64::try_from(self.retention.as_millis()).unwrap_or(i64::MAX);
        millis(SystemTime::now()).saturating_sub(retention)
    }

    /// Records a job just accepted (its end is [`Archive::finish`]'s).
    pub fn insert(&self, record: &JobRecord) -> rusqlite::Result<()> {
        let total = match record.work {
            Work::Known(n) => Some(n as i64),
            Work::Unknown => None,
        };
        lock(&self.db).execute(
            "INSERT OR IGNORE INTO jobs (id, owner, kind, status, done, total, input_hash, \
             submitted, result_bytes) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9)",
            params![
                record.id.to_string(),
                record.owner.as_ref().map(Owner::as_str),
                record.kind.name(),
                record.state.status().as_str(),
                record.done as i64,
                total,
                record.input_hash,
                millis(record.submitted_at),
                i64::try_from(record.result_bytes).unwrap_or(i64::MAX),
            ],
        )?;
        Ok(())
    }

    /// Ends the job `id`, with its result's JSON and CSV (`bodies`) if they could be read; a
    /// job deleted meanwhile or already ended stays as it is.
    pub fn finish(
        &self,
        id: Uuid,
        state: &JobState,
        done: usize,
        finished: SystemTime,
        bodies: Option<(Bytes, Bytes)>,
    ) -> rusqlite::Result<()> {
        let mut db = lock(&self.db);
        let tx = db.transaction()?;
        let error = match state {
            JobState::Failed { error, .. } => serde_json::to_string(error).ok(),
            _ => None,
        };
        // A result is named only when its bodies are written with it.
        let result = state
            .result()
            .filter(|_| bodies.is_some())
            .map(JobResult::form);
        let ended = tx.execute(
            "UPDATE jobs SET status = ?2, done = ?3, finished = ?4, error = ?5, result = ?6 \
             WHERE id = ?1 AND finished IS NULL",
            params![
                id.to_string(),
                state.status().as_str(),
                done as i64,
                millis(finished),
                error,
                result,
            ],
        )?;
        if let (1, Some((json, csv))) = (ended, bodies) {
            tx.execute(
                "INSERT OR REPLACE INTO results (id, json, csv) VALUES (?1, ?2, ?3)",
                params![id.to_string(), &json[..], &csv[..]],
            )?;
        }
        tx.commit()
    }

    /// Moves the job `id` to `status` (a job started), unless it has finished.
    pub fn set_status(&self, id: Uuid, status: JobStatus) -> rusqlite::Result<()> {
        lock(&self.db).execute(
            "UPDATE jobs SET status = ?2 WHERE id = ?1 AND finished IS NULL",
            params![id.to_string(), status.as_str()],
        )?;
        Ok(())
    }

    /// The job `id`, unless unknown or past its retention.
    pub fn get(self: &Arc<Self>, id: Uuid) -> rusqlite::Result<Option<JobRecord>> {
        let sql = format!(
            "SELECT {COLUMNS} FROM jobs WHERE id = ?1 AND (finished IS NULL OR finished > ?2)"
        );
        self.one(&sql, params![id.to_string(), self.cutoff()])
    }

    /// The record that `sql` finds with `params`, if any (and readable).
    fn one(
        self: &Arc<Self>,
        sql: &str,
        params: impl Params,
    ) -> rusqlite::Result<Option<JobRecord>> {
        let row = lock(&self.db)
            .query_row(sql, params, |row| self.record(row))
            .optional()?;
        Ok(row.flatten())
    }

    /// The jobs of `listing`'s owner within their retention, newest first, filtered, paged.
    pub fn list(self: &Arc<Self>, listing: &Listing) -> rusqlite::Result<Page> {
        let filter = "owner = ?1 AND (?2 IS NULL OR kind = ?2) AND (?3 IS NULL OR status = ?3) \
                      AND (finished IS NULL OR finished > ?4)";
        let db = lock(&self.db);
        let (owner, kind, status) = (
            listing.owner.as_str(),
            listing.kind.map(|k| k.name()),
            listing.status.map(JobStatus::as_str),
        );
        let (cutoff, limit, offset) = (self.cutoff(), listing.limit as i64, listing.offset as i64);
        let all = params![owner, kind, status, cutoff, limit, offset];
        let count = format!("SELECT COUNT(*) FROM jobs WHERE {filter}");
        let total: i64 = db.query_row(&count, &all[..4], |row| row.get(0))?;
        // Jobs accepted in the same millisecond are in the order they were accepted (the
        // row id grows with each insert; ids are random past their millisecond).
        let sql = format!(
            "SELECT {COLUMNS} FROM jobs WHERE {filter} ORDER BY submitted DESC, rowid DESC \
             LIMIT ?5 OFFSET ?6"
        );
        let mut statement = db.prepare(&sql)?;
        let rows = statement.query_map(all, |row| self.record(row))?;
        let jobs: Vec<Option<JobRecord>> = rows.collect::<rusqlite::Result<_>>()?;
        Ok(Page {
            jobs: jobs.into_iter().flatten().collect(),
            total: total as usize,
        })
    }

    /// The newest job within its retention that succeeded on the input `input_hash`.
    pub fn with_input(self: &Arc<Self>, input_hash: &str) -> rusqlite::Result<Option<JobRecord>> {
        let sql = format!(
            "SELECT {COLUMNS} FROM jobs WHERE input_hash = ?1 AND status = 'succeeded' \
             AND finished > ?2 ORDER BY finished DESC LIMIT 1"
        );
        self.one(&sql, params![input_hash, self.cutoff()])
    }

    pub fn remove(&self, id: Uuid) -> rusqlite::Result<()> {
        let mut db = lock(&self.db);
        let tx = db.transaction()?;
        tx.execute("DELETE FROM results WHERE id = ?1", [id.to_string()])?;
        tx.execute("DELETE FROM jobs WHERE id = ?1", [id.to_string()])?;
        tx.commit()
    }

    /// Forgets the jobs past their retention; how many.
    pub fn purge(&self) -> rusqlite::Result<usize> {
        let cutoff = self.cutoff();
        let mut db = lock(&self.db);
        let tx = db.transaction()?;
        tx.execute(
            "DELETE FROM results WHERE id IN (SELECT id FROM jobs WHERE finished <= ?1)",
            [cutoff],
        )?;
        let purged = tx.execute("DELETE FROM jobs WHERE finished <= ?1", [cutoff])?;
        tx.commit()?;
        Ok(purged)
    }

    /// The result of job `id` as JSON (`json`) or CSV (`csv`).
    fn body(&self, id: Uuid, field: &str) -> rusqlite::Result<Option<Vec<u8>>> {
        let column = if field == "csv" { "csv" } else { "json" };
        lock(&self.db)
            .query_row(
                &format!("SELECT {column} FROM results WHERE id = ?1"),
                [id.to_string()],
                |row| row.get(0),
            )
            .optional()
    }

    /// The record of a row of `COLUMNS`; `None` for one this version cannot read.
    fn record(self: &Arc<Self>, row: &Row<'_>) -> rusqlite::Result<Option<JobRecord>> {
        let text = |i: usize| row.get::<_, String>(i);
        let Ok(id) = Uuid::parse_str(&text(0)?) else {
            return Ok(None);
        };
        let Ok(kind) = KindName::find(&text(2)?) else {
            return Ok(None);
        };
        let input_hash = text(6)?;
        let result = row.get::<_, Option<String>>(10)?;
        let result = result.map(|form| self.stored(id, input_hash.clone(), kind, form == "whole"));
        let error = || -> JobError {
            row.get::<_, Option<String>>(9)
                .ok()
                .flatten()
                .and_then(|e| serde_json::from_str(&e).ok())
                .unwrap_or_else(|| JobError::Internal("the job's error is unreadable".into()))
        };
        let status = JobStatus::parse(&text(3)?).unwrap_or(JobStatus::Failed);
        let state = JobState::restored(status, result, error);
        Ok(Some(JobRecord {
            id,
            kind,
            work: row
                .get::<_, Option<i64>>(5)?
                .map_or(Work::Unknown, |n| Work::Known(n as usize)),
            state,
            done: row.get::<_, i64>(4)? as usize,
            input_hash,
            owner: row.get::<_, Option<String>>(1)?.map(Owner::stored),
            submitted_at: time(row.get(7)?),
            finished_at: row.get::<_, Option<i64>>(8)?.map(time),
            result_bytes: u64::try_from(row.get::<_, i64>(11)?).unwrap_or(0),
            unsaved: false,
        }))
    }
}

/// Readies the connection `db`: its locking and journal, a quick check of its integrity,
/// its tables (as this version has them); jobs an earlier run left unfinished are marked
/// interrupted, as that run stopped before they ended. The reason, if it cannot be used.
fn prepare(db: &Connection) -> Result<(), String> {
    // WAL with synchronous NORMAL: a transaction committed is in the file's log before the
    // call returns, so a killed process loses nothing; the log is synced to the disk at each
    // checkpoint, so a power cut may lose the last transactions (RELIABILITY.md).
    db.execute_batch(
        "PRAGMA locking_mode = EXCLUSIVE;
         PRAGMA journal_mode = WAL;
         PRAGMA synchronous = NORMAL;",
    )
    .map_err(hint)?;
    let check: String = db
        .query_row("PRAGMA quick_check", [], |row| row.get(0))
        .map_err(hint)?;
    if check != "ok" {
        return Err(format!("{check}{DAMAGED}"));
    }
    db.execute_batch(SCHEMA).map_err(hint)?;
    let added: i64 = db
        .query_row(
            "SELECT COUNT(*) FROM pragma_table_info('jobs') WHERE name = 'result_bytes'",
            [],
            |row| row.get(0),
        )
        .map_err(hint)?;
    if added == 0 {
        db.execute_batch(&format!("ALTER TABLE jobs ADD COLUMN {ADDED_COLUMN}"))
            .map_err(hint)?;
    }
    let interrupted = db
        .execute(
            "UPDATE jobs SET status = 'interrupted', finished = ?1 WHERE finished IS NULL",
            [millis(SystemTime::now())],
        )
        .map_err(hint)?;
    if interrupted > 0 {
        tracing::warn!(
            jobs = interrupted,
            "jobs left unfinished by the last run are marked interrupted"
        );
    }
    Ok(())
}

/// `e`, with how to go on from it when that is known.
fn hint(e: rusqlite::Error) -> String {
    let hint = match e.sqlite_error_code() {
        Some(rusqlite::ErrorCode::DatabaseBusy | rusqlite::ErrorCode::DatabaseLocked) => {
            ": another thirdbody process has it open (give each process its own --database; a \
             fleet keeps its history in Redis)"
        }
        Some(rusqlite::ErrorCode::DatabaseCorrupt | rusqlite::ErrorCode::NotADatabase) => DAMAGED,
        _ => "",
    };
    format!("{e}{hint}")
}

/// `time` as stored: Unix ms (SQLite's integers are signed).
fn millis(time: SystemTime) -> i64 {
    i64::try_from(unix_millis(time)).unwrap_or(i64::MAX)
}

fn time(unix_ms: i64) -> SystemTime {
    from_unix_millis(u64::try_from(unix_ms).unwrap_or(0))
}

#[derive(Debug, thiserror::Error)]
#[error("--database {path}: {why}")]
pub struct ArchiveError {
    path: String,
    why: String,
}

struct Saved {
    archive: Arc<Archive>,
    id: Uuid,
}

#[async_trait]
impl ResultPlace for Saved {
    async fn body(&self, field: &str) -> std::io::Result<Bytes> {
        let (archive, id, field) = (self.archive.clone(), self.id, field.to_string());
        let body = super::heavy::run(move || archive.body(id, &field))
            .await
            .map_err(std::io::Error::other)?
            .map_err(std::io::Error::other)?;
        body.map(Bytes::from).ok_or_else(|| {
            std::io::Error::other("the job's result was deleted, or expired, meanwhile")
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::job::RollingJob;

    /// A database made before jobs counted their answers' bytes gains the column when
    /// opened: its jobs hold nothing, new ones what they said.
    #[test]
    fn a_database_of_an_earlier_version_gains_the_bytes_column() {
        let path = std::env::temp_dir().join(format!("thirdbody-{}.db", Uuid::new_v4()));
        let path = path.to_str().unwrap().to_string();
        let owner = Owner::of_tenant("lab");
        let old = Uuid::new_v4();
        {
            let db = Connection::open(&path).unwrap();
            db.execute_batch(SCHEMA).unwrap();
            db.execute(
                "INSERT INTO jobs (id, owner, kind, status, done, input_hash, submitted) \
                 VALUES (?1, ?2, 'rolling', 'queued', 0, 'k', 1)",
                params![old.to_string(), owner.as_str()],
            )
            .unwrap();
        }
        let archive = Archive::open(&path, Duration::from_secs(60)).unwrap();
        let new = JobRecord::queued(
            Uuid::new_v4(),
            KindName::of::<RollingJob>(),
            Work::Known(1),
            "k",
        )
        .owned_by(Some(owner.clone()))
        .holding(4096);
        archive.insert(&new).unwrap();
        let listing = Listing {
            owner,
            kind: None,
            status: None,
            offset: 0,
            limit: 10,
        };
        let held: Vec<(Uuid, u64)> = archive
            .list(&listing)
            .unwrap()
            .jobs
            .iter()
            .map(|job| (job.id, job.result_bytes))
            .collect();
        assert_eq!(held, [(new.id, 4096), (old, 0)]);
        drop(archive);
        for suffix in ["", "-wal", "-shm"] {
            let _ = std::fs::remove_file(format!("{path}{suffix}"));
        }
    }
}
