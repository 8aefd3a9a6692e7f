//! Compact JSON written straight from serde's data model into a byte vector, in one of two
//! [`Style`]s: an input's canonical form (every object's keys sorted, its `null` members left
//! out: the text a cache key hashes) and an answer (members as they come, numbers through a
//! memo, JSON already written copied in, a `null` refused). Either way the text is
//! serde_json's, byte for byte (tested against it). serde_json itself spent a third of an
//! uncached rolling answer's rendering escaping its 200 keys through its formatter's calls
//! (BENCHMARKS.md, issue 25): a key here is checked in one pass and copied.

use std::borrow::Cow;
use std::io::Write as _;

use serde::ser::{self, Error as _, Impossible, Serialize};

pub(crate) type Error = serde_json::Error;

/// The name serde_json's `RawValue` serializes under, as a struct of one field of that name
/// holding its text: the only way its JSON reaches a serializer other than serde_json's.
/// (Tested: a `RawValue` written by [`Writer`] is its text.)
const RAW_VALUE: &str = "$serde_json::private::RawValue";

/// What differs between the texts written.
pub(crate) trait Style {
    /// Whether an object's members are put in key order, its `null` ones left out.
    const SORTED: bool;

    /// Writes a finite double.
    fn number(&mut self, out: &mut Vec<u8>, x: f64);

    /// Writes a finite 32-bit float.
    fn float(&mut self, out: &mut Vec<u8>, x: f32);

    /// Writes `null` (an absent value, a unit, a non-finite number), or refuses it.
    fn null(&mut self, out: &mut Vec<u8>) -> Result<(), Error>;

    /// Accepts or refuses `json`, JSON already written (a `RawValue`) just copied out.
    fn raw(&mut self, json: &[u8]) -> Result<(), Error>;

    /// Writes a struct's field name and its colon, `"key":`, in order (a style in key order
    /// writes its names when its objects close).
    fn field(&mut self, out: &mut Vec<u8>, key: &'static str) {
        write_field(out, key);
    }
}

/// `"key":`, the name of a member written in order.
pub(crate) fn write_field(out: &mut Vec<u8>, key: &str) {
    write_str(out, key);
    out.push(b':');
}

/// Writes a value at the end of `out`, in the style `S`.
pub(crate) struct Writer<'a, S> {
    out: &'a mut Vec<u8>,
    style: &'a mut S,
}

impl<'a, S: Style> Writer<'a, S> {
    pub(crate) fn new(out: &'a mut Vec<u8>, style: &'a mut S) -> Writer<'a, S> {
        Writer { out, style }
    }

    fn bytes(self, text: &[u8]) -> Result<(), Error> {
        self.out.extend_from_slice(text);
        Ok(())
    }

    fn integer(self, n: impl std::fmt::Display) -> Result<(), Error> {
        write!(self.out, "{n}").map_err(Error::io)
    }

    fn object(self) -> Object<'a, S> {
        self.out.push(b'{');
        Object::new(self, false)
    }

    fn list(self) -> List<'a, S> {
        self.out.push(b'[');
        List {
            writer: self,
            first: true,
        }
    }

    /// Opens `{"variant":` before a variant's value, which [`Variant`] closes (the object
    /// has that one member, never null).
    fn variant(self, variant: &'static str) -> Writer<'a, S> {
        self.out.push(b'{');
        write_field(self.out, variant);
        self
    }

    /// The same writer again, for a member or an element (`self` stays with its container).
    #[inline]
    fn inner(&mut self) -> Writer<'_, S> {
        Writer {
            out: self.out,
            style: self.style,
        }
    }
}

/// A string as serde_json writes it: `"`, `\` and the control characters escaped (the short
/// forms `\b \t \n \f \r`, else `\u00XX`).
fn write_str(out: &mut Vec<u8>, text: &str) {
    out.push(b'"');
    write_str_contents(out, text.as_bytes());
    out.push(b'"');
}

