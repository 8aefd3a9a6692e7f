//! Outputs that describe themselves: each numeric field is declared once with its unit and CSV
//! column, if any ([`described!`]); the unit table (`meta.units`) and the CSV columns are both
//! made from it, so a field cannot be added, renamed or moved without both following.

use std::collections::BTreeMap;
use std::fmt;
use std::sync::{Arc, LazyLock};

use serde::{Serialize, Serializer};

use super::Column;

/// How a row gives the number of a column (`None`: an empty cell).
pub type Reader<T> = Arc<dyn Fn(&T) -> Option<f64> + Send + Sync>;

/// A numeric field of an output, at any depth under it.
pub struct Field<T> {
    /// Its JSON path under the output: `penetration`, `static.contact_area`, `boundary[].y`.
    pub path: String,
    /// Its SI unit ("" for plain numbers and counts).
    pub unit: &'static str,
    /// Its CSV column, if it is one: the column's name and how a row gives its cell.
    pub column: Option<(String, Reader<T>)>,
}

/// A type whose numeric fields are declared ([`described!`] implements it).
pub trait Fields: Sized + 'static {
    /// Every numeric field, in the order of the JSON.
    fn fields() -> Vec<Field<Self>>;
}

/// The JSON key of a Rust field name (a raw identifier such as `r#static` is `static`, as
/// serde writes it).
pub fn key(name: &str) -> &str {
    name.trim_start_matches("r#")
}

impl<T: 'static> Field<T> {
    /// A number under `key`, in `unit`, which is also the column `key`.
    pub fn column(key: &str, unit: &'static str, read: fn(&T) -> Option<f64>) -> Vec<Field<T>> {
        vec![Field {
            path: key.to_string(),
            unit,
            column: Some((key.to_string(), Arc::new(read))),
        }]
    }

    /// A number (or numbers: `path` ends in `[]` for a list) at `path`, in `unit`, no column.
    pub fn unit(path: &str, unit: &'static str) -> Vec<Field<T>> {
        Self::paths(path, [(String::new(), unit)])
    }

    /// The fields of a `U` under `key` (`""`: flattened into `T`). With `columns`, its columns
    /// are `T`'s too, named with that prefix; a row whose `read` gives no `U` has them empty.
    pub fn nested<U: Fields>(
        key: &str,
        columns: Option<&str>,
        read: fn(&T) -> Option<&U>,
    ) -> Vec<Field<T>> {
        U::fields()
            .into_iter()
            .map(|inner| Field {
                path: under(key, &inner.path),
                unit: inner.unit,
                column: columns.zip(inner.column).map(|(prefix, (name, cell))| {
                    let read: Reader<T> = Arc::new(move |t: &T| read(t).and_then(|u| cell(u)));
                    (format!("{prefix}{name}"), read)
                }),
            })
            .collect()
    }

    /// The fields of each `U` of a list under `key` (never columns: a row is one record).
    pub fn each<U: Fields>(key: &str) -> Vec<Field<T>> {
        let inner = U::fields().into_iter();
        Self::paths(key, inner.map(|f| (under("[]", &f.path), f.unit)))
    }

    /// The numbers at each (path, unit) of `paths`, under `key`: fields whose paths come
    /// from data (a map keyed by parameter name), no columns.
    pub fn paths(
        key: &str,
        paths: impl IntoIterator<Item = (String, &'static str)>,
    ) -> Vec<Field<T>> {
        paths
            .into_iter()
            .map(|(path, unit)| Field {
                path: under(key, &path),
                unit,
                column: None,
            })
            .collect()
    }

    /// The fields of a `U` under `key`, every one in `unit`: a type whose numbers are in the
    /// unit of what holds it (a measured value and its fit), no columns.
    pub fn nested_in<U: Fields>(key: &str, unit: &'static str) -> Vec<Field<T>> {
        Self::paths(key, U::fields().into_iter().map(|f| (f.path, unit)))
    }
}

/// `path` under `key`: `key.path`, `key[]…` for a list's, `path` for an empty key
/// (flattened) and `key` for an empty path.
fn under(key: &str, path: &str) -> String {
    if path.is_empty() {
        key.to_string()
    } else if key.is_empty() {
        path.to_string()
    } else if path.starts_with('[') {
        format!("{key}{path}")
    } else {
        format!("{key}.{path}")
    }
}

/// What a list or an option holds (the element type that `[each]` names).
pub trait Element {
    type Item;
}

