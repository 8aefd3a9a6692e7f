//! The canonical form of an input: its JSON with the absent (`null`) members left out and
//! every object's keys sorted, so that it reads back as the same input and equal inputs
//! have equal texts. [`canonical`] gives it as a [`Value`] (to embed in other inputs),
//! [`canonical_text`] as text.

use serde::Serialize;
use serde_json::Value;

use crate::job::meta::Canonical;

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

/// The text of [`canonical`]`(input)`: the text a cache key hashes. It is serde_json's
/// writing of the tree, so that no change to how answers are rendered can move a key.
pub fn canonical_text<T: Serialize>(input: &T) -> Canonical {
    let text = serde_json::to_string(&canonical(input)).expect("a tree serializes to JSON");
    Canonical::from_text(text)
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;

    use serde::Serialize;

    use super::*;
    use crate::render::json::tests::{Flat, Shapes, Tagged};

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
        // Sorted keys at every level, null members gone, lists kept in order.
        assert_eq!(
            text.get(),
            r#"{"by_flag":{"false":"f","true":"t"},"by_number":{"10":1.0,"9":2.5},"bytes":[97,98],"layer":{"model":"local","thickness":1e-7},"other":{"model":"continuum"},"shapes":["Unit",{},{"Newtype":3},{"Tuple":[-4,0.10000000149011612]},{"Struct":{"a":[1,2],"z":"\""}}],"z_last":1e-9,"zeta":7}"#
        );
    }
}
