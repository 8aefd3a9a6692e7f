//! A job kind is one type behind one trait ([`Kind`]): it validates its input, gives its
//! canonical form (and so its cache key), says how much work it takes, and runs under a
//! [`Control`] to an answer the render layer can write in every format. [`Job`] holds any
//! validated job, whatever its kind, and [`KindName`] names its kind as answers and records
//! carry it; the registry ([`super::registry`]) lists the kinds, finds one by its name on
//! the wire and reads a job from JSON.

use std::any::Any;
use std::borrow::Cow;
use std::fmt;
use std::ops::Range;
use std::sync::Arc;

use serde::{Serialize, Serializer};
use serde_json::Value;
use utoipa::openapi::{Ref, RefOr, Schema};
use utoipa::{PartialSchema, ToSchema};

use super::meta::{Canonical, InputWarning, Meta, References};
use super::{Control, JobError, Limits};
use crate::render::{draw, Answer, Draw, Output, UnitTable};

/// Schemas as utoipa collects them: (name, schema).
pub(super) type Schemas = Vec<(String, RefOr<Schema>)>;

/// How much work a job takes, in the units its [`Control`] counts (rolling solves for the
/// kinds that solve contacts); `Unknown` for a job that cannot tell in advance (an
/// iterative one).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Work {
    Known(usize),
    Unknown,
}

impl Work {
    /// The units the job counts for where it must count for something (the queue's
    /// estimate, a quota's points): its own, or one when it cannot tell.
    pub fn units(self) -> usize {
        match self {
            Work::Known(units) => units,
            Work::Unknown => 1,
        }
    }
}

/// What a job is estimated to cost before it runs: the points a quota charges for it and the
/// working memory its solve holds at once, which the engine sets aside before the solve
/// allocates it.
///
/// A point is about ten microseconds of a solver thread, a local-law answer's work: a local
/// sweep costs a point a point, as it always has, and a continuum answer what its grids
/// cost ([`Cost::continuum`]: 7,000 points on the default grid, up to about 800,000 on the
/// largest), the same on every machine. An iterative job guesses at its iterations; what it
/// really took is charged after it ran ([`Cost::of_time`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Cost {
    pub points: u64,
    /// Bytes.
    pub bytes: u64,
}

/// Points of a continuum answer a reference cost ([`crate::model::continuum::Plan::cost`]:
/// three marches on 4,096 fine pixels): about 20 ms in a release build.
const CONTINUUM_POINTS: f64 = 2000.0;

/// A point's time on a solver thread.
pub const POINT_TIME: std::time::Duration = std::time::Duration::from_micros(10);

impl Cost {
    /// The time it is estimated to take on a solver thread, in seconds.
    pub fn seconds(&self) -> f64 {
        self.points as f64 * POINT_TIME.as_secs_f64()
    }

    /// `points` of work that holds no memory worth counting.
    pub fn points(points: u64) -> Cost {
        Cost { points, bytes: 0 }
    }

    /// A continuum answer's, as `plan` sizes it (a point at least).
    pub fn continuum(plan: &crate::model::continuum::Plan) -> Cost {
        Cost {
            points: (plan.cost() * CONTINUUM_POINTS).ceil().max(1.0) as u64,
            bytes: plan.bytes(),
        }
    }

    /// This and `other` one after the other: their points, the larger memory.
    pub fn then(self, other: Cost) -> Cost {
        Cost {
            points: self.points.saturating_add(other.points),
            bytes: self.bytes.max(other.bytes),
        }
    }

    /// This `times` over, one after the other.
    pub fn times(self, times: u64) -> Cost {
        Cost {
            points: self.points.saturating_mul(times),
            bytes: self.bytes,
        }
    }

    /// The points `time` on a solver thread is worth (what a job really cost).
    pub fn of_time(time: std::time::Duration) -> u64 {
        (time.as_nanos() / POINT_TIME.as_nanos()).max(1) as u64
    }
}

/// A job of kind `K` as validated, and what was implausible in its input.
#[derive(Debug)]
pub struct Validated<K> {
    pub job: K,
    pub warnings: Vec<InputWarning>,
}

