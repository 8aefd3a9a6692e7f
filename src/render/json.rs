//! Answers as JSON text: serde_json's compact form, or [`Rows`] for people, with numbers
//! written through a memo ([`Numbers`]) and a non-finite number refused as it is met.

use std::cell::RefCell;
use std::io::{self, Write};
use std::sync::LazyLock;

use memchr::memmem;
use serde::Serialize;
use serde_json::ser::Formatter;

use super::compact::{self, Style, Writer};
use super::RenderError;

/// `value` as JSON: compact, or with `pretty` one field or list element a line ([`Rows`]).
/// A non-finite number is an error, never the `null` serde_json would write for it: the
/// model promises never to return one, and a client must not read `null` as a value.
pub(super) fn write<T: Serialize + ?Sized>(
    value: &T,
    pretty: bool,
) -> Result<Vec<u8>, RenderError> {
    let written = SCRATCH.with(|cell| match cell.try_borrow_mut() {
        Ok(mut scratch) => scratch.write(value, pretty),
        // An answer written while another is (one holding the other).
        Err(_) => Scratch::new().write(value, pretty),
    });
    written.map_err(|e| match e.is_io() {
        // The writer is a vector, which never fails: the error is the style's (or the
        // pretty formatter's) refusal of a null.
        true => RenderError::non_finite(),
        false => RenderError(format!("cannot write the result: {e}")),
    })
}

thread_local! {
    /// What each thread keeps between the answers it writes.
    pub(super) static SCRATCH: RefCell<Scratch> = const { RefCell::new(Scratch::new()) };
}

/// The room a pretty answer (for a terminal, written once) starts with.
const PRETTY_ROOM: usize = 64 << 10;

/// What a thread keeps between the answers it writes: the size of its last answer and the
/// memos of numbers and field names. Written into a fresh vector, a 7 kB rolling answer
/// grew through seven reallocations and their copies (BENCHMARKS.md, issue 12), and written
/// into a buffer kept here, it was copied out once more; the next answer is most often of
/// the same kind and size, so it is written into a vector of that room. The memos are kept
/// too: made anew for each answer, the numbers' 10 kB cost more than they saved.
pub(super) struct Scratch {
    last: usize,
    numbers: Numbers,
    fields: Fields,
}

impl Scratch {
    const fn new() -> Scratch {
        Scratch {
            last: 0,
            numbers: Numbers::new(),
            fields: Fields::new(),
        }
    }

    /// `value` as JSON, in a vector of its size or little more (compact) or of room to
    /// spare (pretty).
    fn write<T: Serialize + ?Sized>(
        &mut self,
        value: &T,
        pretty: bool,
    ) -> serde_json::Result<Vec<u8>> {
        let Scratch {
            last,
            numbers,
            fields,
        } = self;
        if pretty {
            let mut json = Vec::with_capacity(PRETTY_ROOM);
            value.serialize(&mut serde_json::Serializer::with_formatter(
                &mut json,
                Rows::new(numbers),
            ))?;
            return Ok(json);
        }
        let mut json = Vec::with_capacity(*last + *last / 16 + 64);
        value.serialize(Writer::new(&mut json, &mut Answer { numbers, fields }))?;
        *last = json.len();
        // A small answer after a large one does not keep the large one's room.
        if json.capacity() > json.len() + json.len() / 8 + 64 {
            json.shrink_to_fit();
        }
        Ok(json)
    }
}

/// An answer's compact text: serde_json's, its numbers through [`Numbers`], `null` refused,
/// embedded JSON searched for `null` as it is copied.
struct Answer<'a> {
    numbers: &'a mut Numbers,
    fields: &'a mut Fields,
}

