//! Solved jobs, kept by the job's cache key (hash of the canonical input and the model
//! version: equal keys, equal answers). [`ResultCache`] is the seam a shared store plugs
//! into; [`MemoryCache`], bounded in bytes and in time, is the default.

use std::sync::{Arc, OnceLock};
use std::time::{Duration, Instant};

use super::bounded::Bounded;
use super::budget;
use crate::job::registry::KindName;
use crate::job::JobError;
use crate::render::{draw_svg, Answer, Format, RenderError};
use async_trait::async_trait;
use bytes::Bytes;

/// A solved job as it is kept and sent: its JSON rendered once (a cache hit then costs no
/// serialization: measured in BENCHMARKS.md, rendering a rolling answer costs more than a
/// hit), and its CSV rendered the first time a client asks for it, from the typed answer
/// kept for that; or both renderings as another process made them (Redis, assembled parts).
#[derive(Debug)]
pub struct Solved {
    pub key: String,
    /// The job's kind (which draws its picture).
    pub kind: KindName,
    /// Whether the answer is whole: a partial one (what a stopped job finished, marked so in
    /// its `meta`) is never cached, and has no `ETag`.
    pub complete: bool,
    json: Bytes,
    csv: OnceLock<Bytes>,
    svg: OnceLock<Bytes>,
    /// The typed answer, while the CSV is still to render.
    answer: Option<Answer>,
}

impl Solved {
    /// Renders `answer` as JSON; an answer that cannot be rendered (a non-finite number)
    /// is an internal error, never a silent `null` for the client.
    pub fn new(key: String, kind: KindName, answer: Answer) -> Result<Solved, JobError> {
        let json = answer.render(Format::Json);
        let json = json.map_err(|e| JobError::Internal(e.to_string()))?;
        Ok(Solved {
            csv: OnceLock::new(),
            answer: Some(answer),
            ..Solved::rendered(key, kind, json.into(), Bytes::new())
        })
    }

    /// An answer already rendered as JSON and CSV.
    pub fn rendered(key: String, kind: KindName, json: Bytes, csv: Bytes) -> Solved {
        Solved {
            key,
            kind,
            complete: true,
            json,
            csv: OnceLock::from(csv),
            svg: OnceLock::new(),
            answer: None,
        }
    }

    /// The partial answer of a stopped job (see [`Solved::complete`]).
    pub fn partial(key: String, kind: KindName, answer: Answer) -> Result<Solved, JobError> {
        Ok(Solved {
            complete: false,
            ..Solved::new(key, kind, answer)?
        })
    }

    /// The same answer as kept for long: its CSV rendered now, the typed answer let go.
    pub fn kept(&self) -> Result<Solved, RenderError> {
        let (key, csv) = (self.key.clone(), self.body(Format::Csv)?);
        Ok(Solved {
            complete: self.complete,
            ..Solved::rendered(key, self.kind, self.json.clone(), csv)
        })
    }

    pub fn json(&self) -> &Bytes {
        &self.json
    }

    /// The answer in `format`, rendered at most once.
    pub fn body(&self, format: Format) -> Result<Bytes, RenderError> {
        match format {
            Format::Json => Ok(self.json.clone()),
            Format::Csv => once(&self.csv, || {
                let answer = self.answer.as_ref().ok_or_else(|| {
                    RenderError::new("an answer rendered elsewhere came without its CSV")
                })?;
                Ok(answer.render(Format::Csv)?.into())
            }),
            Format::Svg => once(&self.svg, || picture(self.kind, &self.json)),
        }
    }

    /// Bytes held in memory, roughly: the CSV still to render, and the typed answer kept for
    /// it, are counted at the JSON's size.
    pub fn weight(&self) -> u64 {
        let json = self.json.len();
        let csv = self.csv.get().map_or(json, Bytes::len);
        let answer = if self.answer.is_some() { json } else { 0 };
        (json + csv + answer + self.key.len()) as u64
    }
}

/// What `cell` holds, made by `make` the first time.
fn once(
    cell: &OnceLock<Bytes>,
    make: impl FnOnce() -> Result<Bytes, RenderError>,
) -> Result<Bytes, RenderError> {
    if let Some(bytes) = cell.get() {
        return Ok(bytes.clone());
    }
    let bytes = make()?;
    Ok(cell.get_or_init(|| bytes).clone())
}

pub fn picture(kind: KindName, json: &[u8]) -> Result<Bytes, RenderError> {
    draw_svg(kind.picture(), json).map(Bytes::from)
}

/// Who solves a key no cache holds yet.
pub enum Claim {
    /// This process: it solves, keeps the answer, then releases the claim.
    Mine,
    /// Another process sharing the cache solved it meanwhile.
    Solved(Arc<Solved>),
}

/// Where solved jobs are kept.
#[async_trait]
pub trait ResultCache: Send + Sync {
    async fn get(&self, key: &str) -> Option<Arc<Solved>>;
    async fn insert(&self, solved: Arc<Solved>);

    /// Keeps `solved`, which is also the result of job `job` in the fleet's job store: a
    /// cache on that same server refers to it there rather than hold it twice.
    async fn insert_result_of(&self, solved: Arc<Solved>, _job: uuid::Uuid) {
        self.insert(solved).await;
    }

    /// Claims the solve of `key` among the processes sharing the cache, waiting (until
    /// `deadline`) while another holds it. One process's cache needs none (see `coalesce`).
    async fn claim(&self, _key: &str, _deadline: Instant) -> Result<Claim, JobError> {
        Ok(Claim::Mine)
    }

    /// Gives up the claim on `key` (its answer kept, or its solve failed).
    async fn release(&self, _key: &str) {}
}

/// The cache of one process, bounded in bytes and in time.
#[derive(Clone)]
pub struct MemoryCache {
    cache: Arc<Bounded<Arc<Solved>>>,
}

impl MemoryCache {
    /// The cache of an engine with `config`: its share of the memory budget, its TTL.
    pub fn for_engine(config: &super::config::EngineConfig) -> Self {
        let answers = budget::Budget::split(config.memory_budget).answers;
        MemoryCache::new(answers, config.cache_ttl)
    }

    pub fn new(max_bytes: u64, ttl: Duration) -> Self {
        // A rolling answer, the commonest, weighs about 16 kB.
        let weigh = |solved: &Arc<Solved>| solved.weight();
        MemoryCache {
            cache: Arc::new(Bounded::new(max_bytes, ttl, 16 << 10, weigh)),
        }
    }
}

#[async_trait]
impl ResultCache for MemoryCache {
    async fn get(&self, key: &str) -> Option<Arc<Solved>> {
        self.cache.get(key)
    }

    async fn insert(&self, solved: Arc<Solved>) {
        self.cache.insert(solved.key.clone(), solved);
    }
}