impl<K> From<K> for Validated<K> {
    /// A job whose input raised no warning.
    fn from(job: K) -> Self {
        Validated {
            job,
            warnings: Vec::new(),
        }
    }
}

/// A kind of job.
pub trait Kind: fmt::Debug + Send + Sync + Sized + 'static {
    /// The kind's name on the wire: the `kind` of a job envelope and of a job's status.
    const NAME: &'static str;
    /// The input as the wire has it (its OpenAPI schema).
    type Input: ToSchema;
    /// The answer.
    type Output: Output + ToSchema;

    /// Reads and validates an input of this kind; error paths are relative to the input.
    fn validate(input: Value, limits: &Limits) -> Result<Validated<Self>, JobError>;

    /// The canonical input: every default filled in, every quantity an SI number. Equal
    /// canonical inputs have equal answers.
    fn canonical(&self) -> Value;

    /// The canonical input's text, which its cache key is the hash of: [`Kind::canonical`]
    /// written out. Rolling and three-body jobs, solved on requests that must answer fast,
    /// write it straight from their input struct
    /// ([`crate::job::input::canonical_text`]) instead.
    fn canonical_text(&self) -> Canonical {
        Canonical::new(&self.canonical())
    }

    /// The papers behind the answer.
    fn references(&self) -> &'static References;

    /// The work the job takes.
    fn work(&self) -> Work;

    /// What the job is estimated to cost ([`Cost`]): by default a point per unit of work,
    /// and no memory worth counting.
    fn cost(&self) -> Cost {
        Cost::points(self.work().units() as u64)
    }

    /// The jobs whose solve times estimate this one's cost per unit of work (admission by
    /// cost): the kind, unless its units cost differently within it.
    fn cost_class(&self) -> &'static str {
        Self::NAME
    }

    /// Runs the job to its answer, whose `meta` is `meta`. A long job checks `control`
    /// between units of work, and counts them there.
    fn run(&self, meta: Meta, control: &Control) -> Result<Self::Output, JobError>;

    /// The number of points the job splits into, for a job whose answer is one row per
    /// point, `{"points": [...], "meta": {...}}` (a sweep): parts of it can then be solved
    /// apart, by other processes, and assembled ([`super::parts`]). `None`: solved whole.
    fn points(&self) -> Option<usize> {
        None
    }

    /// The unit table of this job's answer (its `meta.units`): the output's, unless an answer
    /// holds only some of the output's fields (a rolling sweep's rows are not a three-body
    /// sweep's).
    fn answer_units(&self) -> &'static UnitTable {
        Self::Output::UNITS
    }

    /// Whether the job is certain to take no more than about a hundred microseconds: the
    /// engine then runs it on the request's own thread, which is cheaper than handing it to
    /// a solver thread and back (BENCHMARKS.md). No by default.
    fn small(&self) -> bool {
        false
    }

    /// Why the job is not answered synchronously, if so: one that takes minutes belongs in
    /// `POST /v1/jobs`, where its progress shows and a cancel stops it, rather than on a
    /// request that would wait out the solve deadline for a 504. None by default.
    fn asynchronous_only(&self) -> Option<JobError> {
        None
    }

    /// Bytes the answer's JSON and CSV take together, at most: an asynchronous job's store
    /// makes room for its result before accepting it ([`crate::engine::store::JobStore`]).
    /// An answer of a few kilobytes by default; kinds whose answer grows with their input
    /// say how.
    fn result_bytes(&self) -> u64 {
        SMALL_ANSWER
    }

    /// Why an answer of this kind is unfinished, if it is: a job that keeps partial work (a
    /// sweep, a fit) answers with what it finished when it is cancelled or runs out of time,
    /// and says so here. `None` by default: an answer is whole.
    fn unfinished(output: &Self::Output) -> Option<JobError> {
        let _ = output;
        None
    }

    /// The answer with the rows of points `range` only (for a job that splits: see
    /// [`Kind::points`]).
    fn run_points(
        &self,
        meta: Meta,
        range: Range<usize>,
        control: &Control,
    ) -> Result<Self::Output, JobError> {
        let _ = range;
        self.run(meta, control)
    }
}

