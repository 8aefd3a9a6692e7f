//! The canonical form of an input: its JSON with the absent (`null`) members left out and
//! every object's keys sorted, so that it reads back as the same input and equal inputs
//! have equal texts. [`canonical`] gives it as a [`Value`] (to embed in other inputs);
//! [`canonical_text`] writes the same text straight from the input, without the tree.

use std::borrow::Cow;
use std::io::Write as _;

use serde::ser::{self, Error as _, Impossible, Serialize};
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

/// The text of [`canonical`]`(input)`, written without building the tree: an uncached
/// request computes it for its cache key, and the tree (a `String` and a map node per key,
/// written out, then freed) made validating a rolling input and keying it 25 % slower
/// (BENCHMARKS.md, issue 25). An input holds no JSON already written (`RawValue`): the tree
/// would parse one, this writer would not.
pub fn canonical_text<T: Serialize>(input: &T) -> Canonical {
    let mut text = Vec::with_capacity(512);
    input
        .serialize(Writer { out: &mut text })
        .expect("an input serializes to JSON");
    let text = String::from_utf8(text).expect("the writer writes UTF-8");
    Canonical::from_text(text)
}

type Error = serde_json::Error;

/// Writes a value's canonical JSON at the end of `out`.
struct Writer<'a> {
    out: &'a mut Vec<u8>,
}

impl<'a> Writer<'a> {
    fn raw(self, text: &[u8]) -> Result<(), Error> {
        self.out.extend_from_slice(text);
        Ok(())
    }

    fn integer(self, n: impl std::fmt::Display) -> Result<(), Error> {
        write!(self.out, "{n}").map_err(Error::io)
    }

    fn null(self) -> Result<(), Error> {
        self.raw(b"null")
    }

    fn object(self) -> Object<'a> {
        self.out.push(b'{');
        Object {
            start: self.out.len(),
            out: self.out,
            members: Vec::new(),
            key: None,
        }
    }

    fn list(self) -> List<'a> {
        self.out.push(b'[');
        List {
            out: self.out,
            first: true,
        }
    }

    /// Opens `{"variant":` before a variant's value, which [`Variant`] closes (the object
    /// has that one member, never null).
    fn variant(self, variant: &'static str) -> Writer<'a> {
        self.out.push(b'{');
        write_str(self.out, variant);
        self.out.push(b':');
        self
    }
}

/// A string as serde_json writes it: `"`, `\` and the control characters escaped (the short
/// forms `\b \t \n \f \r`, else `\u00XX`).
fn write_str(out: &mut Vec<u8>, text: &str) {
    const HEX: &[u8; 16] = b"0123456789abcdef";
    out.push(b'"');
    let bytes = text.as_bytes();
    // Keys and words hardly ever need an escape: one pass finds that out.
    if !bytes.iter().any(|&b| b < 0x20 || b == b'"' || b == b'\\') {
        out.extend_from_slice(bytes);
        out.push(b'"');
        return;
    }
    let mut start = 0;
    for (i, &byte) in bytes.iter().enumerate() {
        let escaped: &[u8] = match byte {
            b'"' => b"\\\"",
            b'\\' => b"\\\\",
            0x08 => b"\\b",
            b'\t' => b"\\t",
            b'\n' => b"\\n",
            0x0c => b"\\f",
            b'\r' => b"\\r",
            0x00..=0x1f => &[
                b'\\',
                b'u',
                b'0',
                b'0',
                HEX[usize::from(byte >> 4)],
                HEX[usize::from(byte & 15)],
            ],
            _ => continue,
        };
        out.extend_from_slice(&bytes[start..i]);
        out.extend_from_slice(escaped);
        start = i + 1;
    }
    out.extend_from_slice(&bytes[start..]);
    out.push(b'"');
}

