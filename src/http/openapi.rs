//! The OpenAPI description, generated from the same route registration as the router (so it
//! cannot drift from what is served).

use std::collections::{BTreeMap, BTreeSet};

use axum::Router;
use serde_json::{json, Value};
use utoipa::openapi::extensions::Extensions;
use utoipa::openapi::header::HeaderBuilder;
use utoipa::openapi::path::{self, ParameterIn};
use utoipa::openapi::schema::{AdditionalProperties, ArrayItems, Object, Schema, SchemaType, Type};
use utoipa::openapi::{OpenApi as Spec, RefOr, Required};
use utoipa::{OpenApi, PartialSchema};
use utoipa_axum::router::OpenApiRouter;

use super::error::Problem;
use super::{routes, AppState};
use crate::job::input::parameters_read;
use crate::job::registry::{self, Registered};
use crate::job::Limits;
use crate::job::Quantity;
use crate::model::Parameter;

#[derive(OpenApi)]
#[openapi(
    info(
        title = "thirdbody",
        description = "Real contact area and friction coefficient of hard particles rolling \
            over a viscoelastic (Kelvin) layer. Every quantity is SI; inputs also take strings \
            with units such as \"25 nm\". Every error is an RFC 9457 problem \
            (application/problem+json)."
    ),
    tags(
        (name = "solve", description = "Synchronous solves, bounded by the solve deadline"),
        (name = "jobs", description = "Asynchronous jobs with progress and cancel"),
        (name = "figures", description = "The data behind the paper's figures"),
        (name = "operations", description = "Health, readiness, metrics"),
    ),
    components(schemas(Problem))
)]
struct ApiDoc;

/// The router and the OpenAPI document it serves, both from the routes' registration.
pub fn router_and_spec() -> (Router<AppState>, Spec) {
    let (router, mut spec) = OpenApiRouter::with_openapi(ApiDoc::openapi())
        .merge(routes::router())
        .split_for_parts();
    document_validators(&mut spec);
    document_units(&mut spec);
    document_ranges(&mut spec);
    document_access(&mut spec);
    (router, spec)
}

/// The OpenAPI document of the service, as committed in `openapi/openapi.json`.
pub fn spec_json() -> String {
    let mut json = router_and_spec()
        .1
        .to_pretty_json()
        .expect("an OpenAPI document serializes");
    json.push('\n');
    json
}

/// Adds the validators to the 200 answer of every operation that can answer 304: the
/// `ETag` and `X-Cache` headers are set in one place for all such routes
/// (`routes::respond`), and documented here in one place too.
fn document_validators(spec: &mut Spec) {
    let header = |description: &str| HeaderBuilder::new().description(Some(description)).build();
    for item in spec.paths.paths.values_mut() {
        for operation in [&mut item.get, &mut item.post].into_iter().flatten() {
            let responses = &mut operation.responses.responses;
            if !responses.contains_key("304") {
                continue;
            }
            if let Some(RefOr::T(ok)) = responses.get_mut("200") {
                let etag = "The cache key of the answer, quoted; suffixed `.csv` for CSV";
                ok.headers.insert("etag".to_string(), header(etag));
                // A result read back was solved before: it has no cache status.
                let read_back = ["get_job_result", "get_result_by_input"];
                if !read_back.contains(&operation.operation_id.as_deref().unwrap_or_default()) {
                    let cache = "`hit` (from the cache) or `miss` (solved for this request)";
                    ok.headers.insert("x-cache".to_string(), header(cache));
                }
                for (name, description) in routes::PROVENANCE.iter().zip([
                    "The version of the model's numbers",
                    "The version of the software",
                    "The git commit the software was built from",
                    "SHA-256 of the canonical input (the cache key)",
                ]) {
                    ok.headers
                        .insert(name.as_str().to_string(), header(description));
                }
            }
        }
    }
}