/// A registered kind: its name and what the rest of the crate needs of it without knowing
/// its type.
pub struct Registered {
    pub(super) name: &'static str,
    validate: fn(Value, &Limits) -> Result<Job, JobError>,
    picture: Draw,
    input_schema: fn() -> Cow<'static, str>,
    pub(super) output_schema: fn(&mut Schemas) -> RefOr<Schema>,
    output_name: fn() -> Cow<'static, str>,
    units: &'static UnitTable,
}

impl Registered {
    /// The kind's name on the wire.
    pub fn name(&self) -> &'static str {
        self.name
    }

    pub(super) const fn of<K: Kind>() -> Registered {
        Registered {
            name: K::NAME,
            validate: validate::<K>,
            picture: draw::<<K::Output as Output>::Picture>,
            input_schema: <K::Input as ToSchema>::name,
            output_schema: output_schema::<K>,
            output_name: <K::Output as ToSchema>::name,
            units: K::Output::UNITS,
        }
    }

    /// The name of the OpenAPI schema of the kind's input.
    pub fn input_name(&self) -> Cow<'static, str> {
        (self.input_schema)()
    }

    /// The name of the OpenAPI schema of the kind's answer.
    pub fn output_name(&self) -> Cow<'static, str> {
        (self.output_name)()
    }

    /// The unit of every numeric field of the kind's answer, by path.
    pub fn units(&self) -> &'static UnitTable {
        self.units
    }

    /// Reads and validates an input of this kind.
    pub fn validate(&self, input: Value, limits: &Limits) -> Result<Job, JobError> {
        (self.validate)(input, limits)
    }
}

fn validate<K: Kind>(input: Value, limits: &Limits) -> Result<Job, JobError> {
    K::validate(input, limits).map(Job::validated)
}

/// Adds the schema of `K`'s output (and those it refers to) to `schemas`; returns a
/// reference to it.
fn output_schema<K: Kind>(schemas: &mut Schemas) -> RefOr<Schema> {
    let name = K::Output::name();
    schemas.push((name.to_string(), K::Output::schema()));
    K::Output::schemas(schemas);
    Ref::from_schema_name(name).into()
}

/// A registered kind, as answers, records and pictures carry it: its name on the wire and
/// what the registry knows of it, without a look-up by name.
#[derive(Clone, Copy)]
pub struct KindName(pub(super) &'static Registered);

impl KindName {
    /// Kind `K`.
    pub const fn of<K: Kind>() -> KindName {
        KindName(const { &Registered::of::<K>() })
    }

    pub fn name(self) -> &'static str {
        self.0.name
    }

    /// How an answer of this kind is drawn ([`Output::Picture`], drawn by [`crate::render::draw`]).
    pub fn picture(self) -> Draw {
        self.0.picture
    }
}

impl PartialEq for KindName {
    fn eq(&self, other: &KindName) -> bool {
        self.name() == other.name()
    }
}

impl Eq for KindName {}

impl PartialEq<&str> for KindName {
    fn eq(&self, other: &&str) -> bool {
        self.name() == *other
    }
}

