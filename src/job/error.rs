//! What is wrong with a job, in terms a client can act on. The model's errors are sorted
//! here, so that the layers above see only the job's.

use std::borrow::Cow;
use std::fmt;

use serde::{Deserialize, Serialize};
use serde_json::Value;
use utoipa::ToSchema;

use crate::model::ModelError;

/// One invalid field: where, what was sent, and what is allowed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, ToSchema, thiserror::Error)]
#[error("{message}")]
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

/// Characters of a value sent that an error echoes at most (RELIABILITY.md): the answer to
/// a huge bad input stays small.
const ECHOED: usize = 100;

/// `text` as an error echoes it: its first [`ECHOED`] characters, then "…" if it was longer.
pub fn echoed(text: &str) -> Cow<'_, str> {
    match text.char_indices().nth(ECHOED) {
        Some((end, _)) => Cow::Owned(format!("{}…", &text[..end])),
        None => Cow::Borrowed(text),
    }
}

/// `text` with every quoted part longer than [`ECHOED`] characters cut to that many: the
/// parts of a message that echo a value sent, which every message here quotes ("…" as JSON
/// and Rust write strings, with their backslash escapes, or `…` as serde names a field).
fn cut_quoted(text: &str) -> Cow<'_, str> {
    if text.len() <= ECHOED {
        return Cow::Borrowed(text);
    }
    let mut cut = String::with_capacity(text.len().min(4 * ECHOED));
    // The quote open, the characters inside it so far, whether the last one was a `\`.
    let (mut open, mut inside, mut escaped) = (None, 0, false);
    for c in text.chars() {
        match open {
            Some(quote) if c == quote && !escaped => open = None,
            Some(quote) => {
                escaped = quote == '"' && c == '\\' && !escaped;
                inside += 1;
                if inside > ECHOED {
                    if inside == ECHOED + 1 {
                        cut.push('…');
                    }
                    continue;
                }
            }
            None if c == '"' || c == '`' => (open, inside, escaped) = (Some(c), 0, false),
            None => {}
        }
        cut.push(c);
    }
    Cow::Owned(cut)
}

impl FieldError {
    /// The error with every value sent it echoes cut to [`ECHOED`] characters: the value
    /// itself, and its quoted echoes in the path (a key sent), the allowed values and the
    /// message.
    fn cut(self) -> FieldError {
        let value = match self.value {
            Value::String(s) if s.chars().nth(ECHOED).is_some() => Value::from(echoed(&s)),
            value => value,
        };
        FieldError {
            field: cut_path(&self.field),
            value,
            allowed: cut_quoted(&self.allowed).into_owned(),
            message: cut_quoted(&self.message).into_owned(),
        }
    }
}

/// A field's path with each of its names cut to [`ECHOED`] characters (a key sent in a map
/// is a name of the path).
fn cut_path(path: &str) -> String {
    if path.len() <= ECHOED {
        return path.to_string();
    }
    path.split('.').map(echoed).collect::<Vec<_>>().join(".")
}

/// Why a job was not answered. Serializable, so that a job failed in one process reads
/// the same from another (`engine::fleet`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, thiserror::Error)]
pub enum JobError {
    /// The body is not JSON.
    #[error("malformed JSON: {0}")]
    Syntax(String),
    /// JSON of the wrong shape: an unknown field or kind, a wrong type.
    #[error("{}", Located(.field, .message))]
    Schema { field: String, message: String },
    /// Values out of their ranges (all of them).
    #[error("{}", Sentence(.0))]
    Invalid(Vec<FieldError>),
    /// Valid values the model cannot solve (a root finder that does not converge, a scale
    /// double precision cannot hold, a load the system cannot carry): the same input always
    /// fails, so only a changed input can help.
    #[error("{0}")]
    Unsolvable(String),
    /// Valid values for which an assumption of the model fails (docs/model.md §7): the answer
    /// would be a number the model cannot vouch for.
    #[error("{0}")]
    OutOfDomain(String),
    /// The job was cancelled before it finished.
    #[error("the job was cancelled")]
    Cancelled,
    /// The job ran past its deadline.
    #[error("the job ran past its deadline")]
    DeadlineExceeded,
    /// The service gave the job up (every worker that took a part of it stopped): its fate,
    /// in words for the client.
    #[error("{0}")]
    Abandoned(String),
    /// A fault of the service, not of the job: logged, not shown to clients.
    #[error("internal error: {0}")]
    Internal(String),
}

/// A schema error's message, after its field when it has one.
struct Located<'a>(&'a String, &'a String);

impl fmt::Display for Located<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Located(field, message) if field.is_empty() => f.write_str(message),
            Located(field, message) => write!(f, "{field}: {message}"),
        }
    }
}

/// Invalid fields as a sentence, not a listing: `errors` of the problem has every field.
struct Sentence<'a>(&'a [FieldError]);

impl fmt::Display for Sentence<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        const SHOWN: usize = 10;
        let messages: Vec<&str> = self
            .0
            .iter()
            .take(SHOWN)
            .map(|e| e.message.as_str())
            .collect();
        f.write_str(&messages.join("; "))?;
        match self.0.len().saturating_sub(SHOWN) {
            0 => Ok(()),
            more => write!(f, "; and {more} more (see `errors`)"),
        }
    }
}

impl JobError {
    /// The error as it is shown, every value sent it echoes cut to [`ECHOED`] characters
    /// (RELIABILITY.md): one place for every problem and every message of the command
    /// line, whichever part of the service wrote the error.
    pub fn cut(self) -> JobError {
        match self {
            JobError::Schema { field, message } => JobError::Schema {
                field: cut_path(&field),
                message: cut_quoted(&message).into_owned(),
            },
            JobError::Invalid(errors) => {
                JobError::Invalid(errors.into_iter().map(FieldError::cut).collect())
            }
            other => other,
        }
    }
}

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

#[cfg(test)]
mod tests {
    use super::*;

    /// Quoted parts past 100 characters are cut, escapes and all, the rest of the message
    /// kept whole; a short text is left as it is.
    #[test]
    fn only_long_quoted_parts_are_cut() {
        let long = "y".repeat(150);
        let head = format!("{}…", "y".repeat(100));
        let text =
            format!("a: \"{long}\" and `{long}`; \"short \\\" quote\" then a long tail {long}");
        assert_eq!(
            cut_quoted(&text),
            format!("a: \"{head}\" and `{head}`; \"short \\\" quote\" then a long tail {long}")
        );
        // An escaped quote does not close the part; an escaped backslash does not escape.
        let escaped = format!("\"{}\\\"{long}\" end \"\\\\\" {long}", "z".repeat(10));
        let cut = cut_quoted(&escaped);
        assert!(cut.ends_with(&format!("…\" end \"\\\\\" {long}")), "{cut}");
        assert_eq!(cut_quoted("\"short\""), "\"short\"");
        assert_eq!(echoed("ünï"), "ünï");
        assert_eq!(echoed(&"é".repeat(101)), format!("{}…", "é".repeat(100)));
    }
}