/// The inside of [`write_str`]: `bytes`, UTF-8, escaped, a run of plain bytes at a time.
fn write_str_contents(out: &mut Vec<u8>, bytes: &[u8]) {
    const HEX: &[u8; 16] = b"0123456789abcdef";
    let mut rest = bytes;
    loop {
        let plain = plain_prefix(rest);
        out.extend_from_slice(&rest[..plain]);
        let Some(&byte) = rest.get(plain) else {
            return;
        };
        let unicode;
        out.extend_from_slice(match byte {
            b'"' => b"\\\"",
            b'\\' => b"\\\\",
            0x08 => b"\\b",
            b'\t' => b"\\t",
            b'\n' => b"\\n",
            0x0c => b"\\f",
            b'\r' => b"\\r",
            _ => {
                let hex = |nibble: u8| HEX[usize::from(nibble)];
                unicode = [b'\\', b'u', b'0', b'0', hex(byte >> 4), hex(byte & 15)];
                &unicode
            }
        });
        rest = &rest[plain + 1..];
    }
}

/// How many bytes `bytes` starts with that a JSON string holds as they are (not `"`, `\`
/// or a control character), eight at a time: an answer's keys and words are 2 kB, and
/// looking at them a byte at a time (serde_json's way too) was a third of writing one.
fn plain_prefix(bytes: &[u8]) -> usize {
    const ONES: u64 = u64::from_ne_bytes([1; 8]);
    const HIGHS: u64 = ONES << 7;
    // The high bit of each byte of `word` below `n`, as in "Bit Twiddling Hacks" (hasless):
    // exact for the lowest such byte, which is all that is read of it.
    let below = |word: u64, n: u8| word.wrapping_sub(ONES * u64::from(n)) & !word & HIGHS;
    let marks = |word: u64| {
        below(word, 0x20)
            | below(word ^ (ONES * u64::from(b'"')), 1)
            | below(word ^ (ONES * u64::from(b'\\')), 1)
    };
    let mut chunks = bytes.chunks_exact(8);
    for (i, chunk) in chunks.by_ref().enumerate() {
        let marks = marks(u64::from_le_bytes(chunk.try_into().expect("eight bytes")));
        if marks != 0 {
            return 8 * i + marks.trailing_zeros() as usize / 8;
        }
    }
    // The last bytes, padded with spaces to a word of their own (most keys are all tail).
    let tail = chunks.remainder();
    let mut last = [b' '; 8];
    last[..tail.len()].copy_from_slice(tail);
    let marks = marks(u64::from_le_bytes(last));
    bytes.len() - tail.len() + (marks.trailing_zeros() as usize / 8).min(tail.len())
}

/// An object being written, after its `{`. In order, each member is written as it comes. In
/// key order, the members' values are written one after the other from `start`, each
/// recorded with its key, and put in key order when it closes.
pub(crate) struct Object<'a, S> {
    writer: Writer<'a, S>,
    start: usize,
    members: Vec<(Cow<'static, str>, usize, usize)>,
    /// The key of the member whose value comes next (a map's `serialize_key`).
    key: Option<Cow<'static, str>>,
    /// Whether a member has been written (in order).
    written: bool,
    /// A `RawValue`: its one field is its JSON, copied out as it is.
    raw: bool,
}

