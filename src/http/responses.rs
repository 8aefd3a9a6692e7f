//! The error responses of the routes, declared once per set for their `responses(...)`:
//! each a status, a description starting with the problem type's name, and whether the
//! answer carries `Retry-After`.

use std::collections::BTreeMap;

use utoipa::openapi::header::HeaderBuilder;
use utoipa::openapi::response::ResponseBuilder;
use utoipa::openapi::schema::{AllOfBuilder, AnyOfBuilder, ObjectBuilder, Type};
use utoipa::openapi::{ContentBuilder, Ref, RefOr, Response};
use utoipa::IntoResponses;

use super::error::PROBLEM_JSON;
use crate::job::registry::AnyOutput;

/// A response whose body is a [`Problem`].
fn problem(description: &str, retry_after: bool) -> RefOr<Response> {
    let content = ContentBuilder::new()
        .schema(Some(Ref::from_schema_name("Problem")))
        .build();
    let mut response = ResponseBuilder::new()
        .description(description)
        .content(PROBLEM_JSON, content);
    if retry_after {
        let header = HeaderBuilder::new()
            .description(Some("Seconds to wait before trying again"))
            .build();
        response = response.header("retry-after", header);
    }
    response.build().into()
}

/// Declares a set of error responses for the `responses(...)` of routes: each entry is a
/// status, a description (starting with the problem type's name), and whether the answer
/// carries `Retry-After`.
macro_rules! problems {
    ($(#[$doc:meta])* $name:ident { $(($status:literal, $description:expr, $retry:literal)),+ $(,)? }) => {
        $(#[$doc])*
        pub enum $name {}

        impl IntoResponses for $name {
            fn responses() -> BTreeMap<String, RefOr<Response>> {
                BTreeMap::from([$(($status.to_string(), problem($description, $retry))),+])
            }
        }
    };
}

const DRAINING: &str = "draining: the service is shutting down";

const INVALID_INPUT: &str = "invalid-input: fields of the wrong shape or out of range, each \
    named in `errors` with its value and the allowed range";

problems!(
    /// The history's store failing a read (a fleet's Redis unreachable, the database).
    HistoryUnreadable {
        (500, "internal: a stored result cannot be read back", false),
        (503, "about:blank: the history cannot be read now (the detail says why)", false),
    }
);

problems!(
    /// A job with an owner, asked to change by a request that does not name it.
    NotTheOwner {
        (403, "forbidden: the job has an owner (an API key's tenant, or a thirdbody-owner \
            token), and only its owner or an admin key may cancel or delete it", false),
    }
);

problems!(
    /// Another tenant's jobs asked for by a key that is not an admin's.
    NotAnAdmin {
        (403, "forbidden: only an admin's API key lists another tenant's jobs", false),
    }
);

problems!(
    /// The answers of the access rules, which every operation but the probes may give.
    Refused {
        (401, "unauthorized: this needs an API key (anonymous callers may not do it here), \
            or the key sent is not accepted (unknown, expired); with WWW-Authenticate", false),
        (403, "forbidden: the API key sent lacks the scope this needs (submit, read, \
            metrics, or admin)", false),
    }
);

problems!(
    /// Errors of a request's query or headers.
    InvalidParameters {
        (422, INVALID_INPUT, false),
    }
);

problems!(
    /// Errors of a request body.
    BadBody {
        (400, "malformed-json: the body is not JSON", false),
        (413, "payload-too-large: the body is larger than the body limit", false),
        (415, "unsupported-media-type: the body is not application/json", false),
        (422, &format!("{INVALID_INPUT}; solve-failed: valid values the model cannot solve; or \
            out-of-domain: values for which an assumption of the model fails (the detail names \
            it, with its numbers)"), false),
    }
);

/// The 200 of an answer read back (a job's result, an input's answer): its JSON, its CSV or
/// its picture.
pub enum ReadBack {}

impl IntoResponses for ReadBack {
    fn responses() -> BTreeMap<String, RefOr<Response>> {
        let text = || {
            ContentBuilder::new()
                .schema(Some(ObjectBuilder::new().schema_type(Type::String)))
                .build()
        };
        // Inline: one of the kinds' outputs, each a component of its kind's endpoint.
        let json = ContentBuilder::new()
            .schema(Some(<AnyOutput as utoipa::PartialSchema>::schema()))
            .build();
        let response = ResponseBuilder::new()
            .description("The answer, or its picture")
            .content("application/json", json)
            .content("text/csv", text())
            .content("image/svg+xml", text())
            .build();
        BTreeMap::from([("200".to_string(), response.into())])
    }
}

/// The 422 of `POST /v1/checks`: checks that failed, or a checks document that is not valid.
/// Listed after [`BadBody`] in the route's responses, whose 422 it replaces (a later entry
/// for a status wins).
pub enum ChecksFailed {}

impl IntoResponses for ChecksFailed {
    fn responses() -> BTreeMap<String, RefOr<Response>> {
        let report = AllOfBuilder::new()
            .item(Ref::from_schema_name("Problem"))
            .item(Ref::from_schema_name("Report"));
        let problem = AnyOfBuilder::new()
            .item(report)
            .item(Ref::from_schema_name("Problem"));
        let junit = ObjectBuilder::new().schema_type(Type::String);
        let response = ResponseBuilder::new()
            .description(format!(
                "checks-failed: one or more checks failed: the detail names them, and the \
                 report's fields (`passed`, `summary`, `checks`, as in the 200 answer) are \
                 members of the problem (with `Accept: application/xml`, the body is the \
                 JUnit report); or {INVALID_INPUT}"
            ))
            .content(
                PROBLEM_JSON,
                ContentBuilder::new().schema(Some(problem)).build(),
            )
            .content(
                "application/xml",
                ContentBuilder::new().schema(Some(junit)).build(),
            );
        BTreeMap::from([("422".to_string(), response.build().into())])
    }
}

problems!(
    /// Refusals of new work.
    Busy {
        (429, "overloaded: every solver thread is busy (or the job queue is full); no queue. \
            Or quota-exceeded: the caller's points this minute (or, for a job, its tenant's \
            unfinished jobs or the bytes its kept answers hold) are at its quota", true),
        (503, DRAINING, true),
    }
);

problems!(
    /// The service is shutting down.
    Draining { (503, DRAINING, true) }
);

problems!(
    /// Failures of a solve.
    SolveErrors {
        (500, "internal: a fault of the service", false),
        (504, "deadline-exceeded: the solve ran past the solve deadline", false),
    }
);

problems!(
    /// The client accepts no form the resource offers.
    NotAcceptable {
        (406, "not-acceptable: the Accept header names no form of the answer this \
            resource offers", false),
    }
);

problems!(
    /// An unknown resource.
    NotFound { (404, "not-found: no such job (or it expired), or figure", false) }
);

/// `If-None-Match` named the current ETag: 304.
pub enum NotModified {}

impl IntoResponses for NotModified {
    fn responses() -> BTreeMap<String, RefOr<Response>> {
        let response = ResponseBuilder::new()
            .description("Not modified: If-None-Match names the answer's ETag; no body")
            .build();
        BTreeMap::from([("304".to_string(), response.into())])
    }
}

problems!(
    /// A job's result that is not there.
    Unfinished {
        (409, "not-ready: the job is queued or running (retry after the seconds given); or \
            cancelled: it was cancelled and has no result", true),
    }
);

problems!(
    /// The problem a failed job ended with.
    JobFailure {
        (422, "invalid-input, solve-failed or out-of-domain: the job's values could not be \
            answered", false),
        (500, "internal: a fault of the service", false),
        (504, "deadline-exceeded: the job ran past the job deadline", false),
    }
);

problems!(
    /// A job the service accepted but could not finish.
    Gone {
        (410, "interrupted: the service stopped before the job finished (its id names an \
            earlier run of the service), or the fleet's job store (Redis) restarted without \
            its data after accepting it; submit it again", false),
    }
);

problems!(
    /// Every event stream the service follows at once is open.
    TooManyStreams {
        (429, "too-many-streams: every event stream this service follows at once is open \
            (an eighth of --max-connections); poll the job instead", true),
    }
);