impl fmt::Debug for KindName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl fmt::Display for KindName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl Serialize for KindName {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

/// A job that stopped before its end: why, and the answer with what it finished, for a kind
/// that keeps partial work ([`Kind::unfinished`]).
#[derive(Debug)]
pub struct Unfinished {
    pub error: JobError,
    pub partial: Option<Answer>,
}

impl From<JobError> for Unfinished {
    fn from(error: JobError) -> Self {
        Unfinished {
            error,
            partial: None,
        }
    }
}

/// The answer of `output`, or the partial answer of an unfinished run.
fn answer<K: Kind>(output: K::Output) -> Result<Answer, Unfinished> {
    match K::unfinished(&output) {
        None => Ok(Answer::new(output)),
        Some(error) => Err(Unfinished {
            error,
            partial: Some(Answer::new(output)),
        }),
    }
}

/// Bytes an answer of fixed size (a rolling contact with its default boundary, a three-body
/// system) takes at most in JSON and CSV, with its `meta` (measured: 6 to 7 kB).
pub const SMALL_ANSWER: u64 = 24 << 10;

/// What [`Job`] needs of a kind, object-safe.
trait Dispatch: fmt::Debug + Send + Sync {
    fn kind(&self) -> KindName;
    fn canonical(&self) -> Value;
    fn canonical_text(&self) -> Canonical;
    fn references(&self) -> &'static References;
    fn work(&self) -> Work;
    fn cost_class(&self) -> &'static str;
    fn small(&self) -> bool;
    fn asynchronous_only(&self) -> Option<JobError>;
    fn result_bytes(&self) -> u64;
    fn run(&self, meta: Meta, control: &Control) -> Result<Answer, Unfinished>;
    fn points(&self) -> Option<usize>;
    fn run_points(
        &self,
        meta: Meta,
        range: Range<usize>,
        control: &Control,
    ) -> Result<Answer, Unfinished>;
    fn units(&self) -> &'static crate::render::UnitTable;
    fn as_any(&self) -> &dyn Any;
}

impl<K: Kind> Dispatch for K {
    fn kind(&self) -> KindName {
        KindName::of::<K>()
    }

    fn canonical(&self) -> Value {
        Kind::canonical(self)
    }

    fn canonical_text(&self) -> Canonical {
        Kind::canonical_text(self)
    }

    fn references(&self) -> &'static References {
        Kind::references(self)
    }

    fn work(&self) -> Work {
        Kind::work(self)
    }

    fn cost_class(&self) -> &'static str {
        Kind::cost_class(self)
    }

    fn small(&self) -> bool {
        Kind::small(self)
    }

    fn asynchronous_only(&self) -> Option<JobError> {
        Kind::asynchronous_only(self)
    }

    fn result_bytes(&self) -> u64 {
        Kind::result_bytes(self)
    }

    fn run(&self, meta: Meta, control: &Control) -> Result<Answer, Unfinished> {
        answer::<K>(Kind::run(self, meta, control)?)
    }

    fn points(&self) -> Option<usize> {
        Kind::points(self)
    }

    fn run_points(
        &self,
        meta: Meta,
        range: Range<usize>,
        control: &Control,
    ) -> Result<Answer, Unfinished> {
        answer::<K>(Kind::run_points(self, meta, range, control)?)
    }

    fn units(&self) -> &'static crate::render::UnitTable {
        self.answer_units()
    }

    fn as_any(&self) -> &dyn Any {
        self
    }
}

/// A validated job of any kind, ready for the engine (cheap to clone).
#[derive(Clone, Debug)]
pub struct Job {
    kind: Arc<dyn Dispatch>,
    warnings: Vec<InputWarning>,
    /// Estimated once, where the job is validated (a continuum sweep plans every point).
    cost: Cost,
}

impl Job {
    /// A job of kind `K`.
    pub fn new<K: Kind>(job: K) -> Job {
        Job::validated(job.into())
    }

    /// A validated job of kind `K`, with its input's warnings.
    pub fn validated<K: Kind>(validated: Validated<K>) -> Job {
        Job {
            cost: validated.job.cost(),
            kind: Arc::new(validated.job),
            warnings: validated.warnings,
        }
    }

    /// What was implausible in the job's input.
    pub fn warnings(&self) -> &[InputWarning] {
        &self.warnings
    }

    /// The job's kind.
    pub fn kind(&self) -> KindName {
        self.kind.kind()
    }