impl<'a, S: Style> Object<'a, S> {
    fn new(writer: Writer<'a, S>, raw: bool) -> Object<'a, S> {
        Object {
            start: writer.out.len(),
            writer,
            members: Vec::new(),
            key: None,
            written: false,
            raw,
        }
    }

    fn member<T: Serialize + ?Sized>(
        &mut self,
        key: Cow<'static, str>,
        value: &T,
    ) -> Result<(), Error> {
        if self.raw {
            if key != RAW_VALUE {
                return Err(Error::custom("a RawValue's one field is its text"));
            }
            let from = self.writer.out.len();
            value.serialize(Key::new(self.writer.out, false))?;
            return self.writer.style.raw(&self.writer.out[from..]);
        }
        if !S::SORTED {
            self.comma();
            write_field(self.writer.out, &key);
            return value.serialize(self.writer.inner());
        }
        let from = self.writer.out.len();
        value.serialize(self.writer.inner())?;
        // A null value is kept as an empty range: a later member of the same key (a
        // flattened field) replaces an earlier one before the nulls are left out, as in
        // the tree.
        if &self.writer.out[from..] == b"null" {
            self.writer.out.truncate(from);
        }
        self.members.push((key, from, self.writer.out.len()));
        Ok(())
    }

    /// A struct's field: in order, its name written by the style (which may keep it).
    #[inline]
    fn field<T: Serialize + ?Sized>(&mut self, key: &'static str, value: &T) -> Result<(), Error> {
        if S::SORTED || self.raw {
            return self.member(Cow::Borrowed(key), value);
        }
        self.comma();
        self.writer.style.field(self.writer.out, key);
        value.serialize(self.writer.inner())
    }

    /// A map's key: in order, written with its `:` (the value follows); in key order, kept
    /// until its value comes, to be written with it.
    fn key<T: Serialize + ?Sized>(&mut self, key: &T) -> Result<(), Error> {
        if !S::SORTED {
            self.comma();
            let out = &mut *self.writer.out;
            out.push(b'"');
            let from = out.len();
            key.serialize(Key::new(out, true))?;
            if plain_prefix(&out[from..]) < out.len() - from {
                let text = out.split_off(from);
                write_str_contents(out, &text);
            }
            out.extend_from_slice(b"\":");
            // Written: the value only has to be there.
            self.key = Some(Cow::Borrowed(""));
            return Ok(());
        }
        let mut text = Vec::new();
        key.serialize(Key::new(&mut text, false))?;
        let text = String::from_utf8(text).map_err(Error::custom)?;
        self.key = Some(Cow::Owned(text));
        Ok(())
    }

    /// A map's value, after its key.
    fn value<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Error> {
        let key = self
            .key
            .take()
            .ok_or_else(|| Error::custom("a map's value came before its key"))?;
        match S::SORTED {
            true => self.member(key, value),
            false => value.serialize(self.writer.inner()),
        }
    }

    /// The comma before a member written in order, unless it is the first.
    #[inline]
    fn comma(&mut self) {
        if std::mem::replace(&mut self.written, true) {
            self.writer.out.push(b',');
        }
    }

    /// Closes the object. In key order, its members are put in key order (the last of equal
    /// keys kept, as a map keeps it, then the null ones left out) in place of its values as
    /// written.
    fn close(self) -> Writer<'a, S> {
        let Object {
            writer,
            start,
            mut members,
            raw,
            ..
        } = self;
        if raw {
            return writer;
        }
        if !S::SORTED {
            writer.out.push(b'}');
            return writer;
        }
        members.sort_by(|a, b| a.0.cmp(&b.0));
        members.dedup_by(|later, earlier| {
            let same = later.0 == earlier.0;
            if same {
                std::mem::swap(later, earlier);
            }
            same
        });
        let values = writer.out.split_off(start);
        let present = members.iter().filter(|(_, from, to)| from < to);
        for (i, (key, from, to)) in present.enumerate() {
            if i > 0 {
                writer.out.push(b',');
            }
            write_str(writer.out, key);
            writer.out.push(b':');
            writer
                .out
                .extend_from_slice(&values[from - start..to - start]);
        }
        writer.out.push(b'}');
        writer
    }
}

/// A list being written, after its `[`.
pub(crate) struct List<'a, S> {
    writer: Writer<'a, S>,
    first: bool,
}

impl<'a, S: Style> List<'a, S> {
    fn element<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Error> {
        if !std::mem::replace(&mut self.first, false) {
            self.writer.out.push(b',');
        }
        value.serialize(self.writer.inner())
    }

