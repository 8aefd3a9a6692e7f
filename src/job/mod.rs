//! Jobs on the wire: the JSON types clients send and receive, their validation into model
//! inputs, their canonical form and the cache key derived from it.
//!
//! The same types serve `thirdbody solve` and the HTTP API. Every input field is optional
//! and defaults to MODEL.md §5; quantities are SI numbers or strings with units
//! ([`units`]). Validation reports every bad field at once, each with its value and the
//! allowed range.

mod error;
mod fields;
pub mod figure;
mod meta;
pub mod rolling;
pub mod sweep;
pub mod three_body;
pub mod units;

use serde::{Deserialize, Serialize};
use serde_json::Value;
use utoipa::ToSchema;

pub use error::{FieldError, JobError};
pub use fields::Quantity;
pub use figure::FigureJob;
pub use meta::{Meta, Reference, REFERENCES};
pub use rolling::RollingJob;
pub use sweep::SweepJob;
pub use three_body::ThreeBodyJob;

/// A number as text for people and CSV: plain between 1e-3 and 1e6, scientific elsewhere,
/// always the shortest text that reads back as the same double.
pub fn format_number(x: f64) -> String {
    if x == 0.0 || (1e-3..1e6).contains(&x.abs()) || !x.is_finite() {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// Limits on the size of a job, beyond the model's own ranges.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limits {
    /// Largest number of points in a sweep (the product of its lists).
    pub max_sweep_points: usize,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_sweep_points: 10_000,
        }
    }
}

/// What a job computes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize, ToSchema)]
#[serde(rename_all = "snake_case")]
pub enum JobKind {
    Rolling,
    ThreeBody,
    Sweep,
    Figure,
}

impl JobKind {
    pub fn as_str(self) -> &'static str {
        match self {
            JobKind::Rolling => "rolling",
            JobKind::ThreeBody => "three_body",
            JobKind::Sweep => "sweep",
            JobKind::Figure => "figure",
        }
    }
}

/// The envelope `{"kind": ..., "input": {...}}`; a missing input means all defaults.
#[derive(Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct Envelope {
    pub kind: JobKind,
    /// The input of the job's kind: a `RollingInput`, `ThreeBodyInput`, `SweepInput` or
    /// `FigureInput`.
    /// Absent, every field takes its default.
    #[serde(default)]
    #[schema(value_type = Option<Object>)]
    pub input: Option<Value>,
}

/// A validated job, ready for the engine.
#[derive(Clone, Debug, PartialEq)]
pub enum Job {
    Rolling(RollingJob),
    ThreeBody(ThreeBodyJob),
    Sweep(SweepJob),
    Figure(FigureJob),
}

impl Job {
    /// Parses and validates an enveloped job from JSON text.
    pub fn from_json(text: &[u8], limits: &Limits) -> Result<Job, JobError> {
        let value: Value = serde_json::from_slice(text).map_err(JobError::from_json)?;
        Job::from_value(value, limits)
    }

    /// Validates an enveloped job already parsed as JSON.
    pub fn from_value(value: Value, limits: &Limits) -> Result<Job, JobError> {
        let envelope: Envelope = fields::deserialize(value, "")?;
        let input = envelope
            .input
            .unwrap_or_else(|| Value::Object(Default::default()));
        Job::from_input(envelope.kind, input, limits)
    }

    /// Validates the input of a job of `kind` (the envelope's `input`, or the body of the
    /// HTTP endpoint of that kind): error paths are relative to the input.
    pub fn from_input(kind: JobKind, input: Value, limits: &Limits) -> Result<Job, JobError> {
        Ok(match kind {
            JobKind::Rolling => Job::Rolling(RollingJob::from_value(input)?),
            JobKind::ThreeBody => Job::ThreeBody(ThreeBodyJob::from_value(input)?),
            JobKind::Sweep => Job::Sweep(SweepJob::from_value(input, limits)?),
            JobKind::Figure => Job::Figure(FigureJob::from_value(input)?),
        })
    }

    pub fn kind(&self) -> JobKind {
        match self {
            Job::Rolling(_) => JobKind::Rolling,
            Job::ThreeBody(_) => JobKind::ThreeBody,
            Job::Sweep(_) => JobKind::Sweep,
            Job::Figure(_) => JobKind::Figure,
        }
    }

    /// The canonical input: every default filled in, every quantity an SI number.
    pub fn canonical(&self) -> Value {
        match self {
            Job::Rolling(job) => job.canonical(),
            Job::ThreeBody(job) => job.canonical(),
            Job::Sweep(job) => job.canonical(),
            Job::Figure(job) => job.canonical(),
        }
    }

    /// The `meta` block of the job's answer: model version, canonical input and its hash.
    /// Computing it costs a few µs, so a caller that needs both the key and the answer
    /// computes it once and passes it on.
    pub fn meta(&self) -> Meta {
        Meta::new(self.kind(), self.canonical())
    }

    /// Hash of the canonical input and the model version: equal keys, equal results.
    pub fn cache_key(&self) -> String {
        self.meta().input_hash
    }

    /// The number of rolling solves the job takes (its progress total).
    pub fn size(&self) -> usize {
        match self {
            Job::Rolling(_) | Job::ThreeBody(_) => 1,
            Job::Sweep(job) => job.len(),
            Job::Figure(job) => job.size(),
        }
    }
}
