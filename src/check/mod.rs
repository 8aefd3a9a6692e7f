//! Checks for CI pipelines: a file of jobs, each with expectations on its answer (bounds,
//! values within a tolerance, or a stored golden answer), run by `thirdbody check` or
//! `POST /v1/checks`, reported for people and as JUnit XML for CI systems.
//!
//! This module reads a checks document ([`Suite`]) and judges answers ([`CheckSpec::judge`]);
//! the command line runs a file of checks in process ([`run_file`]), the service runs a
//! document through its engine. Either way each answer is judged as it comes and let go: a
//! suite holds its verdicts, never its answers, and an answer is read only as far as its
//! checks need ([`read`]).

mod expect;
mod file;
mod path;
mod read;
mod report;

use std::collections::BTreeMap;

use serde::Deserialize;
use serde_json::Value;
use utoipa::ToSchema;

pub use expect::{BadExpectation, Expectation, Golden};
pub use file::run_file;
pub use path::NotAPath;
pub use report::{CheckReport, Outcome, Report, Summary};

use crate::job::input::{deserialize, Checker};
use crate::job::{Job, JobError, Limits};

/// A checks document: `{"checks": [...]}`.
#[derive(Clone, Debug, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"checks": [{"name": "mu stays low",
    "job": {"kind": "rolling", "input": {"load": "1.2 nN"}},
    "expect": {"friction_coefficient": {"max": 0.1}}}]}))]
pub struct ChecksInput {
    pub checks: Vec<CheckInput>,
}

/// One check: a job and what its answer must satisfy.
#[derive(Clone, Debug, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct CheckInput {
    /// The check's name in reports.
    pub name: String,
    /// The job, as `thirdbody solve` takes it: `{"kind": ..., "input": {...}}`.
    #[schema(value_type = crate::job::registry::Envelope)]
    pub job: Value,
    /// Expectations on fields of the answer, by dotted path: `friction_coefficient`,
    /// `static.friction_coefficient`, `points[2].load`, or `points[].contact_area` for every
    /// point.
    #[serde(default)]
    pub expect: BTreeMap<String, ExpectInput>,
    /// A stored answer that every field of this one (outside `meta`) must match.
    pub golden: Option<GoldenInput>,
}

/// Bounds on a number, or the value it must equal within `rtol`·|value| + `atol`. Each
/// bound is a number in the field's SI unit (its `meta.units`), or a quantity in any unit of
/// the field's dimension (`"8.21 nm^2"`), as a job's inputs are.
#[derive(Clone, Debug, Default, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct ExpectInput {
    /// The smallest value allowed.
    pub min: Option<Amount>,
    /// The largest value allowed.
    pub max: Option<Amount>,
    /// The value expected.
    pub equals: Option<Amount>,
    /// Relative tolerance of `equals` (default 1e-9).
    pub rtol: Option<f64>,
    /// Absolute tolerance of `equals`, in the field's unit (default 0).
    pub atol: Option<Amount>,
}

/// A bound: a number in the field's SI unit, or a quantity with its unit.
#[derive(Clone, Debug, Deserialize, ToSchema)]
#[serde(untagged)]
pub enum Amount {
    Number(f64),
    Quantity(String),
}

impl From<f64> for Amount {
    fn from(x: f64) -> Amount {
        Amount::Number(x)
    }
}

/// A golden answer: in a file (the command line reads it, and `--update` rewrites it), or
/// given inline.
#[derive(Clone, Debug, Default, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct GoldenInput {
    /// Path of the file holding the answer, relative to the checks file.
    pub file: Option<String>,
    /// The answer itself, as JSON.
    #[schema(value_type = Option<Object>)]
    pub answer: Option<Value>,
    /// Relative tolerance of every number (default 1e-9).
    pub rtol: Option<f64>,
    /// Absolute tolerance of every number (default 0).
    pub atol: Option<f64>,
}

/// A validated checks document.
#[derive(Clone, Debug)]
pub struct Suite {
    pub checks: Vec<CheckSpec>,
}

/// A validated check.
#[derive(Clone, Debug)]
pub struct CheckSpec {
    pub name: String,
    pub job: Job,
    pub expectations: Vec<Expectation>,
    pub golden: Option<Golden>,
}

impl Suite {
    /// Reads and validates a checks document; every bad check is reported, with its path.
    pub fn from_value(value: Value, limits: &Limits) -> Result<Suite, JobError> {
        let input: ChecksInput = deserialize(value, "")?;
        let mut checker = Checker::new();
        let mut checks = Vec::new();
        if input.checks.is_empty() {
            checker.invalid("checks", Value::Array(Vec::new()), "at least one check");
        }
        for (i, check) in input.checks.into_iter().enumerate() {
            let at = format!("checks[{i}]");
            let job = match Job::from_value(check.job, limits) {
                Ok(job) => Some(job),
                Err(e) => {
                    checker.invalid(
                        &format!("{at}.job"),
                        Value::Null,
                        &format!("a valid job: {e}"),
                    );
                    None
                }
            };
            let expectations: Vec<Expectation> = check
                .expect
                .into_iter()
                .filter_map(|(path, e)| {
                    let units = job.as_ref().map(|job| job.units().get().get());
                    Expectation::new(path, e, units)
                        .map_err(|why| {
                            checker.invalid(&format!("{at}.expect"), Value::Null, &why.to_string())
                        })
                        .ok()
                })
                .collect();
            let golden = check.golden.and_then(|g| {
                Golden::new(g)
                    .map_err(|why| {
                        checker.invalid(&format!("{at}.golden"), Value::Null, &why.to_string())
                    })
                    .ok()
            });
            if expectations.is_empty() && golden.is_none() {
                checker.invalid(
                    &at,
                    Value::Null,
                    "a check with `expect` or `golden`: something to check",
                );
            }
            if let Some(job) = job {
                checks.push(CheckSpec {
                    name: check.name,
                    job,
                    expectations,
                    golden,
                });
            }
        }
        checker.finish(Suite { checks }).map(|v| v.job)
    }
}

impl CheckSpec {
    /// Judges the job's answer (its JSON text, as clients see it), or the error it failed
    /// with. Only what the expectations read is parsed, unless a golden answer is matched
    /// (the whole answer) or a path reaches nothing (the whole answer again, to name the
    /// nearest paths).
    pub fn judge(&self, answer: Result<&[u8], &JobError>) -> CheckReport {
        let mut report = CheckReport::new(&self.name, self.job.kind().name());
        let json = match answer {
            Ok(json) => json,
            Err(e) => {
                report.fail_with(e.to_string());
                report.settle();
                return report;
            }
        };
        let whole = || serde_json::from_slice::<Value>(json);
        let read = match &self.golden {
            Some(_) => whole(),
            None => read::parts(json, self.expectations.iter().map(Expectation::path)),
        };
        match read {
            Err(e) => report.fail_with(format!("the answer could not be read: {e}")),
            Ok(answer) => {
                report.input_hash = answer["meta"]["input_hash"].as_str().map(str::to_string);
                for expectation in &self.expectations {
                    // The text was read a moment ago: it parses again.
                    let outcomes = expectation.judge(&answer, || whole().unwrap_or_default());
                    report.outcomes.extend(outcomes);
                }
                if let Some(golden) = &self.golden {
                    report.outcomes.push(golden.judge(&answer));
                }
            }
        }
        report.settle();
        report
    }
}