impl Style for Answer<'_> {
    const SORTED: bool = false;

    #[inline]
    fn number(&mut self, out: &mut Vec<u8>, x: f64) {
        self.numbers.push(out, x);
    }

    fn float(&mut self, out: &mut Vec<u8>, x: f32) {
        out.extend_from_slice(zmij::Buffer::new().format_finite(x).as_bytes());
    }

    fn null(&mut self, _: &mut Vec<u8>) -> Result<(), compact::Error> {
        refuse_null().map_err(compact::Error::io)
    }

    fn raw(&mut self, json: &[u8]) -> Result<(), compact::Error> {
        match has_null(json) {
            true => self.null(&mut Vec::new()),
            false => Ok(()),
        }
    }

    #[inline]
    fn field(&mut self, out: &mut Vec<u8>, key: &'static str) {
        self.fields.push(out, key);
    }
}

/// Places in the memo of [`Fields`] (a power of two): a rolling answer has about 60 field
/// names.
const FIELD_SLOTS: usize = 512;

/// The longest `"name":` [`Fields`] keeps.
const FIELD_TEXT: usize = 32;

/// The names of answers' fields as written, `"name":`, copied rather than checked for
/// characters to escape again: a rolling answer writes 180 of them (a third of its
/// rendering time went to them, BENCHMARKS.md, issue 25). A field's name is a `&'static
/// str`, so its address and length name its text for good. Direct-mapped by the address.
pub(super) struct Fields {
    slots: [Field; FIELD_SLOTS],
}

/// A field name's address and length (0 and 0: an empty place) and its text as written.
#[derive(Clone, Copy)]
struct Field {
    name: (usize, usize),
    len: u8,
    text: [u8; FIELD_TEXT],
}

impl Fields {
    const fn new() -> Fields {
        const EMPTY: Field = Field {
            name: (0, 0),
            len: 0,
            text: [0; FIELD_TEXT],
        };
        Fields {
            slots: [EMPTY; FIELD_SLOTS],
        }
    }

    /// Writes `"name":`.
    #[inline]
    fn push(&mut self, out: &mut Vec<u8>, name: &'static str) {
        let address = name.as_ptr() as usize;
        let hash = (address as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        let slot = &mut self.slots[(hash >> (64 - FIELD_SLOTS.trailing_zeros())) as usize];
        match slot.name == (address, name.len()) {
            true => push_prefix(out, &slot.text, slot.len),
            false => slot.keep(out, name),
        }
    }
}

impl Field {
    /// Writes `"name":` and keeps it here, unless it is longer than a place holds (such a
    /// name is written each time). Out of line: the writing of a name already kept is the
    /// loop of every answer.
    #[cold]
    #[inline(never)]
    fn keep(&mut self, out: &mut Vec<u8>, name: &'static str) {
        let from = out.len();
        compact::write_field(out, name);
        let text = &out[from..];
        if text.len() <= FIELD_TEXT {
            self.text[..text.len()].copy_from_slice(text);
            self.len = text.len() as u8;
            self.name = (name.as_ptr() as usize, name.len());
        }
    }
}

/// Pushes the first `len` bytes of `text`: the whole array copied (a copy of a known size,
/// without a call to `memcpy`), then the rest cut off again.
#[inline]
fn push_prefix<const N: usize>(out: &mut Vec<u8>, text: &[u8; N], len: u8) {
    let end = out.len() + usize::from(len);
    out.extend_from_slice(text);
    out.truncate(end);
}

/// Places in the memo of [`Numbers`] (a power of two): enough that a rolling answer's
/// boundary finds the first half's numbers still there when it writes the second half
/// (with 64 places, fewer than half of them were).
const SLOTS: usize = 256;

/// The numbers of answers, each written as serde_json writes it (the shortest text that
/// reads back as the same double, from `zmij`), but a magnitude met lately copied from a
/// table of texts rather than formatted again: a rolling answer's boundary is symmetric in
/// y, so half its 123 numbers repeat the other half's, and a sweep repeats its axes' values
/// down its points. The table is direct-mapped by a hash of the magnitude's bits.
pub(super) struct Numbers {
    slots: [Slot; SLOTS],
}

/// A magnitude and its text, after a minus sign that a negative number's copy starts from.
#[derive(Clone, Copy)]
struct Slot {
    /// The magnitude's bits, inverted: a magnitude's sign bit is clear, so its inverted bits
    /// are never those of an empty place (all zero).
    inverted: u64,
    /// The text is `text[1..=len]`.
    len: u8,
    text: [u8; 25],
}

impl Numbers {
    const fn new() -> Numbers {
        const EMPTY: Slot = Slot {
            inverted: 0,
            len: 0,
            text: [0; 25],
        };
        Numbers {
            slots: [EMPTY; SLOTS],
        }
    }

