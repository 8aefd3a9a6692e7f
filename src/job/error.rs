//! What is wrong with a job, in terms a client can act on. The model's errors are sorted
//! here, so that the layers above see only the job's.

use std::fmt;

use serde::{Deserialize, Serialize};
use serde_json::Value;
use utoipa::ToSchema;

use crate::model::ModelError;

/// One invalid field: where, what was sent, and what is allowed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema)]
pub struct FieldError {
    /// Path of the field in the input, e.g. `layer.thickness` or `vary.radius[2]`.
    pub field: String,
    /// The value as sent (any JSON value; `null` when the field's shape was wrong).
    #[schema(value_type = serde_json::Value)]
    pub value: Value,
    /// The allowed values.
    pub allowed: String,
    /// A sentence saying all of it.
    pub message: String,
}

impl fmt::Display for FieldError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

/// Why a job was not answered. Serializable, so that a job failed in one process reads
/// the same from another (`engine::fleet`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum JobError {
    /// The body is not JSON.
    Syntax(String),
    /// JSON of the wrong shape: an unknown field or kind, a wrong type.
    Schema { field: String, message: String },
    /// Values out of their ranges (all of them).
    Invalid(Vec<FieldError>),
    /// Valid values the model cannot solve (a root finder that does not converge, a scale
    /// double precision cannot hold, a load the system cannot carry): the same input always
    /// fails, so only a changed input can help.
    Unsolvable(String),
    /// Valid values for which an assumption of the model fails (docs/model.md §7): the answer
    /// would be a number the model cannot vouch for.
    OutOfDomain(String),
    /// The job was cancelled before it finished.
    Cancelled,
    /// The job ran past its deadline.
    DeadlineExceeded,
    /// The service gave the job up (every worker that took a part of it stopped): its fate,
    /// in words for the client.
    Abandoned(String),
    /// A fault of the service, not of the job: logged, not shown to clients.
    Internal(String),
}

impl fmt::Display for JobError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            JobError::Syntax(m) => write!(f, "malformed JSON: {m}"),
            JobError::Schema { field, message } if field.is_empty() => f.write_str(message),
            JobError::Schema { field, message } => write!(f, "{field}: {message}"),
            JobError::Invalid(errors) => {
                // A sentence, not a listing: `errors` of the problem has every field.
                const SHOWN: usize = 10;
                let messages: Vec<&str> = errors
                    .iter()
                    .take(SHOWN)
                    .map(|e| e.message.as_str())
                    .collect();
                f.write_str(&messages.join("; "))?;
                match errors.len().saturating_sub(SHOWN) {
                    0 => Ok(()),
                    more => write!(f, "; and {more} more (see `errors`)"),
                }
            }
            JobError::Unsolvable(m) | JobError::OutOfDomain(m) | JobError::Abandoned(m) => {
                f.write_str(m)
            }
            JobError::Cancelled => f.write_str("the job was cancelled"),
            JobError::DeadlineExceeded => f.write_str("the job ran past its deadline"),
            JobError::Internal(m) => write!(f, "internal error: {m}"),
        }
    }
}

impl std::error::Error for JobError {}

impl From<ModelError> for JobError {
    /// Validation checks every range before the model runs, so a range error from the model
    /// is still the input's; it names the parameter rather than a field path.
    fn from(e: ModelError) -> Self {
        let message = e.to_string();
        match e {
            ModelError::InvalidParameter(p) => JobError::Invalid(vec![FieldError {
                field: String::new(),
                value: Value::from(p.value),
                allowed: p.allowed,
                message,
            }]),
            ModelError::InvalidOption(o) => JobError::Invalid(vec![FieldError {
                field: String::new(),
                value: Value::from(o.value),
                allowed: o.allowed,
                message,
            }]),
            ModelError::NotRepresentable { .. }
            | ModelError::OutOfModel(_)
            | ModelError::NoConvergence { .. } => JobError::Unsolvable(message),
            // Only a job's control stops a solve, and it says why ([`super::Control::failed`]).
            ModelError::Stopped => JobError::Cancelled,
        }
    }
}