/// The API keys, documented once for all operations (`access::admit` guards them all in
/// one place): an API key in `x-api-key` or as a bearer token, or none (anonymous callers
/// may do what the service's `--anonymous` allows); and the 401 and 403 answers of every
/// operation but the probes.
fn document_access(spec: &mut Spec) {
    use utoipa::openapi::security::{
        ApiKey, ApiKeyValue, Http, HttpAuthScheme, SecurityRequirement, SecurityScheme,
    };
    use utoipa::IntoResponses;
    let components = spec.components.get_or_insert_with(Default::default);
    components.add_security_scheme(
        "api_key",
        SecurityScheme::ApiKey(ApiKey::Header(ApiKeyValue::with_description(
            super::access::API_KEY_HEADER,
            "An API key (see the README's \"API keys\")",
        ))),
    );
    components.add_security_scheme(
        "bearer",
        SecurityScheme::Http(Http::new(HttpAuthScheme::Bearer)),
    );
    spec.security = Some(vec![
        SecurityRequirement::default(),
        SecurityRequirement::new("api_key", Vec::<String>::new()),
        SecurityRequirement::new("bearer", Vec::<String>::new()),
    ]);
    let refused = super::responses::Refused::responses();
    for item in spec.paths.paths.values_mut() {
        for operation in [&mut item.get, &mut item.post, &mut item.delete]
            .into_iter()
            .flatten()
        {
            // An API key names its caller: the owner's token is never required, even where
            // a caller without a key must send it (listing jobs).
            let owner = |p: &&mut path::Parameter| {
                p.name == routes::shared::OWNER_HEADER && p.parameter_in == ParameterIn::Header
            };
            for parameter in operation.parameters.iter_mut().flatten().filter(owner) {
                parameter.required = Required::False;
            }
            let probe = ["healthz", "readyz"];
            if probe.contains(&operation.operation_id.as_deref().unwrap_or_default()) {
                continue;
            }
            let responses = &mut operation.responses.responses;
            for (status, answer) in &refused {
                match (responses.get_mut(status), answer) {
                    (Some(RefOr::T(own)), RefOr::T(theirs)) => {
                        own.description = format!("{}; or {}", own.description, theirs.description);
                    }
                    (Some(_), _) => {}
                    (None, _) => {
                        responses.insert(status.clone(), answer.clone());
                    }
                }
            }
        }
    }
}

/// Gives every numeric field of every answer's schema its unit, as `x-unit`, from the unit
/// table the answer's declaration makes (`described!`): the spec and `meta.units` say the
/// same because one declaration makes both. A schema reached with two units (one shared by
/// fields in different units, such as a comparison of μ or of A) is left without.
fn document_units(spec: &mut Spec) {
    let json = serde_json::to_value(&*spec).expect("an OpenAPI document serializes");
    let mut units: BTreeMap<String, BTreeSet<&str>> = BTreeMap::new();
    for (_, _, unit, leaves) in unit_paths(&json) {
        for leaf in leaves {
            units.entry(leaf).or_default().insert(unit);
        }
    }
    for (leaf, units) in units {
        let (Some(unit), 1) = (units.first(), units.len()) else {
            continue;
        };
        let extensions = match schema_at(spec, &leaf) {
            Some(Schema::Object(object)) => &mut object.extensions,
            Some(Schema::Array(array)) => &mut array.extensions,
            _ => continue,
        };
        let extensions = extensions.get_or_insert_with(Extensions::default);
        extensions.insert("x-unit".to_string(), Value::from(*unit));
    }
}

/// Gives each quantity field of each kind's input the range of the model parameter it is
/// read as (`exclusiveMinimum: 0` for a radius, `minimum: 0` for a speed), from the code that
/// reads it ([`parameters_read`] of each kind's defaults): its numbers are in SI, so the
/// range holds for them (not for text with a unit, which only the service reads), and a
/// client generated from the spec does not send `"radius": 0`. A schema reached for two
/// parameters of different ranges is left as it is.
fn document_ranges(spec: &mut Spec) {
    let json = serde_json::to_value(&*spec).expect("an OpenAPI document serializes");
    let mut ranges: BTreeMap<String, Vec<Range>> = BTreeMap::new();
    for kind in registry::all() {
        let read = parameters_read(|| {
            // Read for the paths of its fields, not for a job.
            let _ = kind.validate(json!({}), &Limits::default());
        });
        let root = format!("/components/schemas/{}", kind.input_name());
        for (path, parameter) in read {
            for leaf in reach(&json, root.clone(), &segments(&path)) {
                let found = ranges.entry(leaf).or_default();
                let range = Range::of(parameter);
                if !found.contains(&range) {
                    found.push(range);
                }
            }
        }
    }
    let RefOr::T(Schema::OneOf(quantity)) = Quantity::schema() else {
        unreachable!("a quantity is a number or a text");
    };
    for (leaf, ranges) in ranges {
        let [range] = &ranges[..] else {
            continue;
        };
        // A field that may be absent, `oneOf` null or a quantity (a field reached through a
        // reference is the quantity's own schema: left), becomes `oneOf` null, a number in
        // its range or a text.
        let Some(Schema::OneOf(field)) = schema_at(spec, &leaf) else {
            continue;
        };
        let Some(at) = field.items.iter().position(
            |item| matches!(item, RefOr::Ref(r) if r.ref_location.ends_with("/Quantity")),
        ) else {
            continue;
        };
        if let RefOr::Ref(reference) = field.items.remove(at) {
            field.description = Some(reference.description).filter(|d| !d.is_empty());
        }
        for form in &quantity.items {
            let mut form = form.clone();
            if let RefOr::T(Schema::Object(number)) = &mut form {
                if number.schema_type == SchemaType::Type(Type::Number) {
                    range.bound(number);
                }
            }
            field.items.push(form);
        }
    }
}