    /// Pushes the text of `x`, finite ([`Numbers::text`]).
    #[inline]
    fn push(&mut self, out: &mut Vec<u8>, x: f64) {
        let negative = x.is_sign_negative();
        let slot = self.slot(x);
        match negative {
            true => push_prefix(out, &slot.text, slot.len + 1),
            false => {
                let text: &[u8; 24] = slot.text[1..].try_into().expect("24 bytes");
                push_prefix(out, text, slot.len)
            }
        }
    }

    /// The text of `x`, finite (serde_json sends non-finite numbers to `write_null`).
    fn text(&mut self, x: f64) -> &[u8] {
        let start = usize::from(!x.is_sign_negative());
        let slot = self.slot(x);
        &slot.text[start..=usize::from(slot.len)]
    }

    /// The place of `|x|`, its text written there if it was not.
    #[inline]
    fn slot(&mut self, x: f64) -> &Slot {
        let magnitude = x.abs();
        let bits = magnitude.to_bits();
        let place = bits.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> (64 - SLOTS.trailing_zeros());
        let slot = &mut self.slots[place as usize];
        if slot.inverted != !bits {
            slot.keep(magnitude);
        }
        slot
    }
}

impl Slot {
    /// Keeps `magnitude` and its text here. Out of line, as [`Field::keep`].
    #[inline(never)]
    fn keep(&mut self, magnitude: f64) {
        let mut shortest = zmij::Buffer::new();
        let text = shortest.format_finite(magnitude).as_bytes();
        self.text[0] = b'-';
        self.text[1..=text.len()].copy_from_slice(text);
        self.len = text.len() as u8;
        self.inverted = !magnitude.to_bits();
    }
}

/// serde_json writes `null` for a NaN or an infinity; the answers hold no other `null`
/// (absent options are skipped), so meeting one stops the writing.
fn refuse_null() -> io::Result<()> {
    Err(io::Error::new(
        io::ErrorKind::InvalidData,
        "a non-finite number",
    ))
}

/// Writes JSON the answer embeds already written (its canonical input, fixed texts, a part
/// of a sweep), refusing it if it holds a `null` as [`refuse_null`] does.
fn write_raw<W: ?Sized + Write>(w: &mut W, fragment: &str) -> io::Result<()> {
    if has_null(fragment.as_bytes()) {
        return refuse_null();
    }
    w.write_all(fragment.as_bytes())
}

/// Whether JSON text holds a `null` value. Outside strings the letter `n` can only start
/// `null` (`true`, `false` and numbers have none), so one pass that skips strings finds it.
fn has_null(json: &[u8]) -> bool {
    // Nearly every text has no `null` anywhere, in a string or not: one vectorised search
    // settles it, by a searcher built once (building it cost more than searching a short
    // text).
    static NULL: LazyLock<memmem::Finder<'static>> = LazyLock::new(|| memmem::Finder::new("null"));
    if NULL.find(json).is_none() {
        return false;
    }
    let (mut in_string, mut escaped) = (false, false);
    for &b in json {
        if in_string {
            match b {
                _ if escaped => escaped = false,
                b'\\' => escaped = true,
                b'"' => in_string = false,
                _ => {}
            }
        } else if b == b'"' {
            in_string = true;
        } else if b == b'n' {
            return true;
        }
    }
    false
}

/// JSON for people: objects indented a field a line, as `serde_json`'s pretty form, but each
/// element of a list on one line of its own. A sweep then reads a point a line (a table, as
/// in its CSV) rather than twenty lines a point, and is written in a quarter less time.
struct Rows<'a> {
    /// Indentation of the innermost indented container.
    level: usize,
    /// Containers opened inside a one-line list element, still open (0: indenting).
    inline: usize,
    /// Of the indented containers open, whether each is a list.
    lists: Vec<bool>,
    /// Whether the innermost indented container has a value yet.
    has_value: bool,
    numbers: &'a mut Numbers,
}