    fn close(self) -> Writer<'a, S> {
        self.writer.out.push(b']');
        self.writer
    }
}

/// A variant's list or object inside `{"variant": …}`.
pub(crate) struct Variant<C>(C);

/// Serializer methods written alike in [`Writer`] and [`Key`]: those that take their arguments
/// only to refuse them (`self.refused()`), those that each hand their argument to one method
/// of the serializer (`self.$to(v)`), and a unit variant's and a newtype struct's.
macro_rules! forward {
    // A unit variant is its name, a newtype struct what it wraps.
    (unit_variant_and_newtype_struct) => {
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
    };
    (refused: $($refused:ident($($arg:ty),*) -> $ret:ty),* $(,)?) => {
        $(fn $refused(self, $(_: $arg),*) -> Result<$ret, Error> {
            self.refused()
        })*
    };
    ($to:ident: $($method:ident($ty:ty)),* $(,)?) => {
        $(fn $method(self, v: $ty) -> Result<(), Error> {
            self.$to(v)
        })*
    };
}

impl<'a, S: Style> ser::Serializer for Writer<'a, S> {
    type Ok = ();
    type Error = Error;
    type SerializeSeq = List<'a, S>;
    type SerializeTuple = List<'a, S>;
    type SerializeTupleStruct = List<'a, S>;
    type SerializeTupleVariant = Variant<List<'a, S>>;
    type SerializeMap = Object<'a, S>;
    type SerializeStruct = Object<'a, S>;
    type SerializeStructVariant = Variant<Object<'a, S>>;

    fn serialize_bool(self, v: bool) -> Result<(), Error> {
        self.bytes(if v { b"true" } else { b"false" })
    }

    forward! {
        integer: serialize_i8(i8), serialize_i16(i16), serialize_i32(i32), serialize_i64(i64),
            serialize_i128(i128), serialize_u8(u8), serialize_u16(u16), serialize_u32(u32),
            serialize_u64(u64), serialize_u128(u128),
    }

    fn serialize_f32(self, v: f32) -> Result<(), Error> {
        if !v.is_finite() {
            return self.style.null(self.out);
        }
        self.style.float(self.out, v);
        Ok(())
    }

    #[inline]
    /// A non-finite number is serde_json's `null`.
    fn serialize_f64(self, v: f64) -> Result<(), Error> {
        if !v.is_finite() {
            return self.style.null(self.out);
        }
        self.style.number(self.out, v);
        Ok(())
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
        self.style.null(self.out)
    }

    fn serialize_some<T: Serialize + ?Sized>(self, value: &T) -> Result<(), Error> {
        value.serialize(self)
    }

    fn serialize_unit(self) -> Result<(), Error> {
        self.style.null(self.out)
    }

    fn serialize_unit_struct(self, _: &'static str) -> Result<(), Error> {
        self.style.null(self.out)
    }

    forward!(unit_variant_and_newtype_struct);

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

    fn serialize_seq(self, _: Option<usize>) -> Result<List<'a, S>, Error> {
        Ok(self.list())
    }

    fn serialize_tuple(self, _: usize) -> Result<List<'a, S>, Error> {
        Ok(self.list())
    }

    fn serialize_tuple_struct(self, _: &'static str, _: usize) -> Result<List<'a, S>, Error> {
        Ok(self.list())
    }

    fn serialize_tuple_variant(
        self,
        _: &'static str,
        _: u32,
        variant: &'static str,
        _: usize,
    ) -> Result<Variant<List<'a, S>>, Error> {
        Ok(Variant(self.variant(variant).list()))
    }

    fn serialize_map(self, _: Option<usize>) -> Result<Object<'a, S>, Error> {
        Ok(self.object())
    }

    fn serialize_struct(self, name: &'static str, _: usize) -> Result<Object<'a, S>, Error> {
        Ok(match name == RAW_VALUE {
            true => Object::new(self, true),
            false => self.object(),
        })
    }

    fn serialize_struct_variant(
        self,
        _: &'static str,
        _: u32,
        variant: &'static str,
        _: usize,
    ) -> Result<Variant<Object<'a, S>>, Error> {
        Ok(Variant(self.variant(variant).object()))
    }
}