/// The numbers a parameter allows, as JSON Schema says it: from 0 or above it, and below ½
/// for a Poisson ratio.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Range {
    zero: bool,
    below_half: bool,
}

impl Range {
    /// The range of `parameter`, found by asking its own check.
    fn of(parameter: Parameter) -> Range {
        let allows = |x: f64| parameter.check(x).is_ok();
        Range {
            zero: allows(0.0),
            below_half: !allows(0.5) && allows(0.25),
        }
    }

    /// Bounds the numbers of `number` to this range.
    fn bound(self, number: &mut Object) {
        if self.zero {
            number.minimum = Some(0.into());
        } else {
            number.exclusive_minimum = Some(0.into());
        }
        if self.below_half {
            number.exclusive_maximum = Some(0.5.into());
        }
    }
}

/// Each path of each kind's unit table, with its kind, its unit and the schemas of `json`
/// (the spec) it reaches.
type UnitPath = (&'static Registered, &'static str, &'static str, Vec<String>);

fn unit_paths(json: &Value) -> Vec<UnitPath> {
    let kinds = registry::all().iter();
    kinds
        .flat_map(|kind| {
            let root = format!("/components/schemas/{}", kind.output_name());
            kind.units().get().get().iter().map(move |(path, unit)| {
                let leaves = reach(json, root.clone(), &segments(path));
                (kind, path.as_str(), *unit, leaves)
            })
        })
        .collect()
}

/// The schema of `spec` at the JSON pointer `pointer` (one [`reach`] gives), for a change.
fn schema_at<'a>(spec: &'a mut Spec, pointer: &str) -> Option<&'a mut Schema> {
    let mut steps = pointer.trim_start_matches('/').split('/');
    let (Some("components"), Some("schemas"), Some(name)) =
        (steps.next(), steps.next(), steps.next())
    else {
        return None;
    };
    let mut at = spec.components.as_mut()?.schemas.get_mut(name)?;
    while let Some(step) = steps.next() {
        let RefOr::T(schema) = at else {
            return None;
        };
        at = match (step, schema) {
            ("properties", Schema::Object(o)) => o.properties.get_mut(steps.next()?)?,
            ("additionalProperties", Schema::Object(o)) => {
                match o.additional_properties.as_deref_mut()? {
                    AdditionalProperties::RefOr(value) => value,
                    AdditionalProperties::FreeForm(_) => return None,
                }
            }
            ("items", Schema::Array(a)) => match &mut a.items {
                ArrayItems::RefOrSchema(items) => items,
                ArrayItems::False => return None,
            },
            ("allOf", Schema::AllOf(c)) => c.items.get_mut(steps.next()?.parse::<usize>().ok()?)?,
            ("oneOf", Schema::OneOf(c)) => c.items.get_mut(steps.next()?.parse::<usize>().ok()?)?,
            ("anyOf", Schema::AnyOf(c)) => c.items.get_mut(steps.next()?.parse::<usize>().ok()?)?,
            _ => return None,
        };
    }
    match at {
        RefOr::T(schema) => Some(schema),
        RefOr::Ref(_) => None,
    }
}

/// The segments of a unit table's path: `boundary[].y` is `boundary`, `[]`, `y`.
fn segments(path: &str) -> Vec<&str> {
    path.split('.')
        .flat_map(|part| {
            let name = part.trim_end_matches("[]");
            let lists = (part.len() - name.len()) / 2;
            std::iter::once(name)
                .filter(|n| !n.is_empty())
                .chain(std::iter::repeat_n("[]", lists))
        })
        .collect()
}

