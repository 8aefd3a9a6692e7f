//! The fixed parts of answers: what is the same in every answer of a kind (its references,
//! its unit table, an assumption in words), kept in a `static` together with its JSON,
//! rendered once on first use. Building and escaping them again for every answer made up
//! about a quarter of rendering one.

use std::collections::BTreeMap;
use std::fmt;
use std::sync::OnceLock;

use serde::ser::Error as _;
use serde::{Serialize, Serializer};
use serde_json::value::RawValue;

/// A fixed part of answers and its JSON. Declared as a `static` (a `const` would be a new
/// value, and a new rendering, at every use): `static X: Fixed<T> = Fixed::new(value);`.
pub struct Fixed<T: 'static> {
    value: T,
    json: OnceLock<Box<RawValue>>,
}

impl<T> Fixed<T> {
    pub const fn new(value: T) -> Fixed<T> {
        Fixed {
            value,
            json: OnceLock::new(),
        }
    }
}

impl<T: Serialize> Fixed<T> {
    /// The JSON, rendered at the first call (two threads meeting it at once may both
    /// render it; one copy then goes unused, once).
    fn json(&self) -> serde_json::Result<&RawValue> {
        if let Some(json) = self.json.get() {
            return Ok(json);
        }
        let rendered = serde_json::value::to_raw_value(&self.value)?;
        Ok(self.json.get_or_init(|| rendered))
    }
}

impl<T: Serialize> Serialize for Fixed<T> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.json().map_err(S::Error::custom)?.serialize(s)
    }
}

impl<T: fmt::Debug> fmt::Debug for Fixed<T> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.value.fmt(f)
    }
}

impl<T: PartialEq> PartialEq for Fixed<T> {
    fn eq(&self, other: &Fixed<T>) -> bool {
        self.value == other.value
    }
}

/// A fixed text of answers (an assumption in words, its rule).
pub type Text = Fixed<&'static str>;

/// The unit of each numeric field of an answer, by path (`a.b`, `list[].c`): SI, `""` for
/// plain numbers and counts; in groups, so that the parts answers share are declared once.
pub type Units = &'static [&'static [(&'static str, &'static str)]];

/// The units of an answer as one JSON object, path → unit (groups may share entries, as
/// the two kinds of sweep points do).
#[derive(Debug, PartialEq)]
pub struct UnitGroups(pub Units);

impl Serialize for UnitGroups {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let map: BTreeMap<_, _> = self
            .0
            .iter()
            .flat_map(|group| group.iter().copied())
            .collect();
        map.serialize(s)
    }
}

/// The unit table of an output kind ([`super::Output::UNITS`]).
pub type UnitTable = Fixed<UnitGroups>;

/// An output's unit table ([`super::Output::UNITS`]) from its groups of (path, unit), as a
/// `static` of its own, so that its JSON is rendered once:
/// `const UNITS: &'static UnitTable = unit_table![&[("x", "m")]];`.
#[macro_export]
macro_rules! unit_table {
    ($($group:expr),* $(,)?) => {{
        static UNITS: $crate::render::UnitTable =
            $crate::render::Fixed::new($crate::render::UnitGroups(&[$($group),*]));
        &UNITS
    }};
}

#[cfg(test)]
mod tests {
    use super::*;

    static SHORT: Fixed<&[u32]> = Fixed::new(&[1, 2]);
    static LONG: Fixed<&[u32]> = Fixed::new(&[1, 2, 3]);
    static UNITS: UnitTable = Fixed::new(UnitGroups(&[&[("b", "m")], &[("a", ""), ("b", "m")]]));

    /// Rendered once, a fixed part still matches a direct rendering on every later use, and
    /// two statics whose values share a prefix stay apart.
    #[test]
    fn a_fixed_part_rendered_once_matches_a_direct_rendering_every_time() {
        for _ in 0..2 {
            assert_eq!(serde_json::to_string(&SHORT).unwrap(), "[1,2]");
            assert_eq!(serde_json::to_string(&LONG).unwrap(), "[1,2,3]");
            assert_eq!(
                serde_json::to_string(&UNITS).unwrap(),
                r#"{"a":"","b":"m"}"#
            );
        }
    }
}