/// An object being written, after its `{`: its members' values are written one after the
/// other from `start`, each recorded with its key, and put in key order when it closes.
struct Object<'a> {
    out: &'a mut Vec<u8>,
    start: usize,
    members: Vec<(Cow<'static, str>, usize, usize)>,
    /// The key of the member whose value comes next (a map's `serialize_key`).
    key: Option<Cow<'static, str>>,
}

impl<'a> Object<'a> {
    fn member<T: Serialize + ?Sized>(
        &mut self,
        key: Cow<'static, str>,
        value: &T,
    ) -> Result<(), Error> {
        let from = self.out.len();
        value.serialize(Writer { out: self.out })?;
        // A null value is kept as an empty range: a later member of the same key (a
        // flattened field) replaces an earlier one before the nulls are left out, as in
        // the tree.
        if &self.out[from..] == b"null" {
            self.out.truncate(from);
        }
        self.members.push((key, from, self.out.len()));
        Ok(())
    }

    /// Closes the object, its members in key order (the last of equal keys kept, as a map
    /// keeps it, then the null ones left out) in place of its values as written.
    fn close(self) -> Writer<'a> {
        let Object {
            out,
            start,
            mut members,
            ..
        } = self;
        members.sort_by(|a, b| a.0.cmp(&b.0));
        members.dedup_by(|later, earlier| {
            let same = later.0 == earlier.0;
            if same {
                std::mem::swap(later, earlier);
            }
            same
        });
        let values = out.split_off(start);
        let present = members.iter().filter(|(_, from, to)| from < to);
        for (i, (key, from, to)) in present.enumerate() {
            if i > 0 {
                out.push(b',');
            }
            write_str(out, key);
            out.push(b':');
            out.extend_from_slice(&values[from - start..to - start]);
        }
        out.push(b'}');
        Writer { out }
    }
}

/// A list being written, after its `[`.
struct List<'a> {
    out: &'a mut Vec<u8>,
    first: bool,
}

impl<'a> List<'a> {
    fn element<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Error> {
        if !std::mem::replace(&mut self.first, false) {
            self.out.push(b',');
        }
        value.serialize(Writer { out: self.out })
    }

    fn close(self) -> Writer<'a> {
        self.out.push(b']');
        Writer { out: self.out }
    }
}

/// A variant's list or object inside `{"variant": …}`.
struct Variant<C>(C);

impl<'a> ser::Serializer for Writer<'a> {
    type Ok = ();
    type Error = Error;
    type SerializeSeq = List<'a>;
    type SerializeTuple = List<'a>;
    type SerializeTupleStruct = List<'a>;
    type SerializeTupleVariant = Variant<List<'a>>;
    type SerializeMap = Object<'a>;
    type SerializeStruct = Object<'a>;
    type SerializeStructVariant = Variant<Object<'a>>;

    fn serialize_bool(self, v: bool) -> Result<(), Error> {
        self.raw(if v { b"true" } else { b"false" })
    }

    fn serialize_i8(self, v: i8) -> Result<(), Error> {
        self.integer(v)
    }

    fn serialize_i16(self, v: i16) -> Result<(), Error> {
        self.integer(v)
    }

    fn serialize_i32(self, v: i32) -> Result<(), Error> {
        self.integer(v)
    }

    fn serialize_i64(self, v: i64) -> Result<(), Error> {
        self.integer(v)
    }

    fn serialize_i128(self, v: i128) -> Result<(), Error> {
        self.integer(v)
    }

    fn serialize_u8(self, v: u8) -> Result<(), Error> {
        self.integer(v)
    }

    fn serialize_u16(self, v: u16) -> Result<(), Error> {
        self.integer(v)
    }

    fn serialize_u32(self, v: u32) -> Result<(), Error> {
        self.integer(v)
    }

    fn serialize_u64(self, v: u64) -> Result<(), Error> {
        self.integer(v)
    }

    fn serialize_u128(self, v: u128) -> Result<(), Error> {
        self.integer(v)
    }

    /// A tree's number is an `f64`: a 32-bit float is written as the `f64` it widens to.
    fn serialize_f32(self, v: f32) -> Result<(), Error> {
        self.serialize_f64(f64::from(v))
    }

