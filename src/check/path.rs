//! Field paths of an answer, as checks name them (`static.friction_coefficient`,
//! `points[2].load`, `points[].contact_area`): reading one, visiting what it reaches
//! ([`FieldPath::visit`]), and saying what is there instead when it reaches nothing
//! ([`FieldPath::miss`]).

use std::collections::BTreeSet;
use std::fmt::{self, Write};

use serde_json::Value;

/// Existing paths a miss names, at most: enough for the likely typos, short enough for a
/// line of a CI log.
const NEAREST: usize = 3;

/// A step of a field path.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum Step {
    Key(String),
    Index(usize),
    /// `[]`: every element.
    Each,
}

/// Text that is no field path, as written.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("\"{0}\" is not a field path (write e.g. static.friction_coefficient or points[].load)")]
pub struct NotAPath(String);

/// A field path, as written and as steps.
#[derive(Clone, Debug, PartialEq)]
pub struct FieldPath {
    text: String,
    steps: Vec<Step>,
}

impl FieldPath {
    /// Reads `a.b[2].c` or `points[].contact_area`.
    pub fn parse(text: String) -> Result<FieldPath, NotAPath> {
        let bad = || NotAPath(text.clone());
        let mut steps = Vec::new();
        for part in text.split('.') {
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
        Ok(FieldPath { text, steps })
    }

    /// The path as written.
    /// The path as the answer's unit table (`meta.units`) names it: every index `[n]` as
    /// `[]`.
    pub fn unit_key(&self) -> String {
        let mut key = String::new();
        let mut index = false;
        for c in self.as_str().chars() {
            match c {
                '[' => index = true,
                ']' => {
                    index = false;
                    key.push_str("[]");
                    continue;
                }
                _ => {}
            }
            if !index {
                key.push(c);
            }
        }
        key
    }

    pub fn as_str(&self) -> &str {
        &self.text
    }

    /// The steps, for what reads only the parts of an answer that paths reach.
    pub(super) fn steps(&self) -> &[Step] {
        &self.steps
    }

    /// Whether the path may reach several values: it has a `[]`.
    pub fn reaches_many(&self) -> bool {
        self.steps.contains(&Step::Each)
    }

    /// Calls `visit` with each value the path reaches in `answer` and its concrete path (`[]`
    /// may reach several, a miss none), one at a time: a path over every point of a sweep
    /// is judged without a list of its thousands of values.
    pub fn visit<'a>(&self, answer: &'a Value, mut visit: impl FnMut(&str, &'a Value)) {
        visit_at(answer, &self.steps, &mut String::new(), &mut visit);
    }

    /// Why the path reaches nothing in `answer`, naming the path and the existing paths
    /// nearest to it: a typo in a CI check is then fixed from the log alone.
    pub fn miss(&self, answer: &Value) -> String {
        let nearest = nearest(&self.text, answer);
        let mut message = format!("{}: the answer has no field at this path", self.text);
        if !nearest.is_empty() {
            message.push_str("; nearest: ");
            message.push_str(&nearest.join(", "));
        }
        message
    }
}

impl fmt::Display for FieldPath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.text)
    }
}

/// Why a row of a sweep has no numbers: the model's reason for a refused point, or that the
/// job stopped before it; `None` for any other value.
pub fn unanswered(row: &Value) -> Option<String> {
    match row.get("status")?.as_str()? {
        "refused" => Some(format!(
            "the model refused this point: {}",
            row.get("reason")
                .and_then(Value::as_str)
                .unwrap_or("no reason given")
        )),
        "missing" => Some("this point was not solved: the job stopped before it".to_string()),
        _ => None,
    }
}

/// `name` below the path `at`.
fn child(at: &str, name: &str) -> String {
    if at.is_empty() {
        name.to_string()
    } else {
        format!("{at}.{name}")
    }
}

/// Calls `visit` with the values at `steps` below `value`, each with its concrete path: `at`
/// followed by the steps taken (one buffer, grown and cut back as the walk goes).
fn visit_at<'a>(
    value: &'a Value,
    steps: &[Step],
    at: &mut String,
    visit: &mut impl FnMut(&str, &'a Value),
) {
    let Some((step, rest)) = steps.split_first() else {
        visit(at, value);
        return;
    };
    let len = at.len();
    let mut below = |at: &mut String, child: &'a Value, rest: &[Step]| {
        visit_at(child, rest, at, visit);
        at.truncate(len);
    };
    match (step, value) {
        (Step::Key(k), Value::Object(map)) => {
            if !at.is_empty() {
                at.push('.');
            }
            at.push_str(k);
            match map.get(k) {
                Some(v) => below(at, v, rest),
                // A row of a sweep without numbers (refused, or not solved) is reached as
                // itself, so that an expectation on it fails saying why rather than passing
                // it over.
                None if unanswered(value).is_some() => below(at, value, &[]),
                None => at.truncate(len),
            }
        }
        (Step::Index(i), Value::Array(items)) => {
            if let Some(v) = items.get(*i) {
                let _ = write!(at, "[{i}]");
                below(at, v, rest);
            }
        }
        (Step::Each, Value::Array(items)) => {
            for (i, v) in items.iter().enumerate() {
                let _ = write!(at, "[{i}]");
                below(at, v, rest);
            }
        }
        _ => {}
    }
}

