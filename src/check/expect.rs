//! What a check expects of an answer, and how an answer is judged against it.

use serde_json::Value;

use super::report::Outcome;
use super::{ExpectInput, GoldenInput};
use crate::render::format_number;

/// The relative tolerance of `equals` and of golden answers when none is given.
const DEFAULT_RTOL: f64 = 1e-9;
/// Mismatches of a golden answer listed in a report, at most.
const GOLDEN_MISMATCHES: usize = 10;

/// Whether `x` is `value` within `rtol`·|value| + `atol` (never for a NaN).
fn within(x: f64, value: f64, rtol: f64, atol: f64) -> bool {
    (x - value).abs() <= atol + rtol * value.abs()
}

/// A step of a field path.
#[derive(Clone, Debug, PartialEq)]
enum Step {
    Key(String),
    Index(usize),
    /// `[]`: every element.
    Each,
}

/// What a number must satisfy.
#[derive(Clone, Debug, PartialEq)]
enum Bound {
    Range { min: Option<f64>, max: Option<f64> },
    Equals { value: f64, rtol: f64, atol: f64 },
}

/// An expectation on the numbers at one path of an answer.
#[derive(Clone, Debug, PartialEq)]
pub struct Expectation {
    path: String,
    steps: Vec<Step>,
    bound: Bound,
}

/// Reads `a.b[2].c` or `points[].contact_area` into steps.
fn parse_path(path: &str) -> Result<Vec<Step>, String> {
    let bad = || {
        format!("\"{path}\" is not a field path (write e.g. static.friction_coefficient or points[].load)")
    };
    let mut steps = Vec::new();
    for part in path.split('.') {
        let (key, mut rest) = part.split_at(part.find('[').unwrap_or(part.len()));
        if key.is_empty() {
            return Err(bad());
        }
        steps.push(Step::Key(key.to_string()));
        while !rest.is_empty() {
            let inner = rest.strip_prefix('[').ok_or_else(bad)?;
            let (index, after) = inner.split_once(']').ok_or_else(bad)?;
            steps.push(if index.is_empty() {
                Step::Each
            } else {
                Step::Index(index.parse().map_err(|_| bad())?)
            });
            rest = after;
        }
    }
    Ok(steps)
}

/// The values at `steps` below `value`, each with its concrete path.
fn resolve<'a>(value: &'a Value, steps: &[Step], at: String, out: &mut Vec<(String, &'a Value)>) {
    let Some((step, rest)) = steps.split_first() else {
        out.push((at, value));
        return;
    };
    let join = |name: &str| {
        if at.is_empty() {
            name.to_string()
        } else {
            format!("{at}.{name}")
        }
    };
    match (step, value) {
        (Step::Key(k), Value::Object(map)) => {
            if let Some(v) = map.get(k) {
                resolve(v, rest, join(k), out);
            }
        }
        (Step::Index(i), Value::Array(items)) => {
            if let Some(v) = items.get(*i) {
                resolve(v, rest, format!("{at}[{i}]"), out);
            }
        }
        (Step::Each, Value::Array(items)) => {
            for (i, v) in items.iter().enumerate() {
                resolve(v, rest, format!("{at}[{i}]"), out);
            }
        }
        _ => {}
    }
}

fn finite(name: &str, x: Option<f64>) -> Result<Option<f64>, String> {
    match x {
        Some(x) if !x.is_finite() => Err(format!("{name} must be a finite number")),
        _ => Ok(x),
    }
}

fn tolerance(name: &str, x: Option<f64>, default: f64) -> Result<f64, String> {
    match finite(name, x)? {
        Some(t) if t < 0.0 => Err(format!("{name} must be ≥ 0")),
        t => Ok(t.unwrap_or(default)),
    }
}

impl Expectation {
    /// The expectation `input` on the field at `path`, or why it cannot be one.
    pub fn new(path: String, input: ExpectInput) -> Result<Expectation, String> {
        let steps = parse_path(&path)?;
        let (min, max) = (finite("min", input.min)?, finite("max", input.max)?);
        let equals = finite("equals", input.equals)?;
        let bound = match (equals, min, max) {
            (Some(value), None, None) => Bound::Equals {
                value,
                rtol: tolerance("rtol", input.rtol, DEFAULT_RTOL)?,
                atol: tolerance("atol", input.atol, 0.0)?,
            },
            (None, None, None) => {
                return Err(format!(
                    "{path}: one of min, max, or equals (with rtol, atol)"
                ))
            }
            (Some(_), ..) => return Err(format!("{path}: equals, or min and max, not both")),
            (None, ..) if input.rtol.is_some() || input.atol.is_some() => {
                return Err(format!("{path}: rtol and atol go with equals"))
            }
            (None, Some(lo), Some(hi)) if lo > hi => {
                return Err(format!("{path}: min {lo} is above max {hi}"))
            }
            (None, min, max) => Bound::Range { min, max },
        };
        Ok(Expectation { path, steps, bound })
    }