    /// What its cost per unit of work is estimated from ([`Kind::cost_class`]).
    pub fn cost_class(&self) -> &'static str {
        self.kind.cost_class()
    }

    /// The canonical input: every default filled in, every quantity an SI number.
    pub fn canonical(&self) -> Value {
        self.kind.canonical()
    }

    /// The `meta` block of the job's answer: model version, canonical input and its hash,
    /// references. Computing it costs a few µs, so a caller that needs both the key and the
    /// answer computes it once and passes it on.
    pub fn meta(&self) -> Meta {
        let kind = &self.kind;
        Meta::new(
            kind.kind().name(),
            kind.canonical_text(),
            kind.references(),
            self.warnings.clone(),
            kind.units(),
        )
    }

    /// The unit of every numeric field of the job's answer, by path (`points[].load`).
    pub fn units(&self) -> &'static crate::render::UnitTable {
        self.kind.units()
    }

    /// Hash of the canonical input and the model version: equal keys, equal results.
    pub fn cache_key(&self) -> String {
        self.meta().input_hash
    }

    /// The work the job takes.
    pub fn work(&self) -> Work {
        self.kind.work()
    }

    /// What it is estimated to cost ([`Kind::cost`]).
    pub fn cost(&self) -> Cost {
        self.cost
    }

    /// Bytes its answer takes at most, in JSON and CSV ([`Kind::result_bytes`]).
    pub fn result_bytes(&self) -> u64 {
        self.kind.result_bytes()
    }

    /// Whether the job is small enough to run on the caller's thread ([`Kind::small`]).
    pub fn is_small(&self) -> bool {
        self.kind.small()
    }

    /// Why the job is not answered synchronously, if so ([`Kind::asynchronous_only`]).
    pub fn asynchronous_only(&self) -> Option<JobError> {
        self.kind.asynchronous_only()
    }

    /// Runs the job to its answer, whose `meta` is `meta` (see [`Job::meta`]); a run
    /// stopped before its end is its error.
    pub fn run(&self, meta: Meta, control: &Control) -> Result<Answer, JobError> {
        self.kind.run(meta, control).map_err(|u| u.error)
    }

    /// Runs the job as [`Job::run`] does, keeping the partial answer of a run stopped before
    /// its end (a cancel, the deadline) for a kind that keeps partial work.
    pub fn run_keeping(&self, meta: Meta, control: &Control) -> Result<Answer, Unfinished> {
        self.kind.run(meta, control)
    }

    /// The points the job splits into, if it does ([`Kind::points`]).
    pub fn points(&self) -> Option<usize> {
        self.kind.points()
    }

    /// The answer with the rows of points `range` only ([`Kind::run_points`]).
    pub fn run_points(
        &self,
        meta: Meta,
        range: Range<usize>,
        control: &Control,
    ) -> Result<Answer, JobError> {
        self.kind
            .run_points(meta, range, control)
            .map_err(|u| u.error)
    }

    /// The same job, with `warnings` as its input's (a job read back from its wire form,
    /// [`super::wire`], keeps the warnings of the input the client sent).
    pub fn with_warnings(mut self, warnings: Vec<InputWarning>) -> Job {
        self.warnings = warnings;
        self
    }

    /// The job, if it is of kind `K`.
    pub fn downcast_ref<K: Kind>(&self) -> Option<&K> {
        self.kind.as_any().downcast_ref()
    }
}

/// A validated job and its [`Meta`] (which holds its cache key), made together by
/// [`Job::keyed`]: what the engine solves and caches, so that a job can never be paired with
/// another's key.
#[derive(Clone, Debug)]
pub struct Keyed {
    job: Job,
    meta: Meta,
    /// The cache key when it is a tenant's ([`Keyed::scoped`]).
    scoped: Option<String>,
}

/// What joins a tenant's name to an input's hash in a cache key ([`Keyed::scoped`]); never
/// in a hash (hexadecimal) or a tenant's name.
const SCOPE: char = '@';

/// The cache key of the input whose hash is `input_hash` among `tenant`'s answers (none:
/// among those of callers without an API key). `None` if `input_hash` is no input's hash (64
/// lowercase hexadecimal digits): a key is never taken from a client whole, or it could name
/// another tenant's.
pub fn scoped_key(input_hash: &str, tenant: Option<&str>) -> Option<String> {
    let hex = |b: u8| b.is_ascii_digit() || (b'a'..=b'f').contains(&b);
    if input_hash.len() != 64 || !input_hash.bytes().all(hex) {
        return None;
    }
    Some(match tenant {
        Some(tenant) => format!("{input_hash}{SCOPE}{tenant}"),
        None => input_hash.to_string(),
    })
}