impl<T> Element for Vec<T> {
    type Item = T;
}

impl<T> Element for Option<T> {
    type Item = T;
}

/// The unit of every numeric field of `T`, by path.
pub fn units<T: Fields>() -> BTreeMap<String, &'static str> {
    T::fields().into_iter().map(|f| (f.path, f.unit)).collect()
}

/// The CSV columns of `T`'s fields, in their order.
pub fn columns<T: Fields>() -> Vec<Column<T>> {
    T::fields()
        .into_iter()
        .filter_map(|f| {
            f.column
                .map(|(name, read)| Column::read(name, f.unit, read))
        })
        .collect()
}

/// The unit table of an output: path → unit, made from its fields on first use.
pub struct UnitGroups(LazyLock<BTreeMap<String, &'static str>>);

impl UnitGroups {
    /// The table `build` makes ([`units`] of the output).
    pub const fn new(build: fn() -> BTreeMap<String, &'static str>) -> UnitGroups {
        UnitGroups(LazyLock::new(build))
    }

    pub fn get(&self) -> &BTreeMap<String, &'static str> {
        &self.0
    }
}

impl Serialize for UnitGroups {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        self.get().serialize(s)
    }
}

impl fmt::Debug for UnitGroups {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.get().fmt(f)
    }
}

impl PartialEq for UnitGroups {
    fn eq(&self, other: &UnitGroups) -> bool {
        self.get() == other.get()
    }
}

