//! The canonical form of an input: its JSON with the absent (`null`) members left out and
//! every object's keys sorted, so that it reads back as the same input and equal inputs
//! have equal texts. [`canonical`] gives it as a [`Value`] (to embed in other inputs);
//! [`canonical_text`] writes the same text straight from the input, without the tree.

use serde::ser::{Error as _, Serialize};
use serde_json::Value;

use crate::job::meta::Canonical;
use crate::render::compact::{Error, Style, Writer};

/// The canonical form of an input filled in, as a tree ([`canonical_text`] for its text).
pub fn canonical<T: Serialize>(input: &T) -> Value {
    /// In place: rebuilding the maps cost an allocation per key on every request.
    fn strip_nulls(value: &mut Value) {
        match value {
            Value::Object(map) => {
                map.retain(|_, v| !v.is_null());
                map.values_mut().for_each(strip_nulls);
            }
            Value::Array(items) => items.iter_mut().for_each(strip_nulls),
            _ => {}
        }
    }
    let mut value = serde_json::to_value(input).expect("an input serializes to JSON");
    strip_nulls(&mut value);
    value
}

/// The text of [`canonical`]`(input)`, written without building the tree: an uncached
/// request computes it for its cache key, and the tree (a `String` and a map node per key,
/// written out, then freed) made validating a rolling input and keying it 25 % slower
/// (BENCHMARKS.md, issue 25). An input holds no JSON already written (`RawValue`): the tree
/// would parse one, this writer refuses it (a panic here, a bug in the input's type).
pub fn canonical_text<T: Serialize>(input: &T) -> Canonical {
    let mut text = Vec::with_capacity(512);
    input
        .serialize(Writer::new(&mut text, &mut Sorted))
        .expect("an input serializes to JSON");
    let text = String::from_utf8(text).expect("the writer writes UTF-8");
    Canonical::from_text(text)
}

/// The canonical text's style: keys sorted, null members left out, numbers as a tree's
/// (`f64`, a 32-bit float widened to one).
struct Sorted;

impl Style for Sorted {
    const SORTED: bool = true;

    fn number(&mut self, out: &mut Vec<u8>, x: f64) {
        out.extend_from_slice(zmij::Buffer::new().format_finite(x).as_bytes());
    }

    fn float(&mut self, out: &mut Vec<u8>, x: f32) {
        self.number(out, f64::from(x));
    }

    fn null(&mut self, out: &mut Vec<u8>) -> Result<(), Error> {
        out.extend_from_slice(b"null");
        Ok(())
    }

    /// The tree would parse JSON already written, which this writer does not do.
    fn raw(&mut self, _: &[u8]) -> Result<(), Error> {
        Err(Error::custom("an input holds no JSON already written"))
    }
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;

    use proptest::prelude::*;
    use serde::{ser, Serialize};

    use super::*;
    use crate::render::compact::tests::{json, Flat, Shapes, Tagged};

    /// The text of the tree, as it was taken before [`canonical_text`] was written.
    fn of_tree<T: Serialize>(input: &T) -> String {
        serde_json::to_string(&canonical(input)).unwrap()
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2000))]

        /// Any JSON: nulls among members (left out) and in lists (kept), keys needing
        /// escapes, every kind of number.
        #[test]
        fn the_text_is_the_trees(value in json()) {
            let text = canonical_text(&value);
            prop_assert_eq!(text.get(), of_tree(&value));
        }
    }

    /// A struct's fields come in declaration order, not sorted: written as the tree writes
    /// them, with what serde's attributes and an enum's forms make of them.
    #[derive(Serialize)]
    struct Input {
        z_last: f64,
        absent: Option<String>,
        layer: Tagged,
        other: Tagged,
        shapes: Vec<Shapes>,
        by_number: BTreeMap<u32, f64>,
        by_flag: BTreeMap<bool, &'static str>,
        #[serde(flatten)]
        flat: Flat,
        nan: f64,
        bytes: &'static [u8],
        a_first: (),
    }

    #[test]
    fn a_typed_input_is_written_as_its_tree() {
        let input = Input {
            z_last: 1e-9,
            absent: None,
            layer: Tagged::Local {
                thickness: 1e-7,
                spare: None,
            },
            other: Tagged::Continuum,
            shapes: vec![
                Shapes::Unit,
                Shapes::Newtype(None),
                Shapes::Newtype(Some(3)),
                Shapes::Tuple(-4, 0.1),
                Shapes::Struct {
                    z: '"',
                    a: vec![1, 2],
                },
            ],
            by_number: BTreeMap::from([(10, 1.0), (9, 2.5)]),
            by_flag: BTreeMap::from([(true, "t"), (false, "f")]),
            flat: Flat {
                zeta: 7,
                skipped: None,
            },
            nan: f64::NAN,
            bytes: b"ab",
            a_first: (),
        };
        let text = canonical_text(&input);
        assert_eq!(text.get(), of_tree(&input));
        // Sorted keys at every level, null members gone, lists kept in order.
        assert_eq!(
            text.get(),
            r#"{"by_flag":{"false":"f","true":"t"},"by_number":{"10":1.0,"9":2.5},"bytes":[97,98],"layer":{"model":"local","thickness":1e-7},"other":{"model":"continuum"},"shapes":["Unit",{},{"Newtype":3},{"Tuple":[-4,0.10000000149011612]},{"Struct":{"a":[1,2],"z":"\""}}],"z_last":1e-9,"zeta":7}"#
        );
    }

    #[derive(Serialize)]
    struct Repeated {
        a: Option<u8>,
        #[serde(flatten)]
        inner: RepeatedInner,
    }

    #[derive(Serialize)]
    struct RepeatedInner {
        a: Option<u8>,
    }

    /// Keys of every kind a map may have in a tree, written as the tree writes them.
    struct Keys;

    impl Serialize for Keys {
        fn serialize<S: ser::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
            use ser::SerializeMap;
            let mut map = s.serialize_map(None)?;
            map.serialize_entry(&0.1f32, "f32")?;
            map.serialize_entry(&2.5e-9, "f64")?;
            map.serialize_entry(&u128::MAX, "u128")?;
            map.serialize_entry(&-3i128, "i128")?;
            map.serialize_entry(&'k', "char")?;
            map.end()
        }
    }

    /// A flattened field repeating a key replaces the earlier member before the nulls are
    /// left out, as a tree's map does; maps keyed by floats and wide integers.
    #[test]
    fn repeated_keys_and_every_kind_of_key_are_written_as_the_tree_has_them() {
        for (a, inner) in [
            (Some(1), None),
            (None, Some(2)),
            (Some(1), Some(2)),
            (None, None),
        ] {
            let input = Repeated {
                a,
                inner: RepeatedInner { a: inner },
            };
            assert_eq!(
                canonical_text(&input).get(),
                of_tree(&input),
                "{a:?} {inner:?}"
            );
        }
        assert_eq!(canonical_text(&Keys).get(), of_tree(&Keys));
    }
}
