//! What is wrong with a job, in terms a client can act on.

use std::fmt;

use serde::Serialize;
use serde_json::Value;
use utoipa::ToSchema;

use crate::model::ModelError;

/// One invalid field: where, what was sent, and what is allowed.
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
pub struct FieldError {
    /// Path of the field in the input, e.g. `layer.thickness` or `vary.radius[2]`.
    pub field: String,
    /// The value as sent (any JSON value; `null` when the field's shape was wrong).
    #[schema(value_type = Object)]
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

/// Why a job was not answered.
#[derive(Clone, Debug, PartialEq)]
pub enum JobError {
    /// The body is not JSON.
    Syntax(String),
    /// JSON of the wrong shape: an unknown field or kind, a wrong type.
    Schema { field: String, message: String },
    /// Values out of their ranges (all of them).
    Invalid(Vec<FieldError>),
    /// The model could not produce a number (non-convergence, unrepresentable scale).
    Solve(ModelError),
    /// The job was cancelled before it finished.
    Cancelled,
    /// The job ran past its deadline.
    DeadlineExceeded,
    /// A fault of the service, not of the job.
    Internal(String),
}

impl JobError {
    /// Classifies a serde_json error: syntax (not JSON) or schema (JSON of the wrong shape).
    pub fn from_json(e: serde_json::Error) -> JobError {
        if e.is_data() {
            JobError::Schema {
                field: String::new(),
                message: e.to_string(),
            }
        } else {
            JobError::Syntax(e.to_string())
        }
    }
}

impl fmt::Display for JobError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            JobError::Syntax(m) => write!(f, "malformed JSON: {m}"),
            JobError::Schema { field, message } if field.is_empty() => f.write_str(message),
            JobError::Schema { field, message } => write!(f, "{field}: {message}"),
            JobError::Invalid(errors) => {
                let messages: Vec<&str> = errors.iter().map(|e| e.message.as_str()).collect();
                f.write_str(&messages.join("; "))
            }
            JobError::Solve(e) => e.fmt(f),
            JobError::Cancelled => f.write_str("the job was cancelled"),
            JobError::DeadlineExceeded => f.write_str("the job ran past its deadline"),
            JobError::Internal(m) => write!(f, "internal error: {m}"),
        }
    }
}

impl std::error::Error for JobError {}

impl From<ModelError> for JobError {
    fn from(e: ModelError) -> Self {
        JobError::Solve(e)
    }
}
