//! The parts of answers the same in every answer of a kind (references, the unit table, an
//! assumption in words), in a `static` with their JSON rendered on first use: building and
//! escaping them for every answer made up about a quarter of rendering one.

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

    pub fn get(&self) -> &T {
        &self.value
    }
}

/// The JSON, rendered at the first use (two threads meeting it at once may both render it;
/// one copy then goes unused, once).
impl<T: Serialize> Serialize for Fixed<T> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        if let Some(json) = self.json.get() {
            return json.serialize(s);
        }
        let rendered = serde_json::value::to_raw_value(&self.value).map_err(S::Error::custom)?;
        self.json.get_or_init(|| rendered).serialize(s)
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

/// The unit table of an output kind ([`super::Output::UNITS`]).
pub type UnitTable = Fixed<super::UnitGroups>;

/// The unit table of `$output`, a `static` of its own so that its JSON is rendered once:
/// `const UNITS: &'static UnitTable = unit_table!(RollingOutput);`.
#[macro_export]
macro_rules! unit_table {
    ($output:ty) => {{
        static UNITS: $crate::render::UnitTable = $crate::render::Fixed::new(
            $crate::render::UnitGroups::new($crate::render::fields::units::<$output>),
        );
        &UNITS
    }};
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::UnitGroups;

    static SHORT: Fixed<&[u32]> = Fixed::new(&[1, 2]);
    static LONG: Fixed<&[u32]> = Fixed::new(&[1, 2, 3]);
    static UNITS: UnitTable = Fixed::new(UnitGroups::new(|| {
        [("b", "m"), ("a", "")]
            .map(|(path, unit)| (path.to_string(), unit))
            .into()
    }));

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
