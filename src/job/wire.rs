//! A validated job as it travels between processes (through Redis, `engine::fleet`): its
//! kind, its canonical input and the warnings of the input its client sent. Read back, it
//! is validated again (a canonical input is a valid input of the same job) and keeps those
//! warnings, so its answer (and cache key) is the one the accepting process would give.

use serde::{Deserialize, Serialize};
use serde_json::Value;

use super::{InputWarning, Job, JobError, Limits};

#[derive(Serialize, Deserialize)]
struct Wire {
    kind: String,
    input: Value,
    warnings: Vec<InputWarning>,
}

impl Job {
    /// The job as text another process reads with [`Job::from_wire`].
    pub fn to_wire(&self) -> String {
        let wire = Wire {
            kind: self.kind().to_string(),
            input: self.canonical(),
            warnings: self.warnings().to_vec(),
        };
        serde_json::to_string(&wire).expect("a job's canonical form is JSON")
    }

    /// The job written by [`Job::to_wire`]. Its size was checked when it was accepted, so
    /// no limit applies again.
    pub fn from_wire(text: &str) -> Result<Job, JobError> {
        let wire: Wire = serde_json::from_str(text)
            .map_err(|e| JobError::Internal(format!("a job read back is unreadable: {e}")))?;
        let unlimited = Limits {
            max_sweep_points: usize::MAX,
        };
        Ok(Job::from_input(&wire.kind, wire.input, &unlimited)?.with_warnings(wire.warnings))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_job_read_back_has_the_same_key_and_warnings() {
        for envelope in [
            r#"{"kind": "rolling", "input": {"radius": 25}}"#,
            r#"{"kind": "three_body", "input": {"operating": {"total_load": "1 mN"}}}"#,
            r#"{"kind": "sweep", "input": {"vary": {"load": ["1 nN", "2 nN"]}}}"#,
            r#"{"kind": "figure", "input": {"number": 4}}"#,
        ] {
            let job = Job::from_json(envelope.as_bytes(), &Limits::default()).unwrap();
            let back = Job::from_wire(&job.to_wire()).unwrap();
            assert_eq!(back, job, "{envelope}");
            assert_eq!(back.cache_key(), job.cache_key(), "{envelope}");
        }
        let warned = Job::from_json(
            br#"{"kind": "rolling", "input": {"radius": 25}}"#,
            &Limits::default(),
        )
        .unwrap();
        assert!(!Job::from_wire(&warned.to_wire())
            .unwrap()
            .warnings()
            .is_empty());
    }

    #[test]
    fn unreadable_text_is_an_internal_error() {
        assert!(matches!(
            Job::from_wire("not json"),
            Err(JobError::Internal(_))
        ));
    }
}
