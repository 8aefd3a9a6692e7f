//! The job kinds the service knows, found by their name on the wire. Adding a kind is its
//! module and one line in [`LIST`]: the envelope, the job store, the OpenAPI schemas of
//! `JobKind` and `Output` follow from here.

use std::borrow::Cow;

use serde::{Deserialize, Deserializer};
use serde_json::Value;
use utoipa::openapi::schema::{Object, ObjectBuilder, OneOfBuilder, Schema, SchemaType, Type};
use utoipa::openapi::RefOr;
use utoipa::{PartialSchema, ToSchema};

use super::figure::FigureJob;
use super::fit::FitJob;
use super::kind::{Job, Schemas};
pub use super::kind::{KindName, Registered};
use super::rolling::RollingJob;
use super::sweep::SweepJob;
use super::three_body::ThreeBodyJob;
use super::{JobError, Limits};

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

impl KindName {
    /// The kind named `name`, or the error naming the known ones.
    pub fn find(name: &str) -> Result<KindName, JobError> {
        find(name).map(KindName)
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
