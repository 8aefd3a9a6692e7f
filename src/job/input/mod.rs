//! The pieces every job kind's input is made of: quantities with units ([`units`]), the
//! Kelvin layer and the quadrature options shared by several kinds, and the [`Checker`] that
//! reads fields and reports every bad one with its path, its value as sent and the allowed
//! range.
//!
//! A field's name is written once, as the field of its input struct: the [`field!`] macro
//! takes the error path from the struct field itself, serde takes the wire name from it,
//! and the canonical form is the input struct filled in and serialized ([`canonical`]).

mod canonical;
mod checker;
mod json;
mod layer;
mod quadrature;
pub mod units;
mod upper;

use std::fmt;

use serde::de::{self, DeserializeOwned, Visitor};
use serde::{Deserialize, Deserializer, Serialize};
use serde_json::Value;
use utoipa::openapi::schema::{
    KnownFormat, ObjectBuilder, OneOfBuilder, Schema, SchemaFormat, Type,
};
use utoipa::openapi::RefOr;
use utoipa::{PartialSchema, ToSchema};

pub use canonical::{canonical, canonical_text};
pub use checker::{parameters_read, Checker};
pub use json::parse;
pub use layer::{LayerInput, LayerModel};
pub use quadrature::QuadratureKind;
pub use upper::{UpperContactKind, UpperSurfaceInput};

use super::JobError;

/// A quantity as sent, before [`units`] reads it in SI: a number (SI already), or text with
/// a unit (its schema, below, says so to clients).
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(untagged)]
pub enum Quantity {
    Number(f64),
    Text(String),
}

/// The schema says what it can of a quantity: a number, or a string starting with one (what
/// follows is the unit, whose dimension only the service checks), so that a client
/// generated from the spec does not send `""` or `"twelve"` (written by hand: a variant's
/// text cannot carry a pattern in the derive).
impl PartialSchema for Quantity {
    fn schema() -> RefOr<Schema> {
        let number = ObjectBuilder::new()
            .schema_type(Type::Number)
            .format(Some(SchemaFormat::KnownFormat(KnownFormat::Double)));
        let text = ObjectBuilder::new()
            .schema_type(Type::String)
            .pattern(Some(r"^\s*[+-]?(\d|\.\d)"));
        OneOfBuilder::new()
            .item(number)
            .item(text)
            .description(Some(
                "A quantity as sent: an SI number, or a string with a unit such as `\"25 nm\"`, \
                 `\"1.2 nN\"`, `\"4 nm/s\"`, `\"3 GPa\"` or `\"100 ms\"` (its dimension must be \
                 the field's).",
            ))
            .into()
    }
}

impl ToSchema for Quantity {}

impl<'de> Deserialize<'de> for Quantity {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(QuantityVisitor)
    }
}

/// Reads a number or a string, and says what it expects in the user's terms.
struct QuantityVisitor;

impl Visitor<'_> for QuantityVisitor {
    type Value = Quantity;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a number (in SI units) or a string with a unit such as \"25 nm\"")
    }

    fn visit_f64<E: de::Error>(self, x: f64) -> Result<Quantity, E> {
        Ok(Quantity::Number(x))
    }

    fn visit_i64<E: de::Error>(self, n: i64) -> Result<Quantity, E> {
        Ok(Quantity::Number(n as f64))
    }

    fn visit_u64<E: de::Error>(self, n: u64) -> Result<Quantity, E> {
        Ok(Quantity::Number(n as f64))
    }

    fn visit_str<E: de::Error>(self, s: &str) -> Result<Quantity, E> {
        Ok(Quantity::Text(s.to_string()))
    }
}

impl Quantity {
    /// The canonical form of an SI value: a number, with -0 read as 0.
    pub fn si(x: f64) -> Option<Quantity> {
        Some(Quantity::Number(si(x)))
    }

    /// The value as sent, for error reports and warnings (a long text cut, so that they
    /// never echo a huge input back).
    fn sent(&self) -> Value {
        match self {
            Quantity::Number(x) => Value::from(*x),
            Quantity::Text(s) => Value::from(super::echoed(s)),
        }
    }
}

/// -0.0 and 0.0 are the same input: one canonical form, one cache key.
pub fn si(x: f64) -> f64 {
    if x == 0.0 {
        0.0
    } else {
        x
    }
}

/// A field of an input as sent: its name and its value, if any.
#[derive(Debug)]
pub struct Field<'a, T> {
    pub name: &'static str,
    pub value: Option<&'a T>,
}

impl<T> Clone for Field<'_, T> {
    fn clone(&self) -> Self {
        *self
    }
}

impl<T> Copy for Field<'_, T> {}

/// `field!(input.radius)`: the field `radius` of `input` (an `Option`), named after the
/// struct field itself, so that an error's path cannot drift from the input's shape.
macro_rules! field {
    ($input:ident . $name:ident) => {
        $crate::job::input::Field {
            name: stringify!($name),
            value: $input.$name.as_ref(),
        }
    };
}
pub(crate) use field;

/// Reads `value` strictly as `T` (objects only where `T` has one; see [`json::Strict`]); a
/// misshapen field is reported with its path under `prefix`.
pub fn deserialize<T: DeserializeOwned>(value: Value, prefix: &str) -> Result<T, JobError> {
    serde_path_to_error::deserialize(json::Strict(value)).map_err(|e| {
        let inner = e.path().to_string();
        let field = match (prefix, inner.as_str()) {
            (p, ".") => p.to_string(),
            ("", i) => i.to_string(),
            (p, i) => format!("{p}.{i}"),
        };
        JobError::Schema {
            field,
            message: e.into_inner().to_string(),
        }
    })
}

/// Deserializes an input of type `I` and reads it with `read` under a fresh checker: the
/// job (with its input's warnings), or every bad field at once.
pub fn validate<I: DeserializeOwned, T>(
    value: Value,
    read: impl FnOnce(&I, &mut Checker) -> T,
) -> Result<super::Validated<T>, JobError> {
    let input: I = deserialize(value, "")?;
    let mut checker = Checker::new();
    let job = read(&input, &mut checker);
    checker.finish(job)
}