impl<'a> Rows<'a> {
    fn new(numbers: &'a mut Numbers) -> Rows<'a> {
        Rows {
            level: 0,
            inline: 0,
            lists: Vec::new(),
            has_value: false,
            numbers,
        }
    }

    fn open<W: ?Sized + Write>(&mut self, w: &mut W, list: bool) -> io::Result<()> {
        if self.inline > 0 || self.lists.last() == Some(&true) {
            self.inline += 1;
        } else {
            self.level += 1;
            self.lists.push(list);
            self.has_value = false;
        }
        w.write_all(if list { b"[" } else { b"{" })
    }

    fn close<W: ?Sized + Write>(&mut self, w: &mut W, list: bool) -> io::Result<()> {
        if self.inline > 0 {
            self.inline -= 1;
        } else {
            self.level -= 1;
            self.lists.pop();
            if self.has_value {
                self.newline(w)?;
            }
        }
        w.write_all(if list { b"]" } else { b"}" })
    }

    /// Before a field or an element: a comma unless it is the first, and a new line when
    /// indenting.
    fn next<W: ?Sized + Write>(&mut self, w: &mut W, first: bool) -> io::Result<()> {
        if !first {
            w.write_all(b",")?;
        }
        if self.inline == 0 {
            self.newline(w)?;
        }
        Ok(())
    }

    fn newline<W: ?Sized + Write>(&self, w: &mut W) -> io::Result<()> {
        w.write_all(b"\n")?;
        for _ in 0..self.level {
            w.write_all(b"  ")?;
        }
        Ok(())
    }

    fn valued(&mut self) {
        if self.inline == 0 {
            self.has_value = true;
        }
    }
}

impl Formatter for Rows<'_> {
    fn write_f64<W: ?Sized + Write>(&mut self, w: &mut W, value: f64) -> io::Result<()> {
        w.write_all(self.numbers.text(value))
    }

    fn write_null<W: ?Sized + Write>(&mut self, _: &mut W) -> io::Result<()> {
        refuse_null()
    }

    fn write_raw_fragment<W: ?Sized + Write>(
        &mut self,
        w: &mut W,
        fragment: &str,
    ) -> io::Result<()> {
        write_raw(w, fragment)
    }

    fn begin_array<W: ?Sized + Write>(&mut self, w: &mut W) -> io::Result<()> {
        self.open(w, true)
    }

    fn end_array<W: ?Sized + Write>(&mut self, w: &mut W) -> io::Result<()> {
        self.close(w, true)
    }

    fn begin_array_value<W: ?Sized + Write>(&mut self, w: &mut W, first: bool) -> io::Result<()> {
        self.next(w, first)
    }

    fn end_array_value<W: ?Sized + Write>(&mut self, _: &mut W) -> io::Result<()> {
        self.valued();
        Ok(())
    }

    fn begin_object<W: ?Sized + Write>(&mut self, w: &mut W) -> io::Result<()> {
        self.open(w, false)
    }

    fn end_object<W: ?Sized + Write>(&mut self, w: &mut W) -> io::Result<()> {
        self.close(w, false)
    }

