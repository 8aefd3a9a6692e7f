//! The parts of an answer a check reads: parsed from the answer's JSON text without building
//! the rest. A check on one number of a 10,000-point sweep (6.7 MB of JSON, a tree of 37 MB
//! once parsed whole) then holds that number; a check on a number of every point holds one
//! small object a point (7 MB). What is not read is skipped as it is parsed.

use std::collections::BTreeMap;
use std::fmt;

use serde::de::{DeserializeSeed, Deserializer, IgnoredAny, MapAccess, SeqAccess, Visitor};
use serde::Deserialize;
use serde_json::{Map, Value};

use super::path::{FieldPath, Step};

/// Fields of a row kept besides those a path names: a row of a sweep that has no numbers
/// (refused, or not solved) says why in them, and a path through it is judged by them
/// ([`super::path::unanswered`]).
const ROW_FIELDS: [&str; 2] = ["status", "reason"];

/// Which parts of an answer to keep, as a tree of the steps of the paths read.
#[derive(Debug, Default)]
struct Parts {
    /// Members to keep, each with the parts of it to keep.
    keys: BTreeMap<String, Parts>,
    /// The parts to keep of the elements of a list, of every element for a `[]` and an
    /// index alike: the elements keep their places, each holding only the parts read.
    items: Option<Box<Parts>>,
    /// Whether a path ends here: the value is kept whole.
    whole: bool,
}

impl Parts {
    fn add(&mut self, steps: &[Step]) {
        match steps.split_first() {
            None => self.whole = true,
            Some((Step::Key(key), rest)) => self.keys.entry(key.clone()).or_default().add(rest),
            Some((Step::Index(_) | Step::Each, rest)) => {
                self.items.get_or_insert_with(Box::default).add(rest)
            }
        }
    }
}

/// Parses of the answer `json` the values at `paths` (and `meta.input_hash`, which the report
/// names), each with what leads to it; every other part is skipped. The paths reach the same
/// numbers in what this gives as in the whole answer, and the same rows without numbers
/// (with what says why).
pub fn parts<'p>(
    json: &[u8],
    paths: impl IntoIterator<Item = &'p FieldPath>,
) -> serde_json::Result<Value> {
    let mut parts = Parts::default();
    parts.add(&[
        Step::Key("meta".to_string()),
        Step::Key("input_hash".to_string()),
    ]);
    for path in paths {
        parts.add(path.steps());
    }
    let mut reader = serde_json::Deserializer::from_slice(json);
    let value = (&parts).deserialize(&mut reader)?;
    reader.end()?;
    Ok(value)
}

impl<'de> DeserializeSeed<'de> for &Parts {
    type Value = Value;

    fn deserialize<D: Deserializer<'de>>(self, deserializer: D) -> Result<Value, D::Error> {
        if self.whole {
            Value::deserialize(deserializer)
        } else {
            deserializer.deserialize_any(self)
        }
    }
}

/// A value on the way to those kept: an object keeps the members named (and a row's
/// [`ROW_FIELDS`]), a list every element with its parts; a plain value is kept as it is
/// (a path through it reaches nothing, here as in the whole answer).
impl<'de> Visitor<'de> for &Parts {
    type Value = Value;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a JSON value")
    }

    fn visit_bool<E>(self, v: bool) -> Result<Value, E> {
        Ok(Value::Bool(v))
    }

    fn visit_i64<E>(self, v: i64) -> Result<Value, E> {
        Ok(v.into())
    }

    fn visit_u64<E>(self, v: u64) -> Result<Value, E> {
        Ok(v.into())
    }

    fn visit_f64<E>(self, v: f64) -> Result<Value, E> {
        Ok(v.into())
    }

    fn visit_str<E>(self, v: &str) -> Result<Value, E> {
        Ok(v.into())
    }

    fn visit_unit<E>(self) -> Result<Value, E> {
        Ok(Value::Null)
    }

    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Value, A::Error> {
        let mut kept = Map::new();
        while let Some(key) = map.next_key_seed(Member(self))? {
            match key {
                Kept::Part(name, parts) => {
                    let value = map.next_value_seed(parts)?;
                    kept.insert(name.clone(), value);
                }
                Kept::Row(name) => {
                    let value = map.next_value::<Value>()?;
                    kept.insert(name.to_string(), value);
                }
                Kept::No => {
                    map.next_value::<IgnoredAny>()?;
                }
            }
        }
        Ok(Value::Object(kept))
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Value, A::Error> {
        let mut kept = Vec::new();
        match &self.items {
            Some(parts) => {
                while let Some(item) = seq.next_element_seed(parts.as_ref())? {
                    kept.push(item);
                }
            }
            None => while seq.next_element::<IgnoredAny>()?.is_some() {},
        }
        Ok(Value::Array(kept))
    }
}

/// What becomes of a member of an object, by its name.
enum Kept<'p> {
    /// Kept with these parts of it.
    Part(&'p String, &'p Parts),
    /// Kept whole: one of a row's [`ROW_FIELDS`].
    Row(&'static str),
    No,
}

/// Reads a member's name (without keeping it unless kept) and says what becomes of it.
struct Member<'p>(&'p Parts);

impl<'de, 'p> DeserializeSeed<'de> for Member<'p> {
    type Value = Kept<'p>;

    fn deserialize<D: Deserializer<'de>>(self, deserializer: D) -> Result<Kept<'p>, D::Error> {
        deserializer.deserialize_str(self)
    }
}

impl<'de, 'p> Visitor<'de> for Member<'p> {
    type Value = Kept<'p>;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a member's name")
    }

    fn visit_str<E>(self, name: &str) -> Result<Kept<'p>, E> {
        if let Some((name, parts)) = self.0.keys.get_key_value(name) {
            return Ok(Kept::Part(name, parts));
        }
        Ok(match ROW_FIELDS.iter().copied().find(|f| *f == name) {
            Some(field) => Kept::Row(field),
            None => Kept::No,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn paths(texts: &[&str]) -> Vec<FieldPath> {
        texts
            .iter()
            .map(|t| FieldPath::parse(t.to_string()).unwrap())
            .collect()
    }

    #[test]
    fn only_the_parts_read_are_kept_and_paths_reach_the_same_values() {
        let answer = json!({
            "points": [
                {"load": 1e-9, "status": "ok", "mu": 0.05, "static": {"mu": 0.1, "area": 2.0},
                 "warn": ["local_layer"]},
                {"load": 2e-9, "status": "refused", "reason": "too deep"}],
            "static": {"mu": 0.3},
            "scalar": 1.5,
            "meta": {"input_hash": "abc", "input": {"big": [1, 2, 3]}}});
        let text = serde_json::to_vec(&answer).unwrap();
        let read = paths(&["points[].static.mu", "points[1].load", "static", "scalar.x"]);
        let kept = parts(&text, &read).unwrap();
        assert_eq!(
            kept,
            json!({
                "points": [{"load": 1e-9, "status": "ok", "static": {"mu": 0.1}},
                           {"load": 2e-9, "status": "refused", "reason": "too deep"}],
                "static": {"mu": 0.3},
                "scalar": 1.5,
                "meta": {"input_hash": "abc"}})
        );
        for path in &read {
            let reached = |answer: &Value| {
                let mut found = Vec::new();
                path.visit(answer, |at, value| {
                    found.push((at.to_string(), value.clone()))
                });
                found
            };
            assert_eq!(reached(&kept), reached(&answer), "{path}");
        }
        assert!(parts(b"{\"a\": 1} trailing", &read).is_err());
    }
}
