//! The job kinds the service knows, found by their name on the wire. Adding a kind is its
//! module and one line in [`LIST`]: the envelope, the job store, the OpenAPI schemas of
//! `JobKind` and `Output` follow from here.

use std::borrow::Cow;
use std::fmt;

use serde::{Deserialize, Deserializer, Serialize, Serializer};
use serde_json::Value;
use utoipa::openapi::schema::{Object, ObjectBuilder, OneOfBuilder, Schema, SchemaType, Type};
use utoipa::openapi::{Ref, RefOr};
use utoipa::{PartialSchema, ToSchema};

use super::figure::FigureJob;
use super::fit::FitJob;
use super::kind::{Job, Kind};
use super::picture::draw;
use super::rolling::RollingJob;
use super::sweep::SweepJob;
use super::three_body::ThreeBodyJob;
use super::{JobError, Limits};
use crate::render::{Draw, Output, UnitTable};

/// Schemas as utoipa collects them: (name, schema).
type Schemas = Vec<(String, RefOr<Schema>)>;

/// A registered kind: its name and what the rest of the crate needs of it without knowing
/// its type.
pub struct Registered {
    name: &'static str,
    validate: fn(Value, &Limits) -> Result<Job, JobError>,
    picture: Draw,
    input_schema: fn() -> Cow<'static, str>,
    output_schema: fn(&mut Schemas) -> RefOr<Schema>,
    output_name: fn() -> Cow<'static, str>,
    units: &'static UnitTable,
}

impl Registered {
    /// The kind's name on the wire.
    pub fn name(&self) -> &'static str {
        self.name
    }

    const fn of<K: Kind>() -> Registered {
        Registered {
            name: K::NAME,
            validate: validate::<K>,
            picture: draw::<K::Picture>,
            input_schema: <K::Input as ToSchema>::name,
            output_schema: output_schema::<K>,
            output_name: <K::Output as ToSchema>::name,
            units: K::Output::UNITS,
        }
    }

    /// The name of the OpenAPI schema of the kind's input.
    pub fn input_name(&self) -> Cow<'static, str> {
        (self.input_schema)()
    }

    /// The name of the OpenAPI schema of the kind's answer.
    pub fn output_name(&self) -> Cow<'static, str> {
        (self.output_name)()
    }

    /// The unit of every numeric field of the kind's answer, by path.
    pub fn units(&self) -> &'static UnitTable {
        self.units
    }

    /// Reads and validates an input of this kind.
    pub fn validate(&self, input: Value, limits: &Limits) -> Result<Job, JobError> {
        (self.validate)(input, limits)
    }
}

fn validate<K: Kind>(input: Value, limits: &Limits) -> Result<Job, JobError> {
    K::validate(input, limits).map(Job::validated)
}

/// Adds the schema of `K`'s output (and those it refers to) to `schemas`; returns a
/// reference to it.
fn output_schema<K: Kind>(schemas: &mut Schemas) -> RefOr<Schema> {
    let name = K::Output::name();
    schemas.push((name.to_string(), K::Output::schema()));
    K::Output::schemas(schemas);
    Ref::from_schema_name(name).into()
}

/// Every job kind, one line each.
const LIST: &[Registered] = &[
    Registered::of::<RollingJob>(),
    Registered::of::<ThreeBodyJob>(),
    Registered::of::<SweepJob>(),
    Registered::of::<FigureJob>(),
    Registered::of::<FitJob>(),
];

static KINDS: &[Registered] = LIST;

/// Every registered kind, in the order of [`LIST`].
pub fn all() -> &'static [Registered] {
    KINDS
}

/// The kinds' names, in the order of [`LIST`] (for the CLI's help, the OpenAPI enum, and
/// errors naming the known kinds).
pub const NAMES: [&str; LIST.len()] = {
    let mut names = [""; LIST.len()];
    let mut i = 0;
    while i < names.len() {
        names[i] = LIST[i].name;
        i += 1;
    }
    names
};

/// The kind named `name`, or the error naming the known ones.
fn find(name: &str) -> Result<&'static Registered, JobError> {
    KINDS
        .iter()
        .find(|k| k.name == name)
        .ok_or_else(|| JobError::Schema {
            field: "kind".to_string(),
            message: unknown_kind(name),
        })
}

fn unknown_kind(name: &str) -> String {
    format!(
        "unknown kind \"{name}\": expected one of {}",
        quoted_names(", ")
    )
}

/// The kinds' names as JSON strings, in the order of [`LIST`], joined by `separator`.
pub fn quoted_names(separator: &str) -> String {
    let quoted: Vec<String> = NAMES.iter().map(|n| format!("\"{n}\"")).collect();
    quoted.join(separator)
}

