//! Answers as JSON text: serde_json's compact form, or [`Rows`] for people, with numbers
//! written through a memo ([`Numbers`]) and a non-finite number refused as it is met.

use std::cell::RefCell;
use std::io::{self, Write};
use std::sync::LazyLock;

use memchr::memmem;
use serde::Serialize;
use serde_json::ser::Formatter;

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
        // The writer is a vector, which never fails: the error is the formatter's refusal.
        true => RenderError::non_finite(),
        false => RenderError(format!("cannot write the result: {e}")),
    })
}

thread_local! {
    /// What each thread keeps between the answers it writes.
    pub(super) static SCRATCH: RefCell<Scratch> = const { RefCell::new(Scratch::new()) };
}

/// Buffers larger than this are not kept for the next answer.
pub(super) const SCRATCH_KEPT: usize = 64 << 10;

/// A buffer to write answers into and the memo of their numbers. Written into a fresh
/// vector, a 7 kB rolling answer grew through seven reallocations and their copies, and the
/// large ones made the allocator consolidate its free lists: on an uncached request's path
/// (BENCHMARKS.md, issue 12). The memo is kept too: made anew for each answer, its 10 kB
/// cost more than it saved.
pub(super) struct Scratch {
    pub(super) buffer: Vec<u8>,
    numbers: Numbers,
}

impl Scratch {
    const fn new() -> Scratch {
        Scratch {
            buffer: Vec::new(),
            numbers: Numbers::new(),
        }
    }

    /// `value` as JSON, in a vector of its exact size (compact) or of room to spare (pretty,
    /// for a terminal: written once).
    fn write<T: Serialize + ?Sized>(
        &mut self,
        value: &T,
        pretty: bool,
    ) -> serde_json::Result<Vec<u8>> {
        let Scratch { buffer, numbers } = self;
        if pretty {
            let mut json = Vec::with_capacity(SCRATCH_KEPT);
            serialize(value, &mut json, Rows::new(numbers))?;
            return Ok(json);
        }
        buffer.clear();
        let written = serialize(value, buffer, Compact { numbers }).map(|()| buffer.to_vec());
        if buffer.capacity() > SCRATCH_KEPT {
            *buffer = Vec::new();
        }
        written
    }
}

fn serialize<T: Serialize + ?Sized>(
    value: &T,
    out: &mut Vec<u8>,
    formatter: impl Formatter,
) -> serde_json::Result<()> {
    value.serialize(&mut serde_json::Serializer::with_formatter(
        Tokens(out),
        formatter,
    ))
}

/// The vector serde_json writes an answer into, a token at a time. Most tokens are one byte
/// (`"`, `,`, `:`, brackets), which `Vec`'s own `write_all` copies through a call to
/// `memcpy`; they are pushed here (a rolling answer has about 1,200 tokens).
struct Tokens<'a>(&'a mut Vec<u8>);

impl Write for Tokens<'_> {
    #[inline]
    fn write(&mut self, bytes: &[u8]) -> io::Result<usize> {
        self.write_all(bytes)?;
        Ok(bytes.len())
    }

    #[inline]
    fn write_all(&mut self, bytes: &[u8]) -> io::Result<()> {
        match bytes {
            [byte] => self.0.push(*byte),
            _ => self.0.extend_from_slice(bytes),
        }
        Ok(())
    }

    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
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

    /// Writes `x`, finite (serde_json sends non-finite numbers to `write_null`).
    fn write<W: ?Sized + Write>(&mut self, w: &mut W, x: f64) -> io::Result<()> {
        let magnitude = x.abs();
        let bits = magnitude.to_bits();
        let place = bits.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> (64 - SLOTS.trailing_zeros());
        let slot = &mut self.slots[place as usize];
        if slot.inverted != !bits {
            let mut shortest = zmij::Buffer::new();
            let text = shortest.format_finite(magnitude).as_bytes();
            slot.text[0] = b'-';
            slot.text[1..=text.len()].copy_from_slice(text);
            slot.len = text.len() as u8;
            slot.inverted = !bits;
        }
        let start = usize::from(!x.is_sign_negative());
        w.write_all(&slot.text[start..=usize::from(slot.len)])
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

/// The values both layouts write alike: numbers through the formatter's [`Numbers`], `null`
/// refused, embedded JSON searched for `null` as it is copied.
macro_rules! answer_values {
    () => {
        fn write_f64<W: ?Sized + Write>(&mut self, w: &mut W, value: f64) -> io::Result<()> {
            self.numbers.write(w, value)
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
    };
}

/// serde_json's compact form, its numbers through [`Numbers`].
struct Compact<'a> {
    numbers: &'a mut Numbers,
}

impl Formatter for Compact<'_> {
    answer_values!();
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
    answer_values!();

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
    use proptest::prelude::*;

    use super::*;

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