    /// A non-finite number is `null` in the tree (serde_json's), so it is here.
    fn serialize_f64(self, v: f64) -> Result<(), Error> {
        if !v.is_finite() {
            return self.null();
        }
        self.raw(zmij::Buffer::new().format_finite(v).as_bytes())
    }

    fn serialize_char(self, v: char) -> Result<(), Error> {
        self.serialize_str(v.encode_utf8(&mut [0; 4]))
    }

    fn serialize_str(self, v: &str) -> Result<(), Error> {
        write_str(self.out, v);
        Ok(())
    }

    fn serialize_bytes(self, v: &[u8]) -> Result<(), Error> {
        let mut list = self.list();
        v.iter().try_for_each(|byte| list.element(byte))?;
        list.close();
        Ok(())
    }

    fn serialize_none(self) -> Result<(), Error> {
        self.null()
    }

    fn serialize_some<T: Serialize + ?Sized>(self, value: &T) -> Result<(), Error> {
        value.serialize(self)
    }

    fn serialize_unit(self) -> Result<(), Error> {
        self.null()
    }

    fn serialize_unit_struct(self, _: &'static str) -> Result<(), Error> {
        self.null()
    }

    fn serialize_unit_variant(
        self,
        _: &'static str,
        _: u32,
        variant: &'static str,
    ) -> Result<(), Error> {
        self.serialize_str(variant)
    }

    fn serialize_newtype_struct<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        value: &T,
    ) -> Result<(), Error> {
        value.serialize(self)
    }

    fn serialize_newtype_variant<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        _: u32,
        variant: &'static str,
        value: &T,
    ) -> Result<(), Error> {
        let mut object = self.object();
        object.member(Cow::Borrowed(variant), value)?;
        object.close();
        Ok(())
    }

    fn serialize_seq(self, _: Option<usize>) -> Result<List<'a>, Error> {
        Ok(self.list())
    }

    fn serialize_tuple(self, _: usize) -> Result<List<'a>, Error> {
        Ok(self.list())
    }

    fn serialize_tuple_struct(self, _: &'static str, _: usize) -> Result<List<'a>, Error> {
        Ok(self.list())
    }

    fn serialize_tuple_variant(
        self,
        _: &'static str,
        _: u32,
        variant: &'static str,
        _: usize,
    ) -> Result<Variant<List<'a>>, Error> {
        Ok(Variant(self.variant(variant).list()))
    }

    fn serialize_map(self, _: Option<usize>) -> Result<Object<'a>, Error> {
        Ok(self.object())
    }

    fn serialize_struct(self, _: &'static str, _: usize) -> Result<Object<'a>, Error> {
        Ok(self.object())
    }

    fn serialize_struct_variant(
        self,
        _: &'static str,
        _: u32,
        variant: &'static str,
        _: usize,
    ) -> Result<Variant<Object<'a>>, Error> {
        Ok(Variant(self.variant(variant).object()))
    }
}

impl ser::SerializeSeq for List<'_> {
    type Ok = ();
    type Error = Error;

    fn serialize_element<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Error> {
        self.element(value)
    }

    fn end(self) -> Result<(), Error> {
        self.close();
        Ok(())
    }
}

impl ser::SerializeTuple for List<'_> {
    type Ok = ();
    type Error = Error;

    fn serialize_element<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Error> {
        self.element(value)
    }

    fn end(self) -> Result<(), Error> {
        self.close();
        Ok(())
    }
}

impl ser::SerializeTupleStruct for List<'_> {
    type Ok = ();
    type Error = Error;

    fn serialize_field<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Error> {
        self.element(value)
    }

    fn end(self) -> Result<(), Error> {
        self.close();
        Ok(())
    }
}

impl ser::SerializeTupleVariant for Variant<List<'_>> {
    type Ok = ();
    type Error = Error;

    fn serialize_field<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Error> {
        self.0.element(value)
    }

    fn end(self) -> Result<(), Error> {
        self.0.close().out.push(b'}');
        Ok(())
    }
}