/// The three traits of a list, each adding an element with [`List::element`].
macro_rules! lists {
    ($($trait:ident::$method:ident),*) => {$(
        impl<S: Style> ser::$trait for List<'_, S> {
            type Ok = ();
            type Error = Error;

            fn $method<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Error> {
                self.element(value)
            }

            fn end(self) -> Result<(), Error> {
                self.close();
                Ok(())
            }
        }
    )*};
}

lists!(
    SerializeSeq::serialize_element,
    SerializeTuple::serialize_element,
    SerializeTupleStruct::serialize_field
);

impl<S: Style> ser::SerializeTupleVariant for Variant<List<'_, S>> {
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

impl<S: Style> ser::SerializeStruct for Object<'_, S> {
    type Ok = ();
    type Error = Error;

    #[inline]
    fn serialize_field<T: Serialize + ?Sized>(
        &mut self,
        key: &'static str,
        value: &T,
    ) -> Result<(), Error> {
        self.field(key, value)
    }

    fn end(self) -> Result<(), Error> {
        self.close();
        Ok(())
    }
}

impl<S: Style> ser::SerializeStructVariant for Variant<Object<'_, S>> {
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

impl<S: Style> ser::SerializeMap for Object<'_, S> {
    type Ok = ();
    type Error = Error;

    fn serialize_key<T: Serialize + ?Sized>(&mut self, key: &T) -> Result<(), Error> {
        self.key(key)
    }

    fn serialize_value<T: Serialize + ?Sized>(&mut self, value: &T) -> Result<(), Error> {
        self.value(value)
    }

    fn end(self) -> Result<(), Error> {
        self.close();
        Ok(())
    }
}

/// A map's key as serde_json has it, its text written unescaped at the end of the vector: a
/// string, a character, a finite number or a boolean as its text. (Also the text of a
/// `RawValue`, a string.)
struct Key<'a> {
    out: &'a mut Vec<u8>,
    /// Whether `Some(key)` is the key's (serde_json's writer), or refused (its tree).
    some: bool,
}

impl<'a> Key<'a> {
    fn new(out: &'a mut Vec<u8>, some: bool) -> Key<'a> {
        Key { out, some }
    }

    fn text(self, text: impl std::fmt::Display) -> Result<(), Error> {
        write!(self.out, "{text}").map_err(Error::io)
    }

    fn refused<T>(self) -> Result<T, Error> {
        Err(Error::custom(
            "a map key must be a string, a number or a boolean",
        ))
    }
}

impl ser::Serializer for Key<'_> {
    type Ok = ();
    type Error = Error;
    type SerializeSeq = Impossible<(), Error>;
    type SerializeTuple = Impossible<(), Error>;
    type SerializeTupleStruct = Impossible<(), Error>;
    type SerializeTupleVariant = Impossible<(), Error>;
    type SerializeMap = Impossible<(), Error>;
    type SerializeStruct = Impossible<(), Error>;
    type SerializeStructVariant = Impossible<(), Error>;

    forward! {
        text: serialize_bool(bool), serialize_i8(i8), serialize_i16(i16), serialize_i32(i32),
            serialize_i64(i64), serialize_i128(i128), serialize_u8(u8), serialize_u16(u16),
            serialize_u32(u32), serialize_u64(u64), serialize_u128(u128), serialize_char(char),
    }