/// Declares an output struct and its [`Fields`]: each field as usual (docs, attributes,
/// type), followed by `=> [how]`, what it is as a number:
/// - `[]`: not a number (text, a status), or not part of the JSON;
/// - `[number "m"]`: an `f64` in metres, also the CSV column of its name;
/// - `[optional "m"]`: an `Option<f64>`, the same (an empty cell when absent);
/// - `[unit "m"]`, `[list "m"]`, `[grid "m"]`: a number (any type), a list of them, a list
///   of lists: in the unit table, no column;
/// - `[nested]`, `[nested "prefix_"]`: a [`Fields`] type under the field's key, its columns
///   (with the prefix) also the outer type's when a prefix is given; `[optional nested …]`
///   for an `Option` of it; `[flatten]`, `[optional flatten]` for one `#[serde(flatten)]`
///   into the outer type (its columns unprefixed);
/// - `[in "m^2"]`, `[optional in "m^2"]`: a [`Fields`] type (or an `Option` of it) whose
///   every number is in the given unit, no columns;
/// - `[by f()]`, `[flatten by f()]`: numbers whose paths (under the key, or flattened) and
///   units `f()` lists;
/// - `[each]`: a `Vec` of a [`Fields`] type (`key[].…`).
#[macro_export]
macro_rules! described {
    (
        $(#[$meta:meta])*
        $vis:vis struct $name:ident {
            $(
                $(#[$field_meta:meta])*
                $field_vis:vis $field:ident : $ty:ty => [$($how:tt)*]
            ),* $(,)?
        }
    ) => {
        $(#[$meta])*
        $vis struct $name {
            $( $(#[$field_meta])* $field_vis $field: $ty, )*
        }

        impl $crate::render::Fields for $name {
            fn fields() -> Vec<$crate::render::Field<Self>> {
                let mut fields: Vec<$crate::render::Field<Self>> = Vec::new();
                $(
                    #[allow(unused_variables)] // by the arms that flatten
                    let key = $crate::render::fields::key(stringify!($field));
                    fields.extend($crate::described!(@how key, $field, $ty, $($how)*));
                )*
                fields
            }
        }
    };
    (@how $key:ident, $field:ident, $ty:ty, ) => {
        Vec::<$crate::render::Field<Self>>::new()
    };
    (@how $key:ident, $field:ident, $ty:ty, number $unit:literal) => {
        $crate::render::Field::column($key, $unit, |s: &Self| Some(s.$field))
    };
    (@how $key:ident, $field:ident, $ty:ty, optional $unit:literal) => {
        $crate::render::Field::column($key, $unit, |s: &Self| s.$field)
    };
    (@how $key:ident, $field:ident, $ty:ty, unit $unit:literal) => {
        $crate::render::Field::<Self>::unit($key, $unit)
    };
    (@how $key:ident, $field:ident, $ty:ty, list $unit:literal) => {
        $crate::render::Field::<Self>::unit(&format!("{}[]", $key), $unit)
    };
    (@how $key:ident, $field:ident, $ty:ty, grid $unit:literal) => {
        $crate::render::Field::<Self>::unit(&format!("{}[][]", $key), $unit)
    };
    (@how $key:ident, $field:ident, $ty:ty, nested $($prefix:literal)?) => {
        $crate::render::Field::nested($key, $crate::described!(@prefix $($prefix)?), |s: &Self| {
            Some(&s.$field)
        })
    };
    (@how $key:ident, $field:ident, $ty:ty, optional nested $($prefix:literal)?) => {
        $crate::render::Field::nested($key, $crate::described!(@prefix $($prefix)?), |s: &Self| {
            s.$field.as_ref()
        })
    };
    (@how $key:ident, $field:ident, $ty:ty, flatten) => {
        $crate::render::Field::nested("", Some(""), |s: &Self| Some(&s.$field))
    };
    (@how $key:ident, $field:ident, $ty:ty, optional flatten) => {
        $crate::render::Field::nested("", Some(""), |s: &Self| s.$field.as_ref())
    };
    (@how $key:ident, $field:ident, $ty:ty, in $unit:literal) => {
        $crate::render::Field::<Self>::nested_in::<$ty>($key, $unit)
    };
    (@how $key:ident, $field:ident, $ty:ty, optional in $unit:literal) => {
        $crate::render::Field::<Self>::nested_in::<
            <$ty as $crate::render::fields::Element>::Item,
        >($key, $unit)
    };
    (@how $key:ident, $field:ident, $ty:ty, by $paths:expr) => {
        $crate::render::Field::<Self>::paths($key, $paths)
    };
    (@how $key:ident, $field:ident, $ty:ty, flatten by $paths:expr) => {
        $crate::render::Field::<Self>::paths("", $paths)
    };
    (@how $key:ident, $field:ident, $ty:ty, each) => {
        $crate::render::Field::<Self>::each::<<$ty as $crate::render::fields::Element>::Item>($key)
    };
    (@prefix) => { None };
    (@prefix $prefix:literal) => { Some($prefix) };
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::{Cell, Table};
    use serde::Serialize;

    crate::described! {
        #[derive(Serialize)]
        struct Inner {
            r#static: f64 => [number "m"],
            count: usize => [unit ""],
        }
    }

    crate::described! {
        #[derive(Serialize)]
        struct Row {
            x: f64 => [number "N"],
            label: String => [],
            maybe: Option<f64> => [optional "s"],
            inner: Inner => [nested "in_"],
            quiet: Inner => [nested],
            #[serde(flatten)]
            flat: Option<Inner> => [optional flatten],
            list: Vec<Inner> => [each],
            xs: Vec<f64> => [list "Pa"],
            grid: Vec<Vec<f64>> => [grid "m"],
            named: () => [by vec![("a".to_string(), "m^2")]],
        }
    }

    fn inner(x: f64) -> Inner {
        Inner {
            r#static: x,
            count: 1,
        }
    }

    /// Every way a field can be declared gives its path and unit, and the fields that are
    /// columns read their cells from the row, nested ones through what holds them.
    #[test]
    fn one_declaration_gives_the_units_and_the_columns() {
        let units = units::<Row>();
        let expected = [
            ("x", "N"),
            ("maybe", "s"),
            ("inner.static", "m"),
            ("inner.count", ""),
            ("quiet.static", "m"),
            ("quiet.count", ""),
            ("static", "m"),
            ("count", ""),
            ("list[].static", "m"),
            ("list[].count", ""),
            ("xs[]", "Pa"),
            ("grid[][]", "m"),
            ("named.a", "m^2"),
        ];
        let expected: BTreeMap<String, &str> =
            expected.iter().map(|(p, u)| (p.to_string(), *u)).collect();
        assert_eq!(units, expected);

        let row = Row {
            x: 2.0,
            label: "a".to_string(),
            maybe: None,
            inner: inner(3.0),
            quiet: inner(4.0),
            flat: Some(inner(5.0)),
            list: vec![inner(6.0)],
            xs: vec![],
            grid: vec![],
            named: (),
        };
        let table = Table::new(&columns::<Row>(), [&row]);
        assert_eq!(
            table.to_csv().unwrap(),
            "x [N],maybe [s],in_static [m],static [m]\n2,,3,5\n"
        );
        let empty = Row { flat: None, ..row };
        let cells = &Table::new(&columns::<Row>(), [&empty]).rows[0];
        assert_eq!(cells[3], Cell::Empty);
    }
}