/// The JSON pointers of the schemas `segments` reach from the schema at `at` (a pointer
/// into `spec`), through references, compositions (`allOf` of a flattened struct, `oneOf`
/// of an option), list items and map values.
fn reach(spec: &Value, at: String, segments: &[&str]) -> Vec<String> {
    let Some(node) = spec.pointer(&at) else {
        return Vec::new();
    };
    let Some((first, rest)) = segments.split_first() else {
        // A number's schema, not a reference to an object's (the path of one kind of row
        // followed into the other's).
        let number = node.get("$ref").is_none() && node.get("properties").is_none();
        return if number { vec![at] } else { Vec::new() };
    };
    if let Some(target) = node.get("$ref").and_then(Value::as_str) {
        return reach(spec, target.trim_start_matches('#').to_string(), segments);
    }
    let mut found = Vec::new();
    for composite in ["allOf", "oneOf", "anyOf"] {
        let parts = node.get(composite).and_then(Value::as_array);
        for i in 0..parts.map_or(0, Vec::len) {
            found.extend(reach(spec, format!("{at}/{composite}/{i}"), segments));
        }
    }
    let next = if *first == "[]" {
        node.get("items").map(|_| format!("{at}/items"))
    } else if node["properties"].get(*first).is_some() {
        Some(format!("{at}/properties/{first}"))
    } else if node["additionalProperties"].is_object() {
        Some(format!("{at}/additionalProperties"))
    } else {
        None
    };
    found.extend(next.into_iter().flat_map(|next| reach(spec, next, rest)));
    found
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An API key replaces the owner's token: the header is never required, and a string
    /// of its pattern where sent (schemathesis sent `null`, and none where a key named the
    /// caller).
    #[test]
    fn the_owners_token_is_an_optional_string_of_its_pattern() {
        let spec = serde_json::to_value(router_and_spec().1).unwrap();
        let mut found = 0;
        for (path, item) in spec["paths"].as_object().unwrap() {
            for (method, operation) in item.as_object().unwrap() {
                let parameters = operation["parameters"].as_array().into_iter().flatten();
                for parameter in parameters.filter(|p| p["name"] == "thirdbody-owner") {
                    let schema = json!({"type": "string", "pattern": "^[A-Za-z0-9._~-]{16,128}$"});
                    assert_eq!(parameter["required"], false, "{method} {path}");
                    assert_eq!(parameter["schema"], schema, "{method} {path}");
                    found += 1;
                }
            }
        }
        assert_eq!(found, 4, "listed, submitted, cancelled, deleted");
    }

    /// The range the spec gives each parameter read is the model's check, at its ends and
    /// beyond: a number the spec allows is one the check allows.
    #[test]
    fn every_range_is_its_parameters_check() {
        let mut read = Vec::new();
        for kind in registry::all() {
            read.extend(parameters_read(|| {
                let _ = kind.validate(json!({}), &Limits::default());
            }));
        }
        assert!(read.len() > 20, "{read:?}");
        for (path, parameter) in read {
            let mut number = Object::new();
            Range::of(parameter).bound(&mut number);
            let bound = |b: &Option<utoipa::Number>| {
                b.as_ref()
                    .map(|b| serde_json::to_value(b).unwrap().as_f64().unwrap())
            };
            let allows = |x: f64| {
                bound(&number.minimum).is_none_or(|m| x >= m)
                    && bound(&number.exclusive_minimum).is_none_or(|m| x > m)
                    && bound(&number.exclusive_maximum).is_none_or(|m| x < m)
            };
            for x in [
                -1.0, -1e-300, 0.0, 1e-300, 0.25, 0.4999, 0.5, 0.6, 1.0, 1e300,
            ] {
                assert_eq!(allows(x), parameter.check(x).is_ok(), "{path}: {x}");
            }
        }
    }

    /// Every numeric field of every kind's answer is a field of its schema, with its unit
    /// (but for fields whose schema serves several units); so a field's unit, its place
    /// in the answer and its place in the spec cannot part.
    #[test]
    fn every_unit_of_every_answer_is_in_the_spec_at_its_field() {
        let spec = serde_json::to_value(router_and_spec().1).unwrap();
        let mut shared = Vec::new();
        for (kind, path, unit, leaves) in unit_paths(&spec) {
            assert!(
                !leaves.is_empty(),
                "{}: {path} is not in the spec",
                kind.name()
            );
            for leaf in leaves {
                match spec.pointer(&leaf).unwrap().get("x-unit") {
                    Some(given) => assert_eq!(given, unit, "{}: {path}", kind.name()),
                    None => shared.push(leaf),
                }
            }
        }
        shared.sort();
        shared.dedup();
        // A comparison holds μ or A, in their units; an estimate is in its parameter's; a
        // row's operating point is a distance or a load.
        assert_eq!(
            shared,
            [
                "/components/schemas/Comparison/properties/fitted",
                "/components/schemas/Comparison/properties/measured",
                "/components/schemas/Comparison/properties/residual",
                "/components/schemas/Comparison/properties/uncertainty",
                "/components/schemas/Estimate/properties/bounds/items",
                "/components/schemas/Estimate/properties/interval_95/items",
                "/components/schemas/Estimate/properties/standard_error",
                "/components/schemas/Estimate/properties/value",
                "/components/schemas/ThreeBodySweepPoint/allOf/2/properties/operating/additionalProperties",
            ]
        );
        assert_eq!(
            segments("pressure.values[][]"),
            ["pressure", "values", "[]", "[]"]
        );
    }
}