impl ser::SerializeMap for Object<'_> {
    type Ok = ();
    type Error = Error;

    fn serialize_key<T: Serialize + ?Sized>(&mut self, key: &T) -> Result<(), Error> {
        self.key = Some(Cow::Owned(key.serialize(Key)?));
        Ok(())
    }

    fn serialize_value<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Error> {
        let key = self
            .key
            .take()
            .ok_or_else(|| Error::custom("a map's value came before its key"))?;
        self.member(key, value)
    }

    fn end(self) -> Result<(), Error> {
        self.close();
        Ok(())
    }
}

impl ser::SerializeStruct for Object<'_> {
    type Ok = ();
    type Error = Error;

    fn serialize_field<T: Serialize + ?Sized>(
        &mut self,
        key: &'static str,
        value: &T,
    ) -> Result<(), Error> {
        self.member(Cow::Borrowed(key), value)
    }

    fn end(self) -> Result<(), Error> {
        self.close();
        Ok(())
    }
}

impl ser::SerializeStructVariant for Variant<Object<'_>> {
    type Ok = ();
    type Error = Error;

    fn serialize_field<T: Serialize + ?Sized>(
        &mut self,
        key: &'static str,
        value: &T,
    ) -> Result<(), Error> {
        self.0.member(Cow::Borrowed(key), value)
    }

    fn end(self) -> Result<(), Error> {
        self.0.close().out.push(b'}');
        Ok(())
    }
}

/// A map's key as the tree has it: a string, a character, a finite number or a boolean as
/// its text.
struct Key;

impl Key {
    fn text(self, text: impl ToString) -> Result<String, Error> {
        Ok(text.to_string())
    }

    fn refused<T>(self) -> Result<T, Error> {
        Err(Error::custom(
            "a map key must be a string, a number or a boolean",
        ))
    }
}

impl ser::Serializer for Key {
    type Ok = String;
    type Error = Error;
    type SerializeSeq = Impossible<String, Error>;
    type SerializeTuple = Impossible<String, Error>;
    type SerializeTupleStruct = Impossible<String, Error>;
    type SerializeTupleVariant = Impossible<String, Error>;
    type SerializeMap = Impossible<String, Error>;
    type SerializeStruct = Impossible<String, Error>;
    type SerializeStructVariant = Impossible<String, Error>;

    fn serialize_bool(self, v: bool) -> Result<String, Error> {
        self.text(v)
    }

    fn serialize_i8(self, v: i8) -> Result<String, Error> {
        self.text(v)
    }

    fn serialize_i16(self, v: i16) -> Result<String, Error> {
        self.text(v)
    }

    fn serialize_i32(self, v: i32) -> Result<String, Error> {
        self.text(v)
    }

    fn serialize_i64(self, v: i64) -> Result<String, Error> {
        self.text(v)
    }

    fn serialize_u8(self, v: u8) -> Result<String, Error> {
        self.text(v)
    }

    fn serialize_u16(self, v: u16) -> Result<String, Error> {
        self.text(v)
    }

    fn serialize_u32(self, v: u32) -> Result<String, Error> {
        self.text(v)
    }

    fn serialize_u64(self, v: u64) -> Result<String, Error> {
        self.text(v)
    }

    fn serialize_i128(self, v: i128) -> Result<String, Error> {
        self.text(v)
    }

    fn serialize_u128(self, v: u128) -> Result<String, Error> {
        self.text(v)
    }

    /// A finite float, as its own shortest text (a 32-bit one is not widened).
    fn serialize_f32(self, v: f32) -> Result<String, Error> {
        match v.is_finite() {
            true => self.text(zmij::Buffer::new().format_finite(v)),
            false => self.refused(),
        }
    }

    fn serialize_f64(self, v: f64) -> Result<String, Error> {
        match v.is_finite() {
            true => self.text(zmij::Buffer::new().format_finite(v)),
            false => self.refused(),
        }
    }