/// The input's hash of a cache key, without its tenant ([`Keyed::scoped`]): what a client
/// reads as `input_hash` and `X-Input-Hash`.
pub fn input_hash_of(key: &str) -> &str {
    key.split(SCOPE).next().unwrap_or(key)
}

/// The tenant of a cache key, if it is a tenant's.
pub fn tenant_of(key: &str) -> Option<&str> {
    key.split_once(SCOPE).map(|(_, tenant)| tenant)
}

impl Keyed {
    pub fn job(&self) -> &Job {
        &self.job
    }

    pub fn meta(&self) -> &Meta {
        &self.meta
    }

    /// The cache key: the hash of the canonical input and the model version, and for a
    /// tenant's job its tenant ([`Keyed::scoped`]).
    pub fn key(&self) -> &str {
        self.scoped.as_deref().unwrap_or(&self.meta.input_hash)
    }

    /// The same job, its answers kept and found among `tenant`'s only (none: among those of
    /// callers without an API key). An answer is a pure function of its input, but whether
    /// it is cached tells that somebody asked for it: a tenant learns from the cache (its
    /// `X-Cache`, its input's link) only what it asked itself.
    pub fn scoped(self, tenant: Option<&str>) -> Keyed {
        let scoped = tenant.and_then(|t| scoped_key(&self.meta.input_hash, Some(t)));
        Keyed { scoped, ..self }
    }

    /// The job, its meta and its cache key, to run it ([`Job::run`]).
    pub fn into_parts(self) -> (Job, Meta, String) {
        let key = self.key().to_string();
        (self.job, self.meta, key)
    }
}

impl Job {
    /// The job with its [`Meta`] (computing it costs a few µs: once per request).
    pub fn keyed(self) -> Keyed {
        let meta = self.meta();
        Keyed {
            job: self,
            meta,
            scoped: None,
        }
    }
}

/// Jobs of one kind whose canonical texts are equal are the same job: equal canonical
/// inputs have equal answers ([`Kind::canonical`]).
impl PartialEq for Job {
    fn eq(&self, other: &Job) -> bool {
        self.kind() == other.kind()
            && self.kind.canonical_text() == other.kind.canonical_text()
            && self.warnings == other.warnings
    }
}

#[cfg(test)]
mod tests {
    use serde_json::json;

    use super::*;

    /// A kind that writes its canonical text straight from its input writes its tree's
    /// text: the cache key of every input stays what it was.
    #[test]
    fn a_kinds_canonical_text_is_its_trees() {
        let layer = json!({"elastic_modulus": "3 GPa", "thickness": "100 nm",
                           "retardation_time": "0.5 s", "relaxation_time": "100 ms"});
        let inputs = [
            ("rolling", json!({})),
            (
                "rolling",
                json!({"load": "1 nN", "options": {"pressure_grid": 8}}),
            ),
            (
                "rolling",
                json!({"layer": {"model": "continuum", "elastic_modulus": "3 GPa",
                                 "prony": [{"modulus": "12 GPa", "time": "100 ms"}],
                                 "temperature": "310 K",
                                 "wlf": {"reference_temperature": "300 K",
                                         "c1": 17.4, "c2": 51.6}}}),
            ),
            (
                "three_body",
                json!({"distribution": {"mean_diameter": "50 nm", "std_diameter": "5 nm",
                                        "areal_density": "1e12 m^-2"},
                       "nominal_area": "1 mm^2",
                       "upper_surface": {"elastic_modulus": "210 GPa", "poisson_ratio": 0.3,
                                         "contact": "elastic"},
                       "layer": layer, "velocity": "4 nm/s",
                       "operating": {"total_load": "1 mN"}}),
            ),
        ];
        for (kind, input) in inputs {
            let job = Job::from_input(kind, input.clone(), &Limits::default())
                .unwrap_or_else(|e| panic!("{input}: {e:?}"));
            let tree = serde_json::to_string(&job.canonical()).unwrap();
            assert_eq!(job.kind.canonical_text().get(), tree, "{input}");
        }
    }
}