    /// What the bound says, for reports.
    fn expected(&self) -> String {
        match &self.bound {
            Bound::Range { min, max } => match (min, max) {
                (Some(lo), Some(hi)) => {
                    format!("between {} and {}", format_number(*lo), format_number(*hi))
                }
                (Some(lo), None) => format!("at least {}", format_number(*lo)),
                (None, Some(hi)) => format!("at most {}", format_number(*hi)),
                (None, None) => "a number".to_string(),
            },
            Bound::Equals { value, rtol, atol } => format!(
                "{} within rtol {} and atol {}",
                format_number(*value),
                format_number(*rtol),
                format_number(*atol)
            ),
        }
    }

    fn holds(&self, x: f64) -> bool {
        match self.bound {
            Bound::Range { min, max } => {
                min.map_or(true, |lo| lo <= x) && max.map_or(true, |hi| x <= hi)
            }
            Bound::Equals { value, rtol, atol } => within(x, value, rtol, atol),
        }
    }

    /// One outcome per number at the path (`[]` may give several); a path with no number
    /// at it fails.
    pub fn judge(&self, answer: &Value) -> Vec<Outcome> {
        let expected = self.expected();
        let mut found = Vec::new();
        resolve(answer, &self.steps, String::new(), &mut found);
        if found.is_empty() {
            return vec![Outcome::failed(
                &self.path,
                &expected,
                None,
                "the answer has no such field",
            )];
        }
        found
            .into_iter()
            .map(|(path, value)| match value.as_f64() {
                None => Outcome::failed(&path, &expected, None, "not a number"),
                Some(x) if self.holds(x) => Outcome::passed(&path, &expected, x),
                Some(x) => Outcome::failed(
                    &path,
                    &expected,
                    Some(x),
                    &format!("{path} = {}: expected {expected}", format_number(x)),
                ),
            })
            .collect()
    }
}

/// A stored answer to match field by field.
#[derive(Clone, Debug, PartialEq)]
pub struct Golden {
    /// Where it is kept, when in a file.
    pub file: Option<String>,
    /// The answer (absent until the command line has read the file).
    pub answer: Option<Value>,
    rtol: f64,
    atol: f64,
}

impl Golden {
    pub fn new(input: GoldenInput) -> Result<Golden, String> {
        if input.file.is_none() && input.answer.is_none() {
            return Err("a golden answer needs `file` or `answer`".to_string());
        }
        Ok(Golden {
            file: input.file,
            answer: input.answer,
            rtol: tolerance("rtol", input.rtol, DEFAULT_RTOL)?,
            atol: tolerance("atol", input.atol, 0.0)?,
        })
    }

    /// Whether every field of `answer` outside `meta` matches the golden one.
    pub fn judge(&self, answer: &Value) -> Outcome {
        let expected = format!(
            "the golden answer{} within rtol {} and atol {}",
            self.file
                .as_ref()
                .map_or(String::new(), |f| format!(" in {f}")),
            format_number(self.rtol),
            format_number(self.atol)
        );
        let Some(golden) = &self.answer else {
            return Outcome::failed("(golden)", &expected, None, "no golden answer was read");
        };
        let mut mismatches = Vec::new();
        self.compare(golden, answer, String::new(), &mut mismatches);
        if mismatches.is_empty() {
            Outcome::matched("(golden)", &expected)
        } else {
            let more = mismatches.len().saturating_sub(GOLDEN_MISMATCHES);
            mismatches.truncate(GOLDEN_MISMATCHES);
            let mut message = mismatches.join("; ");
            if more > 0 {
                message.push_str(&format!("; and {more} more"));
            }
            Outcome::failed("(golden)", &expected, None, &message)
        }
    }