    forward! {
        refused: serialize_bytes(&[u8]) -> (), serialize_none() -> (), serialize_unit() -> (),
            serialize_unit_struct(&'static str) -> (),
            serialize_seq(Option<usize>) -> Self::SerializeSeq,
            serialize_tuple(usize) -> Self::SerializeTuple,
            serialize_tuple_struct(&'static str, usize) -> Self::SerializeTupleStruct,
            serialize_tuple_variant(&'static str, u32, &'static str, usize)
                -> Self::SerializeTupleVariant,
            serialize_map(Option<usize>) -> Self::SerializeMap,
            serialize_struct(&'static str, usize) -> Self::SerializeStruct,
            serialize_struct_variant(&'static str, u32, &'static str, usize)
                -> Self::SerializeStructVariant,
    }

    fn serialize_str(self, v: &str) -> Result<(), Error> {
        self.out.extend_from_slice(v.as_bytes());
        Ok(())
    }

    /// A finite float, as its own shortest text (a 32-bit one is not widened).
    fn serialize_f32(self, v: f32) -> Result<(), Error> {
        match v.is_finite() {
            true => self.serialize_str(zmij::Buffer::new().format_finite(v)),
            false => self.refused(),
        }
    }

    fn serialize_f64(self, v: f64) -> Result<(), Error> {
        match v.is_finite() {
            true => self.serialize_str(zmij::Buffer::new().format_finite(v)),
            false => self.refused(),
        }
    }

    fn serialize_some<T: Serialize + ?Sized>(self, key: &T) -> Result<(), Error> {
        match self.some {
            true => key.serialize(self),
            false => self.refused(),
        }
    }

    forward!(unit_variant_and_newtype_struct);

    fn serialize_newtype_variant<T: Serialize + ?Sized>(
        self,
        _: &'static str,
        _: u32,
        _: &'static str,
        _: &T,
    ) -> Result<(), Error> {
        self.refused()
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use proptest::prelude::*;
    use serde::Serialize;
    use serde_json::Value;

    use super::*;

    /// An internally tagged enum, as a layer's model is.
    #[derive(Serialize)]
    #[serde(tag = "model", rename_all = "snake_case")]
    pub(crate) enum Tagged {
        Local {
            thickness: f64,
            #[serde(skip_serializing_if = "Option::is_none")]
            spare: Option<f64>,
        },
        Continuum,
    }

    /// Every form of an externally tagged enum's variants.
    #[derive(Serialize)]
    pub(crate) enum Shapes {
        Unit,
        Newtype(Option<u8>),
        Tuple(i32, f32),
        Struct { z: char, a: Vec<u8> },
    }

    /// Fields to flatten into another struct, one of them skipped when absent.
    #[derive(Serialize)]
    pub(crate) struct Flat {
        pub(crate) zeta: u8,
        #[serde(skip_serializing_if = "Option::is_none")]
        pub(crate) skipped: Option<u8>,
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(5000))]

        /// Eight bytes at a time finds the first byte a byte at a time finds, wherever it
        /// is and whatever follows it (other such bytes, bytes past 0x7f).
        #[test]
        fn the_plain_prefix_ends_at_the_first_byte_to_escape(
            bytes in prop::collection::vec(
                prop_oneof![Just(b'"'), Just(b'\\'), Just(0x1f), Just(0x20), Just(0x7f), 0x80u8.., any::<u8>(), b'a'..=b'z'],
                0..40,
            ),
        ) {
            let expected = bytes
                .iter()
                .position(|&b| b < 0x20 || b == b'"' || b == b'\\')
                .unwrap_or(bytes.len());
            prop_assert_eq!(plain_prefix(&bytes), expected);
        }
    }

    /// Any JSON: nulls among members and in lists, keys needing escapes, every kind of
    /// number.
    pub(crate) fn json() -> impl Strategy<Value = Value> {
        let leaf = prop_oneof![
            Just(Value::Null),
            any::<bool>().prop_map(Value::from),
            any::<i64>().prop_map(Value::from),
            any::<u64>().prop_map(Value::from),
            any::<f64>().prop_map(Value::from),
            "(?s).{0,40}".prop_map(Value::from),
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
}
