//! Answers as JSON text: serde_json's compact form, or [`Rows`] for people, with a
//! non-finite number refused as it is met.

use std::cell::Cell;
use std::io::{self, Write};
use std::sync::LazyLock;

use memchr::memmem;
use serde::Serialize;
use serde_json::ser::Formatter;

use super::RenderError;

/// `value` as JSON: compact, or with `pretty` one field or list element a line ([`Rows`]).
/// A non-finite number is an error, never the `null` serde_json would write for it: the
/// model promises never to return one, and a client must not read `null` as a value.
/// Compact JSON starts in the room of the thread's last (the next answer is most often of the
/// same kind and size): from nothing, a 7 kB answer took seven reallocations (issue 12).
pub(super) fn write<T: Serialize + ?Sized>(
    value: &T,
    pretty: bool,
) -> Result<Vec<u8>, RenderError> {
    let last = LAST.get();
    let room = if pretty { 1 << 16 } else { last * 17 / 16 + 64 };
    let mut json = Vec::with_capacity(room);
    // Rows inside a one-line container write serde_json's compact text.
    let rows = Rows {
        inline: usize::from(!pretty),
        ..Rows::default()
    };
    let mut serializer = serde_json::Serializer::with_formatter(&mut json, rows);
    value
        .serialize(&mut serializer)
        .map_err(|e| match e.is_io() {
            // The writer is a vector, which never fails: the error is the formatter's refusal
            // of a null.
            true => RenderError::non_finite(),
            false => RenderError(format!("cannot write the result: {e}")),
        })?;
    if !pretty {
        LAST.set(json.len());
        // A small answer after a large one does not keep the large one's room.
        if json.capacity() > json.len() + json.len() / 8 + 64 {
            json.shrink_to_fit();
        }
    }
    Ok(json)
}

thread_local! {
    /// The size of the last compact answer this thread wrote.
    static LAST: Cell<usize> = const { Cell::new(0) };
}

/// serde_json writes `null` for a NaN or an infinity; the answers hold no other (absent options
/// are skipped), so one, written or in JSON embedded already written, stops the writing.
fn refuse_null() -> io::Result<()> {
    Err(io::Error::other("a non-finite number"))
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

/// JSON for people: objects a field a line, each element of a list on one line of its own: a
/// sweep reads a point a line rather than twenty, and is written in a quarter less time.
#[derive(Default)]
struct Rows {
    /// Indentation of the innermost indented container.
    level: usize,
    /// Containers opened inside a one-line list element, still open (0: indenting).
    inline: usize,
    /// Of the indented containers open, whether each is a list.
    lists: Vec<bool>,
    /// Whether the innermost indented container has a value yet.
    has_value: bool,
}

impl Rows {
    fn newline<W: ?Sized + Write>(&self, w: &mut W) -> io::Result<()> {
        w.write_all(b"\n")?;
        for _ in 0..self.level {
            w.write_all(b"  ")?;
        }
        Ok(())
    }
}

/// The four methods of a kind of container (lists and objects are written alike).
macro_rules! container {
    ($list:literal, $begin:ident, $end:ident, $before:ident, $after:ident) => {
        fn $begin<W: ?Sized + Write>(&mut self, w: &mut W) -> io::Result<()> {
            if self.inline > 0 || self.lists.last() == Some(&true) {
                self.inline += 1;
            } else {
                self.level += 1;
                self.lists.push($list);
                self.has_value = false;
            }
            w.write_all(if $list { b"[" } else { b"{" })
        }

        fn $end<W: ?Sized + Write>(&mut self, w: &mut W) -> io::Result<()> {
            if self.inline > 0 {
                self.inline -= 1;
            } else {
                self.level -= 1;
                self.lists.pop();
                if self.has_value {
                    self.newline(w)?;
                }
            }
            w.write_all(if $list { b"]" } else { b"}" })
        }

        /// A comma unless first, and a new line when indenting.
        fn $before<W: ?Sized + Write>(&mut self, w: &mut W, first: bool) -> io::Result<()> {
            if !first {
                w.write_all(b",")?;
            }
            if self.inline == 0 {
                self.newline(w)?;
            }
            Ok(())
        }

        fn $after<W: ?Sized + Write>(&mut self, _: &mut W) -> io::Result<()> {
            if self.inline == 0 {
                self.has_value = true;
            }
            Ok(())
        }
    };
}

impl Formatter for Rows {
    fn write_null<W: ?Sized + Write>(&mut self, _: &mut W) -> io::Result<()> {
        refuse_null()
    }

    fn write_raw_fragment<W: ?Sized + Write>(
        &mut self,
        w: &mut W,
        fragment: &str,
    ) -> io::Result<()> {
        if has_null(fragment.as_bytes()) {
            return refuse_null();
        }
        w.write_all(fragment.as_bytes())
    }

    container!(
        true,
        begin_array,
        end_array,
        begin_array_value,
        end_array_value
    );
    container!(
        false,
        begin_object,
        end_object,
        begin_object_key,
        end_object_value
    );

    fn begin_object_value<W: ?Sized + Write>(&mut self, w: &mut W) -> io::Result<()> {
        w.write_all(if self.inline == 0 { b": " } else { b":" })
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use std::collections::BTreeMap;

    use proptest::prelude::*;
    use serde_json::value::RawValue;
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

        #[test]
        fn numbers_are_written_as_serde_json_writes_them(xs in numbers()) {
            let compact = write(&xs, false).unwrap();
            prop_assert_eq!(&compact, &serde_json::to_vec(&xs).unwrap());
            // Rows lays out the same text: only white space differs.
            let pretty = String::from_utf8(write(&xs, true).unwrap()).unwrap();
            let unspaced: String = pretty.split_whitespace().collect();
            prop_assert_eq!(unspaced.as_bytes(), &compact[..]);
        }


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
        /// Names to escape, one of them long.
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
        // A second time, into the room the first left.
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
