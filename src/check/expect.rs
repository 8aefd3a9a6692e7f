//! What a check expects of an answer, and how an answer is judged against it.

use std::collections::BTreeMap;

use serde_json::Value;

use super::path::{unanswered, FieldPath, NotAPath};
use super::report::Outcome;
use super::{Amount, ExpectInput, GoldenInput};
use crate::job::input::units::{parse_quantity, Dimension};
use crate::render::format_number;

/// The relative tolerance of `equals` and of golden answers when none is given.
const DEFAULT_RTOL: f64 = 1e-9;
/// Failures listed in a report for one expectation or one golden answer, at most; the rest
/// are counted. A check over every point of a 10,000-point sweep then reports a dozen lines,
/// not one per point (before, a suite of 332 such checks answered 3.3 million outcomes and
/// took the service to 1.4 GB).
const LISTED: usize = 10;

/// Whether `x` is `value` within `rtol`·|value| + `atol` (never for a NaN).
fn within(x: f64, value: f64, rtol: f64, atol: f64) -> bool {
    (x - value).abs() <= atol + rtol * value.abs()
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
    path: FieldPath,
    bound: Bound,
}

/// Why an expectation or a golden answer cannot be one: the message a 422 names it with.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum BadExpectation {
    #[error(transparent)]
    Path(#[from] NotAPath),
    #[error("{0} must be a finite number")]
    NotFinite(&'static str),
    #[error("{0} must be ≥ 0")]
    Negative(&'static str),
    #[error("{0}: one of min, max, or equals (with rtol, atol)")]
    NoBound(FieldPath),
    #[error("{0}: equals, or min and max, not both")]
    EqualsAndRange(FieldPath),
    #[error("{0}: rtol and atol go with equals")]
    ToleranceWithoutEquals(FieldPath),
    #[error("{path}: min {} is above max {}", format_number(*.min), format_number(*.max))]
    Inverted { path: FieldPath, min: f64, max: f64 },
    /// A bound given as a quantity that is not one of the field's dimension.
    #[error("{path}: {name} \"{text}\" {why}")]
    Quantity {
        path: FieldPath,
        name: &'static str,
        text: String,
        why: String,
    },
    #[error("a golden answer needs `file` or `answer`")]
    NoGolden,
}

fn finite(name: &'static str, x: Option<f64>) -> Result<Option<f64>, BadExpectation> {
    match x {
        Some(x) if !x.is_finite() => Err(BadExpectation::NotFinite(name)),
        _ => Ok(x),
    }
}

fn tolerance(name: &'static str, x: Option<f64>, default: f64) -> Result<f64, BadExpectation> {
    match finite(name, x)? {
        Some(t) if t < 0.0 => Err(BadExpectation::Negative(name)),
        t => Ok(t.unwrap_or(default)),
    }
}

/// `amount` in SI: a number as it is, a quantity read in the unit `units` gives the field
/// at `path` (`None`: the job is invalid, and its error is reported).
fn si(
    path: &FieldPath,
    name: &'static str,
    amount: Option<Amount>,
    units: Option<&BTreeMap<String, &'static str>>,
) -> Result<Option<f64>, BadExpectation> {
    let text = match amount {
        None => return Ok(None),
        Some(Amount::Number(x)) => return finite(name, Some(x)),
        Some(Amount::Quantity(text)) => text,
    };
    let refused = |why: String| BadExpectation::Quantity {
        path: path.clone(),
        name,
        text: text.clone(),
        why,
    };
    let Some(units) = units else {
        return Err(refused("cannot be read: the job is not valid".to_string()));
    };
    let unit = units.get(&path.unit_key()).copied();
    let Some(dimension) = unit.and_then(Dimension::of_unit) else {
        return Err(refused(
            "cannot be read: the answer gives this field no unit (give a number)".to_string(),
        ));
    };
    parse_quantity(&text, dimension)
        .map(Some)
        .map_err(|e| refused(format!("{e}; expected {}", dimension.describe())))
}

impl Expectation {
    /// The expectation `input` on the field at `path`, or why it cannot be one; `units` is
    /// the answer's unit table, which a bound given as a quantity is read with.
    pub fn new(
        path: String,
        input: ExpectInput,
        units: Option<&BTreeMap<String, &'static str>>,
    ) -> Result<Expectation, BadExpectation> {
        let path = FieldPath::parse(path)?;
        let min = si(&path, "min", input.min, units)?;
        let max = si(&path, "max", input.max, units)?;
        let equals = si(&path, "equals", input.equals, units)?;
        let atol = si(&path, "atol", input.atol, units)?;
        let bound = match (equals, min, max) {
            (Some(value), None, None) => Bound::Equals {
                value,
                rtol: tolerance("rtol", input.rtol, DEFAULT_RTOL)?,
                atol: tolerance("atol", atol, 0.0)?,
            },
            (None, None, None) => return Err(BadExpectation::NoBound(path)),
            (Some(_), ..) => return Err(BadExpectation::EqualsAndRange(path)),
            (None, ..) if input.rtol.is_some() || atol.is_some() => {
                return Err(BadExpectation::ToleranceWithoutEquals(path))
            }
            (None, Some(min), Some(max)) if min > max => {
                return Err(BadExpectation::Inverted { path, min, max })
            }
            (None, min, max) => Bound::Range { min, max },
        };
        Ok(Expectation { path, bound })
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
                min.is_none_or(|lo| lo <= x) && max.is_none_or(|hi| x <= hi)
            }
            Bound::Equals { value, rtol, atol } => within(x, value, rtol, atol),
        }
    }

    /// The path the expectation reads.
    pub fn path(&self) -> &FieldPath {
        &self.path
    }

    /// The outcomes of the numbers at the path in `answer`, judged one at a time: a path to
    /// one number gives its outcome; a path with `[]` gives the outcomes of the first
    /// [`LISTED`] numbers that fail, then one outcome for all of them, which passes when
    /// every number holds and otherwise counts the failures. A path reaching nothing fails,
    /// naming the nearest paths of the answer: `whole` gives the whole answer for that
    /// (`answer` may hold only the parts the check reads).
    pub fn judge(&self, answer: &Value, whole: impl FnOnce() -> Value) -> Vec<Outcome> {
        let expected = self.expected();
        let many = self.path.reaches_many();
        let (mut outcomes, mut judged, mut failed) = (Vec::new(), 0usize, 0usize);
        self.path.visit(answer, |path, value| {
            judged += 1;
            let outcome = match value.as_f64() {
                Some(x) if many && self.holds(x) => return,
                Some(x) if self.holds(x) => Outcome::passed(path, &expected, x),
                Some(x) => Outcome::failed(
                    path,
                    &expected,
                    Some(x),
                    &format!("{path} = {}: expected {expected}", format_number(x)),
                ),
                None => {
                    let why = unanswered(value).unwrap_or_else(|| "not a number".to_string());
                    Outcome::failed(path, &expected, None, &format!("{path}: {why}"))
                }
            };
            failed += usize::from(!outcome.passed);
            if outcome.passed || failed <= LISTED {
                outcomes.push(outcome);
            }
        });
        let path = self.path.as_str();
        if judged == 0 {
            let why = self.path.miss(&whole());
            return vec![Outcome::failed(path, &expected, None, &why)];
        }
        if many {
            outcomes.push(match failed {
                0 => Outcome::matched(path, &expected),
                _ => {
                    let listed = if failed > LISTED {
                        format!(" (the first {LISTED} listed)")
                    } else {
                        String::new()
                    };
                    let why = format!("{path}: {failed} of {judged} values fail{listed}");
                    Outcome::failed(path, &expected, None, &why)
                }
            });
        }
        outcomes
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
    pub fn new(input: GoldenInput) -> Result<Golden, BadExpectation> {
        if input.file.is_none() && input.answer.is_none() {
            return Err(BadExpectation::NoGolden);
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
            let more = mismatches.len().saturating_sub(LISTED);
            mismatches.truncate(LISTED);
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
    fn an_expectation_on_a_refused_or_missing_point_fails_saying_why() {
        let answer = json!({"points": [
            {"load": 1e-9, "status": "ok", "mu": 0.05},
            {"load": 1e-3, "status": "refused", "reason": "the penetration reaches the base"},
            {"load": 2e-9, "status": "missing"}]});
        let outcomes = Expectation::new(
            "points[].mu".to_string(),
            ExpectInput {
                max: Some(0.1.into()),
                ..Default::default()
            },
            None,
        )
        .unwrap()
        .judge(&answer, || answer.clone());
        let messages: Vec<&str> = outcomes.iter().map(|o| o.message.as_str()).collect();
        assert_eq!(
            messages[0],
            "points[1].mu: the model refused this point: the penetration reaches the base"
        );
        assert!(messages[1].contains("not solved"), "{}", messages[1]);
        assert_eq!(messages[2], "points[].mu: 2 of 3 values fail");
        assert!(outcomes.iter().all(|o| !o.passed));
    }

    #[test]
    fn every_number_at_a_path_is_judged_and_a_path_reaching_none_fails() {
        let answer = json!({"points": [{"mu": 0.05}, {"mu": 0.2}], "static": {"mu": 0.3}});
        let at_most = |path: &str, max: f64| {
            Expectation::new(
                path.to_string(),
                ExpectInput {
                    max: Some(max.into()),
                    ..Default::default()
                },
                None,
            )
            .unwrap()
            .judge(&answer, || answer.clone())
        };
        let outcomes = at_most("points[].mu", 0.1);
        let paths: Vec<&str> = outcomes.iter().map(|o| o.path.as_str()).collect();
        assert_eq!(paths, ["points[1].mu", "points[].mu"]);
        assert_eq!(outcomes[0].actual, Some(0.2));
        assert_eq!(outcomes[1].message, "points[].mu: 1 of 2 values fail");
        assert!(outcomes.iter().all(|o| !o.passed));
        let held = at_most("points[].mu", 0.5);
        assert_eq!(held, [Outcome::matched("points[].mu", "at most 0.5")]);
        assert!(at_most("static.mu", 0.5)[0].passed);
        let miss = &at_most("static.nu", 0.5)[0];
        assert!(!miss.passed);
        assert_eq!(miss.path, "static.nu");
        assert!(
            miss.message.ends_with("nearest: static.mu"),
            "{}",
            miss.message
        );
        let object = &at_most("static", 0.5)[0];
        assert_eq!(object.message, "static: not a number");
    }

    #[test]
    fn equals_takes_relative_and_absolute_tolerances() {
        let equals = |value: f64, rtol, atol: Option<f64>| {
            Expectation::new(
                "x".into(),
                ExpectInput {
                    equals: Some(value.into()),
                    rtol,
                    atol: atol.map(Amount::from),
                    ..Default::default()
                },
                None,
            )
            .unwrap()
        };
        let answer = json!({"x": 1.0 + 5e-10});
        let passed = |e: Expectation| e.judge(&answer, || answer.clone())[0].passed;
        assert!(passed(equals(1.0, None, None)));
        assert!(!passed(equals(1.0, Some(1e-10), None)));
        assert!(passed(equals(1.0, Some(0.0), Some(1e-9))));
        for bad in [
            ExpectInput::default(),
            ExpectInput {
                min: Some(2.0.into()),
                max: Some(1.0.into()),
                ..Default::default()
            },
            ExpectInput {
                equals: Some(1.0.into()),
                max: Some(1.0.into()),
                ..Default::default()
            },
            ExpectInput {
                max: Some(1.0.into()),
                rtol: Some(0.1),
                ..Default::default()
            },
            ExpectInput {
                equals: Some(1.0.into()),
                rtol: Some(-1.0),
                ..Default::default()
            },
        ] {
            assert!(Expectation::new("x".into(), bad, None).is_err());
        }
    }

    /// Every point of a 10,000-point sweep is judged, and the report holds a dozen outcomes:
    /// the failures listed up to [`LISTED`], and one for all the points.
    #[test]
    fn a_path_over_every_point_reports_its_failures_and_one_outcome_for_all() {
        let rows = |bad: usize| {
            let mu = |i| if i < bad { 0.5 } else { 0.05 };
            let points: Vec<Value> = (0..10_000).map(|i| json!({"mu": mu(i)})).collect();
            json!({ "points": points })
        };
        let every = Expectation::new(
            "points[].mu".to_string(),
            ExpectInput {
                max: Some(0.1.into()),
                ..Default::default()
            },
            None,
        )
        .unwrap();
        let held = rows(0);
        let outcomes = every.judge(&held, || held.clone());
        assert_eq!(outcomes, [Outcome::matched("points[].mu", "at most 0.1")]);

        let some_fail = rows(25);
        let outcomes = every.judge(&some_fail, || some_fail.clone());
        assert_eq!(outcomes.len(), LISTED + 1);
        assert_eq!(outcomes[9].path, "points[9].mu");
        assert_eq!(outcomes[9].actual, Some(0.5));
        assert_eq!(
            outcomes[LISTED].message,
            "points[].mu: 25 of 10000 values fail (the first 10 listed)"
        );
        assert!(outcomes.iter().all(|o| !o.passed));
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

    #[test]
    fn bounds_take_quantities_in_the_fields_dimension() {
        let units = BTreeMap::from([("points[].contact_area", "m²"), ("mu", "")]);
        let units: BTreeMap<String, &'static str> =
            units.into_iter().map(|(k, v)| (k.to_string(), v)).collect();
        let quantity = |text: &str| Some(Amount::Quantity(text.to_string()));
        let area = Expectation::new(
            "points[3].contact_area".to_string(),
            ExpectInput {
                equals: quantity("8.21 nm^2"),
                atol: quantity("0.01 nm²"),
                ..Default::default()
            },
            Some(&units),
        )
        .unwrap();
        let answer = json!({"points": [{}, {}, {}, {"contact_area": 8.215e-18}]});
        assert!(area.judge(&answer, || answer.clone())[0].passed);
        assert_eq!(
            area.bound,
            Bound::Equals {
                value: 8.21e-18,
                rtol: DEFAULT_RTOL,
                atol: 1e-20
            }
        );
        let refused = |path: &str, text: &str| {
            Expectation::new(
                path.to_string(),
                ExpectInput {
                    min: quantity(text),
                    ..Default::default()
                },
                Some(&units),
            )
            .unwrap_err()
            .to_string()
        };
        assert_eq!(
            refused("points[].contact_area", "3 nN"),
            "points[].contact_area: min \"3 nN\" is a force; expected an area (a number in \
             m², or a string such as \"1 mm^2\")"
        );
        assert!(refused("nothing", "1 nm").contains("gives this field no unit"));
        assert!(Expectation::new(
            "mu".to_string(),
            ExpectInput {
                max: quantity("0.1"),
                ..Default::default()
            },
            Some(&units)
        )
        .is_ok());
    }

    #[test]
    fn an_inverted_range_is_said_in_numbers_people_read() {
        let inverted = Expectation::new(
            "x".to_string(),
            ExpectInput {
                min: Some(1e-20.into()),
                max: Some(1e-30.into()),
                ..Default::default()
            },
            None,
        )
        .unwrap_err();
        assert_eq!(inverted.to_string(), "x: min 1e-20 is above max 1e-30");
    }
}