/// Puts the path of every number below `value` into `out`, with `[]` for the elements of a
/// list: the paths a check can expect something of (only numbers are judged).
fn number_paths(value: &Value, at: String, out: &mut BTreeSet<String>) {
    match value {
        Value::Number(_) => {
            out.insert(at);
        }
        Value::Object(map) => {
            for (key, v) in map {
                number_paths(v, child(&at, key), out);
            }
        }
        Value::Array(items) => {
            for v in items {
                number_paths(v, format!("{at}[]"), out);
            }
        }
        _ => {}
    }
}

/// The number paths of `answer` nearest to `written`, nearest first. A path is as near as
/// the nearest of its dotted tails (so `friction_coeficient` finds
/// `static.friction_coefficient` as well as `friction_coefficient`), ties broken by the
/// distance of the whole path; only the paths at the least distance are named.
fn nearest(written: &str, answer: &Value) -> Vec<String> {
    let mut paths = BTreeSet::new();
    number_paths(answer, String::new(), &mut paths);
    let mut ranked: Vec<(usize, usize, String)> = paths
        .into_iter()
        .map(|path| {
            let whole = levenshtein(written, &path);
            let tails = path.match_indices('.').map(|(i, _)| &path[i + 1..]);
            let near = tails
                .map(|t| levenshtein(written, t))
                .fold(whole, usize::min);
            (near, whole, path)
        })
        .collect();
    ranked.sort();
    let best = ranked.first().map(|r| r.0);
    ranked
        .into_iter()
        .take_while(|r| Some(r.0) == best)
        .take(NEAREST)
        .map(|r| r.2)
        .collect()
}

/// The Levenshtein distance of `a` and `b`, in characters: the fewest insertions,
/// deletions and substitutions that turn one into the other.
fn levenshtein(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    // `row[j]`: the distance of the part of `a` read so far and the first j characters of b.
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut diagonal = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let substitution = diagonal + usize::from(ca != *cb);
            diagonal = row[j + 1];
            row[j + 1] = substitution.min(row[j] + 1).min(diagonal + 1);
        }
    }
    row[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn path(text: &str) -> FieldPath {
        FieldPath::parse(text.to_string()).unwrap()
    }

    #[test]
    fn paths_reach_nested_fields_indices_and_every_element() {
        assert_eq!(
            path("points[].static.contact_area").steps,
            vec![
                Step::Key("points".into()),
                Step::Each,
                Step::Key("static".into()),
                Step::Key("contact_area".into())
            ]
        );
        assert_eq!(path("a[2][0]").steps[1..], [Step::Index(2), Step::Index(0)]);
        for bad in ["", "a..b", "a[x]", "a[1", "[1]"] {
            assert!(FieldPath::parse(bad.to_string()).is_err(), "{bad}");
        }
        let answer = json!({"points": [{"mu": 0.05}, {"mu": 0.2}], "static": {"mu": 0.3}});
        let reached = |text: &str| {
            let mut found = Vec::new();
            path(text).visit(&answer, |at, _| found.push(at.to_string()));
            found
        };
        assert_eq!(reached("points[].mu"), ["points[0].mu", "points[1].mu"]);
        assert_eq!(reached("points[1].mu"), ["points[1].mu"]);
        assert_eq!(reached("static.mu"), ["static.mu"]);
        for miss in ["static.nu", "points[2].mu", "static[]", "points.mu"] {
            assert!(reached(miss).is_empty(), "{miss}");
        }
    }

    #[test]
    fn a_miss_names_the_path_and_the_nearest_existing_ones() {
        let rolling = json!({"friction_coefficient": 0.09, "contact_area": 8e-17,
            "static": {"friction_coefficient": 0.1, "contact_area": 9e-17},
            "boundary": [[1.0, 2.0], [3.0, 4.0]], "meta": {"model_version": "1"}});
        assert_eq!(
            path("friction_coeficient").miss(&rolling),
            "friction_coeficient: the answer has no field at this path; \
             nearest: friction_coefficient, static.friction_coefficient"
        );
        assert_eq!(
            path("statik.contact_area").miss(&rolling),
            "statik.contact_area: the answer has no field at this path; \
             nearest: static.contact_area"
        );
        assert_eq!(
            path("boundary[][2]").miss(&rolling),
            "boundary[][2]: the answer has no field at this path; nearest: boundary[][]"
        );
        let sweep = json!({"points": [{"load": 1e-9, "static": {"friction_coefficient": 0.1}},
                                      {"load": 2e-9, "static": {"friction_coefficient": 0.2}}]});
        assert_eq!(
            path("points[].lod").miss(&sweep),
            "points[].lod: the answer has no field at this path; nearest: points[].load"
        );
        assert_eq!(
            path("x").miss(&json!({"meta": {"kind": "rolling"}})),
            "x: the answer has no field at this path"
        );
    }

    #[test]
    fn levenshtein_counts_insertions_deletions_and_substitutions() {
        for (a, b, d) in [
            ("", "", 0),
            ("", "abc", 3),
            ("abc", "", 3),
            ("kitten", "sitting", 3),
            ("friction_coeficient", "friction_coefficient", 1),
            ("flaw", "lawn", 2),
            ("µm", "nm", 1),
        ] {
            assert_eq!(levenshtein(a, b), d, "{a} {b}");
            assert_eq!(levenshtein(b, a), d, "{b} {a}");
        }
    }
}