    /// Lists in `out` where `answer` differs from `golden` below the path `at` (the top's
    /// `meta` is left out: it names the software and the hash, not results).
    fn compare(&self, golden: &Value, answer: &Value, at: String, out: &mut Vec<String>) {
        let child = |key: &str| {
            if at.is_empty() {
                key.to_string()
            } else {
                format!("{at}.{key}")
            }
        };
        let judged = |key: &&String| !(at.is_empty() && *key == "meta");
        let here = if at.is_empty() {
            "the answer"
        } else {
            at.as_str()
        };
        match (golden, answer) {
            (Value::Object(g), Value::Object(a)) => {
                for key in g.keys().filter(judged) {
                    match a.get(key) {
                        Some(value) => self.compare(&g[key], value, child(key), out),
                        None => out.push(format!("{} is missing", child(key))),
                    }
                }
                for key in a.keys().filter(judged).filter(|k| !g.contains_key(*k)) {
                    out.push(format!("{} is new", child(key)));
                }
            }
            (Value::Array(g), Value::Array(a)) if g.len() == a.len() => {
                for (i, (g, a)) in g.iter().zip(a).enumerate() {
                    self.compare(g, a, format!("{at}[{i}]"), out);
                }
            }
            (Value::Array(g), Value::Array(a)) => {
                out.push(format!("{here} has {} items, golden {}", a.len(), g.len()))
            }
            (Value::Number(g), Value::Number(a)) => {
                let g = g.as_f64().unwrap_or(f64::NAN);
                let a = a.as_f64().unwrap_or(f64::NAN);
                if !within(a, g, self.rtol, self.atol) {
                    let (a, g) = (format_number(a), format_number(g));
                    out.push(format!("{here} = {a}, golden {g}"));
                }
            }
            (g, a) if g == a => {}
            (g, a) => out.push(format!("{here} = {a}, golden {g}")),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn paths_reach_nested_fields_indices_and_every_element() {
        assert_eq!(
            parse_path("points[].static.contact_area").unwrap(),
            vec![
                Step::Key("points".into()),
                Step::Each,
                Step::Key("static".into()),
                Step::Key("contact_area".into())
            ]
        );
        assert_eq!(
            parse_path("a[2][0]").unwrap()[1..],
            [Step::Index(2), Step::Index(0)]
        );
        for bad in ["", "a..b", "a[x]", "a[1", "[1]"] {
            assert!(parse_path(bad).is_err(), "{bad}");
        }
        let answer = json!({"points": [{"mu": 0.05}, {"mu": 0.2}], "static": {"mu": 0.3}});
        let at_most = |path: &str, max| {
            Expectation::new(
                path.to_string(),
                ExpectInput {
                    max: Some(max),
                    ..Default::default()
                },
            )
            .unwrap()
            .judge(&answer)
        };
        let outcomes = at_most("points[].mu", 0.1);
        assert_eq!(
            outcomes.iter().map(|o| o.passed).collect::<Vec<_>>(),
            [true, false]
        );
        assert_eq!(outcomes[1].path, "points[1].mu");
        assert!(at_most("static.mu", 0.5)[0].passed);
        assert!(!at_most("static.nu", 0.5)[0].passed);
    }

    #[test]
    fn equals_takes_relative_and_absolute_tolerances() {
        let equals = |value, rtol, atol| {
            Expectation::new(
                "x".into(),
                ExpectInput {
                    equals: Some(value),
                    rtol,
                    atol,
                    ..Default::default()
                },
            )
            .unwrap()
        };
        let answer = json!({"x": 1.0 + 5e-10});
        assert!(equals(1.0, None, None).judge(&answer)[0].passed);
        assert!(!equals(1.0, Some(1e-10), None).judge(&answer)[0].passed);
        assert!(equals(1.0, Some(0.0), Some(1e-9)).judge(&answer)[0].passed);
        for bad in [
            ExpectInput::default(),
            ExpectInput {
                min: Some(2.0),
                max: Some(1.0),
                ..Default::default()
            },
            ExpectInput {
                equals: Some(1.0),
                max: Some(1.0),
                ..Default::default()
            },
            ExpectInput {
                max: Some(1.0),
                rtol: Some(0.1),
                ..Default::default()
            },
            ExpectInput {
                equals: Some(1.0),
                rtol: Some(-1.0),
                ..Default::default()
            },
        ] {
            assert!(Expectation::new("x".into(), bad).is_err());
        }
    }

    #[test]
    fn a_golden_answer_is_matched_field_by_field_outside_meta() {
        let golden = Golden::new(GoldenInput {
            answer: Some(json!({"a": 1.0, "b": [1, 2], "meta": {"x": 1}})),
            ..Default::default()
        })
        .unwrap();
        assert!(
            golden
                .judge(&json!({"a": 1.0, "b": [1, 2], "meta": {"x": 2}}))
                .passed
        );
        let off = golden.judge(&json!({"a": 1.1, "b": [1], "c": 0}));
        assert!(!off.passed);
        assert!(off.message.contains("a = 1.1, golden 1"), "{}", off.message);
        assert!(
            off.message.contains("b has 1 items, golden 2"),
            "{}",
            off.message
        );
        assert!(off.message.contains("c is new"), "{}", off.message);
    }
}
