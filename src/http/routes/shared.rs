//! What the jobs and the history routes share: who owns a job (the `Thirdbody-Owner`
//! header), how a job is shown to clients, and the 422 naming a bad parameter.

use axum::extract::FromRequestParts;
use axum::http::request::Parts;
use serde::Serialize;
use serde_json::Value;
use utoipa::ToSchema;
use uuid::Uuid;

use crate::engine::store::{JobRecord, JobState, JobStatus, Owner};
use crate::http::error::{ApiError, Problem};
use crate::job::registry::KindName;
use crate::job::{input_hash_of, FieldError, JobError, Work};

/// The header naming who submits and lists jobs.
pub const OWNER_HEADER: &str = "thirdbody-owner";

/// The owner named by the request's `Thirdbody-Owner` header, if any: a token of 16 to 128
/// characters that the client keeps (stored only as its hash).
pub struct OwnerHeader(pub Option<Owner>);

impl<S: Send + Sync> FromRequestParts<S> for OwnerHeader {
    type Rejection = ApiError;

    async fn from_request_parts(parts: &mut Parts, _: &S) -> Result<Self, ApiError> {
        let Some(value) = parts.headers.get(OWNER_HEADER) else {
            return Ok(OwnerHeader(None));
        };
        let token = String::from_utf8_lossy(value.as_bytes());
        let allowed = |b: u8| b.is_ascii_alphanumeric() || b"-_.~".contains(&b);
        if (16..=128).contains(&token.len()) && token.bytes().all(allowed) {
            return Ok(OwnerHeader(Some(Owner::of_token(&token))));
        }
        // Not echoed: it may be a secret mistyped.
        Err(invalid(
            &format!("header {OWNER_HEADER}"),
            Value::String(format!("({} characters)", token.chars().count())),
            "16 to 128 characters of A-Z, a-z, 0-9, '-', '_', '.' and '~' (a random token \
             the client keeps, e.g. a UUID)",
        ))
    }
}

/// A 422 `invalid-input` problem naming `field`, its `value` and what is `allowed`.
pub(super) fn invalid(field: &str, value: Value, allowed: &str) -> ApiError {
    let shown = match &value {
        Value::Null => "missing".to_string(),
        other => other.to_string(),
    };
    JobError::Invalid(vec![FieldError {
        field: field.to_string(),
        message: format!("{field} = {shown}: allowed {allowed}"),
        value,
        allowed: allowed.to_string(),
    }])
    .into()
}

/// Work done out of the job's total.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, ToSchema)]
pub struct Progress {
    /// Units of work done (count): rolling solves, or for a fit the points evaluated.
    pub done: usize,
    /// Units of work the job takes (count; 0 for a job that cannot tell in advance, a fit).
    pub total: usize,
}

/// An asynchronous job as clients see it: small, whatever the size of its answer, which is
/// at `result_url`.
#[derive(Debug, Serialize, ToSchema)]
pub struct JobView {
    /// The job's id (a UUID); its URL is `/v1/jobs/{id}`.
    pub id: Uuid,
    pub kind: KindName,
    pub status: JobStatus,
    pub progress: Progress,
    /// Where the job's answer is, once it has one: `/v1/jobs/{id}/result` (JSON, CSV or its
    /// picture). A succeeded job's answer is whole; a cancelled or failed sweep's holds the
    /// points it finished (see `partial`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub result_url: Option<String>,
    /// Whether the answer at `result_url` is partial: what a cancelled or failed job
    /// finished, its unsolved points `missing` (present only when true).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub partial: bool,
    /// Why it failed, once `failed`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub problem: Option<Problem>,
    /// The hash of the job's canonical input: its answer's stable link is
    /// `/v1/results/{input_hash}`.
    pub input_hash: String,
    /// When the job was accepted (RFC 3339, UTC).
    #[schema(format = DateTime)]
    pub submitted_at: String,
    /// When it finished, once it has (RFC 3339, UTC).
    #[serde(skip_serializing_if = "Option::is_none")]
    #[schema(format = DateTime)]
    pub finished_at: Option<String>,
    /// `true` (present only then) when the job's end could not be saved in the database of
    /// saved analyses (a full disk): it is kept in memory only, for `--job-retention`, and
    /// not across a restart.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    #[schema(value_type = Option<bool>)]
    pub unsaved: bool,
}

impl JobView {
    /// The job as recorded.
    pub fn of(record: &JobRecord) -> JobView {
        let time = |t| humantime::format_rfc3339_millis(t).to_string();
        let result = record.state.result();
        JobView {
            id: record.id,
            kind: record.kind,
            status: record.state.status(),
            progress: Progress {
                done: record.done,
                total: match record.work {
                    Work::Known(total) => total,
                    Work::Unknown => 0,
                },
            },
            result_url: result.map(|_| format!("/v1/jobs/{}/result", record.id)),
            partial: result.is_some_and(|r| !r.complete()),
            problem: match &record.state {
                JobState::Failed { error, .. } => Some(ApiError::from(error.clone()).problem()),
                _ => None,
            },
            input_hash: input_hash_of(&record.input_hash).to_string(),
            submitted_at: time(record.submitted_at),
            finished_at: record.finished_at.map(time),
            unsaved: record.unsaved,
        }
    }
}
