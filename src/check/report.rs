//! What a run of checks found: for people (text), for CI systems (JUnit XML), and as JSON.

use std::fmt::Write;

use serde::Serialize;
use utoipa::ToSchema;

/// One judgement of one number (or of a golden answer).
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
pub struct Outcome {
    /// The field judged, e.g. `points[3].friction_coefficient`, or `(golden)`.
    pub path: String,
    /// What was expected.
    pub expected: String,
    /// The number found (in the field's SI unit), when there is one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub actual: Option<f64>,
    pub passed: bool,
    /// Why it failed (empty when it passed).
    pub message: String,
}

impl Outcome {
    pub fn passed(path: &str, expected: &str, actual: f64) -> Outcome {
        Outcome {
            path: path.to_string(),
            expected: expected.to_string(),
            actual: Some(actual),
            passed: true,
            message: String::new(),
        }
    }

    /// A judgement with no single number that held: a golden answer matched, or every
    /// number at a path with `[]`.
    pub fn matched(path: &str, expected: &str) -> Outcome {
        Outcome {
            path: path.to_string(),
            expected: expected.to_string(),
            actual: None,
            passed: true,
            message: String::new(),
        }
    }

    pub fn failed(path: &str, expected: &str, actual: Option<f64>, message: &str) -> Outcome {
        Outcome {
            path: path.to_string(),
            expected: expected.to_string(),
            actual,
            passed: false,
            message: message.to_string(),
        }
    }
}

/// The result of one check.
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
pub struct CheckReport {
    pub name: String,
    /// The job's kind.
    pub kind: String,
    pub passed: bool,
    /// The answer's input hash, when the job was answered.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub input_hash: Option<String>,
    pub outcomes: Vec<Outcome>,
    /// Why the job itself gave no answer.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// Time the check took, its job's answer and its judgement (s): what a CI report shows.
    pub seconds: f64,
}

impl CheckReport {
    pub fn new(name: &str, kind: &str) -> CheckReport {
        CheckReport {
            name: name.to_string(),
            kind: kind.to_string(),
            passed: false,
            input_hash: None,
            outcomes: Vec::new(),
            error: None,
            seconds: 0.0,
        }
    }

    /// The same report, the check having begun at `started`.
    pub fn timed(self, started: std::time::Instant) -> CheckReport {
        let seconds = started.elapsed().as_secs_f64();
        CheckReport { seconds, ..self }
    }

    pub fn fail_with(&mut self, error: String) {
        self.error = Some(error);
    }

    /// Passed: answered, and every outcome passed.
    pub fn settle(&mut self) {
        self.passed = self.error.is_none() && self.outcomes.iter().all(|o| o.passed);
    }

    /// The messages of what failed.
    fn failures(&self) -> Vec<String> {
        let outcomes = self.outcomes.iter().filter(|o| !o.passed);
        self.error
            .iter()
            .cloned()
            .chain(outcomes.map(|o| o.message.clone()))
            .collect()
    }
}

/// Counts of a run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, ToSchema)]
pub struct Summary {
    pub checks: usize,
    pub passed: usize,
    pub failed: usize,
}

/// The result of a run of checks.
#[derive(Clone, Debug, PartialEq, Serialize, ToSchema)]
pub struct Report {
    /// Whether every check passed.
    pub passed: bool,
    pub summary: Summary,
    pub checks: Vec<CheckReport>,
}

impl Report {
    pub fn new(checks: Vec<CheckReport>) -> Report {
        let passed = checks.iter().filter(|c| c.passed).count();
        Report {
            passed: passed == checks.len(),
            summary: Summary {
                checks: checks.len(),
                passed,
                failed: checks.len() - passed,
            },
            checks,
        }
    }

    /// Which checks failed, in a sentence for a failed report: "2 of 5 checks failed: mu
    /// stays low, area at 1 nN".
    pub fn failed_checks(&self) -> String {
        let failed: Vec<&str> = self
            .checks
            .iter()
            .filter(|c| !c.passed)
            .map(|c| c.name.as_str())
            .collect();
        let of = self.summary.checks;
        let noun = if of == 1 { "check" } else { "checks" };
        format!(
            "{} of {of} {noun} failed: {}",
            failed.len(),
            failed.join(", ")
        )
    }

    /// For people: one line per check, the failures under it, and the counts.
    pub fn to_text(&self) -> String {
        let mut text = String::new();
        for check in &self.checks {
            let verdict = if check.passed { "PASS" } else { "FAIL" };
            let _ = writeln!(text, "{verdict}  {}", check.name);
            for failure in check.failures() {
                let _ = writeln!(text, "      {failure}");
            }
        }
        let s = &self.summary;
        let _ = writeln!(
            text,
            "{} checks: {} passed, {} failed",
            s.checks, s.passed, s.failed
        );
        text
    }

    /// JUnit XML, as CI systems (GitHub Actions reporters, GitLab) display it: one test
    /// case per check, a failure element per failed check.
    pub fn to_junit(&self) -> String {
        let s = &self.summary;
        let time: f64 = self.checks.iter().map(|c| c.seconds).sum();
        let mut xml = String::from("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
        let _ = writeln!(
            xml,
            "<testsuites name=\"thirdbody check\" tests=\"{}\" failures=\"{}\" time=\"{time:.6}\">",
            s.checks, s.failed
        );
        let _ = writeln!(
            xml,
            "  <testsuite name=\"thirdbody check\" tests=\"{}\" failures=\"{}\" errors=\"0\" \
             time=\"{time:.6}\">",
            s.checks, s.failed
        );
        for check in &self.checks {
            let _ = write!(
                xml,
                "    <testcase name=\"{}\" classname=\"thirdbody.{}\" time=\"{:.6}\"",
                escape(&check.name),
                escape(&check.kind),
                check.seconds
            );
            if check.passed {
                xml.push_str("/>\n");
                continue;
            }
            let failures = check.failures();
            let _ = writeln!(
                xml,
                ">\n      <failure message=\"{}\">{}</failure>\n    </testcase>",
                escape(failures.first().map_or("", String::as_str)),
                escape(&failures.join("\n"))
            );
        }
        xml.push_str("  </testsuite>\n</testsuites>\n");
        xml
    }
}

/// Text as XML character data or attribute value.
fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c if c.is_control() && !matches!(c, '\n' | '\t') => {}
            c => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn junit_names_each_check_and_escapes_what_it_says() {
        let mut pass = CheckReport::new("mu <0.1>", "rolling");
        pass.seconds = 0.25;
        pass.settle();
        let mut fail = CheckReport::new("area", "sweep");
        fail.seconds = 1.5;
        fail.outcomes
            .push(Outcome::failed("x", "at most 1", Some(2.0), "x = 2 & more"));
        fail.settle();
        let report = Report::new(vec![pass, fail]);
        assert!(!report.passed);
        let xml = report.to_junit();
        assert!(
            xml.contains("tests=\"2\" failures=\"1\" errors=\"0\" time=\"1.750000\""),
            "{xml}"
        );
        assert!(xml.contains(
            "<testcase name=\"mu &lt;0.1&gt;\" classname=\"thirdbody.rolling\" time=\"0.250000\"/>"
        ));
        assert!(
            xml.contains("<failure message=\"x = 2 &amp; more\">"),
            "{xml}"
        );
        let text = report.to_text();
        assert!(
            text.contains("PASS  mu <0.1>\nFAIL  area\n      x = 2 & more\n"),
            "{text}"
        );
        assert!(text.ends_with("2 checks: 1 passed, 1 failed\n"));
        assert_eq!(report.failed_checks(), "1 of 2 checks failed: area");
    }
}