impl Job {
    /// Parses and validates an enveloped job from JSON text.
    pub fn from_json(text: &[u8], limits: &Limits) -> Result<Job, JobError> {
        Job::from_value(super::input::parse(text)?, limits)
    }

    /// Validates an enveloped job `{"kind": ..., "input": {...}}` already parsed as JSON.
    pub fn from_value(value: Value, limits: &Limits) -> Result<Job, JobError> {
        let envelope: Envelope = super::input::deserialize(value, "")?;
        let input = envelope
            .input
            .unwrap_or_else(|| Value::Object(Default::default()));
        Job::from_input(envelope.kind.name(), input, limits)
    }

    /// Validates the input of a job of the kind named `kind` (the envelope's `input`, or the
    /// body of the HTTP endpoint of that kind): error paths are relative to the input.
    pub fn from_input(kind: &str, input: Value, limits: &Limits) -> Result<Job, JobError> {
        find(kind)?.validate(input, limits)
    }
}

/// A registered kind, as answers, records and pictures carry it: its name on the wire and
/// what the registry knows of it, without a look-up by name.
#[derive(Clone, Copy)]
pub struct KindName(&'static Registered);

impl KindName {
    /// Kind `K`.
    pub const fn of<K: Kind>() -> KindName {
        KindName(const { &Registered::of::<K>() })
    }

    /// The kind named `name`, or the error naming the known ones.
    pub fn find(name: &str) -> Result<KindName, JobError> {
        find(name).map(KindName)
    }

    pub fn name(self) -> &'static str {
        self.0.name
    }

    /// How an answer of this kind is drawn ([`Kind::Picture`], drawn by [`super::picture::draw`]).
    pub fn picture(self) -> Draw {
        self.0.picture
    }
}

impl PartialEq for KindName {
    fn eq(&self, other: &KindName) -> bool {
        self.name() == other.name()
    }
}

impl Eq for KindName {}

impl PartialEq<&str> for KindName {
    fn eq(&self, other: &&str) -> bool {
        self.name() == *other
    }
}

impl fmt::Debug for KindName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl fmt::Display for KindName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl Serialize for KindName {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

impl<'de> Deserialize<'de> for KindName {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let name = Cow::<str>::deserialize(d)?;
        KindName::find(&name).map_err(|_| serde::de::Error::custom(unknown_kind(&name)))
    }
}

impl PartialSchema for KindName {
    fn schema() -> RefOr<Schema> {
        ObjectBuilder::new()
            .schema_type(Type::String)
            .description(Some("What a job computes."))
            .enum_values(Some(NAMES))
            .into()
    }
}

impl ToSchema for KindName {
    fn name() -> Cow<'static, str> {
        Cow::Borrowed("JobKind")
    }
}

/// The envelope `{"kind": ..., "input": {...}}`; a missing input means all defaults.
#[derive(Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[schema(example = json!({"kind": "sweep", "input": {
    "vary": {"load": ["0.5 nN", "1 nN", "2 nN"], "velocity": ["0 nm/s", "4 nm/s"]}}}))]
pub struct Envelope {
    pub kind: KindName,
    #[serde(default)]
    #[schema(schema_with = any_input)]
    pub input: Option<Value>,
}

/// The envelope's `input`: an object (or absent), whose schema is its kind's.
fn any_input() -> Object {
    let names: Vec<String> = KINDS
        .iter()
        .map(|k| format!("`{}`", k.input_name()))
        .collect();
    let (last, rest) = names.split_last().expect("there are kinds");
    ObjectBuilder::new()
        .schema_type(SchemaType::from_iter([Type::Object, Type::Null]))
        .description(Some(format!(
            "The input of the job's kind: a {} or {last}. Absent, every field takes its \
             default.",
            rest.join(", ")
        )))
        .build()
}

/// The answer to any job, for the OpenAPI description: one of the kinds' outputs.
pub struct AnyOutput;

impl PartialSchema for AnyOutput {
    fn schema() -> RefOr<Schema> {
        let mut ignored = Schemas::new();
        KINDS
            .iter()
            .fold(OneOfBuilder::new(), |one_of, k| {
                one_of.item((k.output_schema)(&mut ignored))
            })
            .description(Some("The answer to any job."))
            .into()
    }
}

impl ToSchema for AnyOutput {
    fn name() -> Cow<'static, str> {
        Cow::Borrowed("Output")
    }

    fn schemas(schemas: &mut Schemas) {
        for kind in KINDS {
            (kind.output_schema)(schemas);
        }
    }
}