    fn serialize_char(self, v: char) -> Result<String, Error> {
        self.text(v)
    }

    fn serialize_str(self, v: &str) -> Result<String, Error> {
        self.text(v)
    }

    fn serialize_bytes(self, _: &[u8]) -> Result<String, Error> {
        self.refused()
    }

    fn serialize_none(self) -> Result<String, Error> {
        self.refused()
    }

    fn serialize_some<T: Serialize + ?Sized>(self, _: &T) -> Result<String, Error> {
        self.refused()
    }

    fn serialize_unit(self) -> Result<String, Error> {
        self.refused()
    }

    fn serialize_unit_struct(self, _: &'static str) -> Result<String, Error> {
        self.refused()
    }

    fn serialize_unit_variant(
        self,
        _: &'static str,
        _: u32,
        variant: &'static str,
    ) -> Result<String, Error> {
        self.text(variant)
    }

    fn serialize_newtype_struct<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        value: &T,
    ) -> Result<String, Error> {
        value.serialize(self)
    }

    fn serialize_newtype_variant<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: &T,
    ) -> Result<String, Error> {
        self.refused()
    }

    fn serialize_seq(self, _: Option<usize>) -> Result<Self::SerializeSeq, Error> {
        self.refused()
    }

    fn serialize_tuple(self, _: usize) -> Result<Self::SerializeTuple, Error> {
        self.refused()
    }

    fn serialize_tuple_struct(
        self,
        _: &'static str,
        _: usize,
    ) -> Result<Self::SerializeTupleStruct, Error> {
        self.refused()
    }

    fn serialize_tuple_variant(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: usize,
    ) -> Result<Self::SerializeTupleVariant, Error> {
        self.refused()
    }

    fn serialize_map(self, _: Option<usize>) -> Result<Self::SerializeMap, Error> {
        self.refused()
    }

    fn serialize_struct(self, _: &'static str, _: usize) -> Result<Self::SerializeStruct, Error> {
        self.refused()
    }

    fn serialize_struct_variant(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: usize,
    ) -> Result<Self::SerializeStructVariant, Error> {
        self.refused()
    }
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;

    use proptest::prelude::*;
    use serde::Serialize;

    use super::*;

    /// The text of the tree, as it was taken before [`canonical_text`] was written.
    fn of_tree<T: Serialize>(input: &T) -> String {
        serde_json::to_string(&canonical(input)).unwrap()
    }

    fn json() -> impl Strategy<Value = Value> {
        let leaf = prop_oneof![
            Just(Value::Null),
            any::<bool>().prop_map(Value::from),
            any::<i64>().prop_map(Value::from),
            any::<u64>().prop_map(Value::from),
            any::<f64>().prop_map(Value::from),
            "(?s).{0,12}".prop_map(Value::from),
            prop::sample::select(vec!["\"", "\\", "\u{0}", "\u{1f}", "\u{7f}", "\n\t", "é €"])
                .prop_map(Value::from),
        ];
        leaf.prop_recursive(4, 48, 6, |inner| {
            prop_oneof![
                prop::collection::vec(inner.clone(), 0..6).prop_map(Value::Array),
                prop::collection::btree_map("[a-c_\"é]{0,3}", inner, 0..6)
                    .prop_map(|map| Value::Object(map.into_iter().collect())),
            ]
        })
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

    #[derive(Serialize)]
    #[serde(tag = "model", rename_all = "snake_case")]
    enum Tagged {
        Local { thickness: f64, spare: Option<f64> },
        Continuum,
    }

    #[derive(Serialize)]
    enum Shapes {
        Unit,
        Newtype(Option<u8>),
        Tuple(i32, f32),
        Struct { z: char, a: Vec<u8> },
    }

    #[derive(Serialize)]
    struct Flat {
        zeta: u8,
        #[serde(skip_serializing_if = "Option::is_none")]
        skipped: Option<u8>,
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