    fn begin_object_key<W: ?Sized + Write>(&mut self, w: &mut W, first: bool) -> io::Result<()> {
        self.next(w, first)
    }

    fn begin_object_value<W: ?Sized + Write>(&mut self, w: &mut W) -> io::Result<()> {
        w.write_all(if self.inline == 0 { b": " } else { b":" })
    }

    fn end_object_value<W: ?Sized + Write>(&mut self, _: &mut W) -> io::Result<()> {
        self.valued();
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;

    use proptest::prelude::*;
    use serde_json::value::RawValue;
    use serde_json::Value;

    use super::*;
    use crate::render::compact::tests::{json, Flat, Shapes, Tagged};

    /// Numbers drawn so that many repeat, in either sign, among every kind of double.
    fn numbers() -> impl Strategy<Value = Vec<f64>> {
        let pool = prop::collection::vec(
            prop_oneof![
                any::<f64>().prop_filter("finite", |x| x.is_finite()),
                Just(0.0),
                Just(-0.0),
                Just(f64::MIN_POSITIVE / 3.0),
                Just(f64::MAX),
                Just(1e16),
                Just(-1e-7),
            ],
            1..40,
        );
        pool.prop_flat_map(|pool| {
            let n = pool.len();
            prop::collection::vec((0..n, any::<bool>()), 0..200).prop_map(move |picks| {
                picks
                    .into_iter()
                    .map(|(i, flip)| if flip { -pool[i] } else { pool[i] })
                    .collect()
            })
        })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2000))]

        #[test]
        fn numbers_are_written_as_serde_json_writes_them(xs in numbers()) {
            let compact = write(&xs, false).unwrap();
            prop_assert_eq!(&compact, &serde_json::to_vec(&xs).unwrap());
            // Rows lays out the same text: only white space differs.
            let pretty = String::from_utf8(write(&xs, true).unwrap()).unwrap();
            let unspaced: String = pretty.split_whitespace().collect();
            prop_assert_eq!(unspaced.as_bytes(), &compact[..]);
        }
    }

    /// Whether `value` holds a `null` anywhere.
    fn holds_null(value: &Value) -> bool {
        match value {
            Value::Null => true,
            Value::Array(items) => items.iter().any(holds_null),
            Value::Object(map) => map.values().any(holds_null),
            _ => false,
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2000))]

        /// Any JSON, as itself and embedded already written: serde_json's text, or refused
        /// if it holds a `null`.
        #[test]
        fn answers_are_written_as_serde_json_writes_them(value in json()) {
            let raw = RawValue::from_string(value.to_string()).unwrap();
            let answer = serde_json::json!({"value": value, "raw": raw});
            let expected = serde_json::to_vec(&(&value, &raw)).unwrap();
            match write(&(&value, &raw), false) {
                Ok(compact) => {
                    prop_assert!(!holds_null(&value));
                    prop_assert_eq!(&compact, &expected);
                }
                Err(refused) => {
                    prop_assert!(holds_null(&value), "{}", answer);
                    prop_assert_eq!(refused, RenderError::non_finite());
                }
            }
        }
    }

    /// Every form serde's attributes and an enum's variants give an answer, in declaration
    /// order, with maps keyed by every kind of key serde_json takes.
    #[derive(Serialize)]
    struct Typed {
        z_first: f64,
        some: Option<&'static str>,
        layer: Tagged,
        other: Tagged,
        shapes: Vec<Shapes>,
        by_number: BTreeMap<i128, f32>,
        by_flag: BTreeMap<bool, &'static str>,
        by_char: BTreeMap<char, u128>,
        by_some: BTreeMap<Option<u8>, u8>,
        #[serde(flatten)]
        flat: Flat,
        bytes: &'static [u8],
        input: Box<RawValue>,
        pair: (i64, bool),
        /// Names to escape, one longer than [`Fields`] keeps.
        #[serde(rename = "tab\tname")]
        tab: u8,
        #[serde(rename = "a \"quoted\" name longer than 32 bytes")]
        long: u8,
    }

    #[test]
    fn a_typed_answer_is_written_as_serde_json_writes_it() {
        let typed = Typed {
            z_first: -1e-9,
            some: Some("quote \" and \u{1}"),
            layer: Tagged::Local {
                thickness: 1e-7,
                spare: Some(0.5),
            },
            other: Tagged::Continuum,
            shapes: vec![
                Shapes::Unit,
                Shapes::Newtype(Some(3)),
                Shapes::Tuple(-4, 0.1),
                Shapes::Struct {
                    z: '"',
                    a: vec![1, 2],
                },
            ],
            by_number: BTreeMap::from([(-10, 1.5), (9, 0.1)]),
            by_flag: BTreeMap::from([(true, "t"), (false, "f")]),
            by_char: BTreeMap::from([('é', u128::MAX)]),
            by_some: BTreeMap::from([(Some(1), 2)]),
            flat: Flat {
                zeta: 7,
                skipped: None,
            },
            bytes: b"ab",
            input: RawValue::from_string(r#"{"b": [1, 2.5e-9], "a": "x"}"#.into()).unwrap(),
            pair: (i64::MIN, false),
            tab: 1,
            long: 2,
        };
        let compact = String::from_utf8(write(&typed, false).unwrap()).unwrap();
        assert_eq!(compact, serde_json::to_string(&typed).unwrap());
        assert!(compact.starts_with(r#"{"z_first":-1e-9,"some":"quote \" and \u0001","#));
        assert!(compact.contains(r#""input":{"b": [1, 2.5e-9], "a": "x"},"#));
        assert!(compact.contains(r#""by_some":{"1":2},"#));
        assert!(compact.ends_with(r#""tab\tname":1,"a \"quoted\" name longer than 32 bytes":2}"#));
        // A second time, its names from the memo.
        assert_eq!(write(&typed, false).unwrap(), compact.as_bytes());
        // Rows lays out the same text.
        let pretty = String::from_utf8(write(&typed, true).unwrap()).unwrap();
        let parsed: Value = serde_json::from_str(&pretty).unwrap();
        assert_eq!(parsed, serde_json::from_str::<Value>(&compact).unwrap());
    }

    #[test]
    fn a_non_finite_number_is_refused_and_nothing_else_is() {
        for x in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            for pretty in [false, true] {
                let refused = write(&[1.0, x], pretty).unwrap_err();
                assert_eq!(refused, RenderError::non_finite());
            }
        }
        assert_eq!(write(&("null", 1.5), false).unwrap(), br#"["null",1.5]"#);
        // JSON embedded as written (a canonical input, a fixed text) is held to the same.
        let raw = |text: &str| serde_json::value::RawValue::from_string(text.into()).unwrap();
        for pretty in [false, true] {
            let refused = write(&[raw("[1,null]")], pretty).unwrap_err();
            assert_eq!(refused, RenderError::non_finite());
            let kept = write(&[raw(r#"{"a":"x: null"}"#)], pretty).unwrap();
            assert!(String::from_utf8(kept)
                .unwrap()
                .contains(r#"{"a":"x: null"}"#));
        }
    }

    #[test]
    fn a_null_value_is_found_and_a_null_inside_a_string_is_not() {
        assert!(has_null(br#"{"a":null}"#));
        assert!(has_null(br#"{"a":[1,null]}"#));
        assert!(has_null(b"[null]"));
        assert!(has_null(b"{\n  \"a\": null\n}"));
        assert!(!has_null(br#"{"a":"nullable","b":1}"#));
        assert!(!has_null(br#"{"a":"x: null"}"#));
        assert!(!has_null(br#"{"a":"quote \" null","b":true}"#));
        assert!(!has_null(br#"{"a":"back\\","b":false}"#));
    }
}
