//! The OpenAPI description, generated from the same route registration as the router (so it
//! cannot drift from what is served), with the error responses declared once per kind.

use std::collections::BTreeMap;

use utoipa::openapi::header::HeaderBuilder;
use utoipa::openapi::response::ResponseBuilder;
use utoipa::openapi::{ContentBuilder, Ref, RefOr, Response};
use utoipa::{IntoResponses, OpenApi};
use utoipa_axum::router::OpenApiRouter;
use utoipa_axum::routes;

use super::error::{Problem, PROBLEM_JSON};
use super::routes::{figures, jobs, ops, rolling, sweeps, three_body};
use super::AppState;

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

/// The API's routes with their OpenAPI operations.
pub fn router() -> OpenApiRouter<AppState> {
    OpenApiRouter::with_openapi(ApiDoc::openapi())
        .routes(routes!(rolling::solve))
        .routes(routes!(three_body::solve))
        .routes(routes!(sweeps::solve))
        .routes(routes!(jobs::submit))
        .routes(routes!(jobs::status, jobs::cancel))
        .routes(routes!(jobs::events))
        .routes(routes!(figures::figure))
        .routes(routes!(ops::healthz))
        .routes(routes!(ops::readyz))
        .routes(routes!(ops::metrics))
}

/// The OpenAPI document of the service, as committed in `openapi/openapi.json`.
pub fn spec_json() -> String {
    let spec = router().split_for_parts().1;
    let mut json = spec
        .to_pretty_json()
        .expect("an OpenAPI document serializes");
    json.push('\n');
    json
}

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

fn responses(list: &[(u16, &str, bool)]) -> BTreeMap<String, RefOr<Response>> {
    list.iter()
        .map(|&(status, description, retry)| (status.to_string(), problem(description, retry)))
        .collect()
}

/// Errors of a request body: 400, 413, 415, 422.
pub enum BadBody {}

impl IntoResponses for BadBody {
    fn responses() -> BTreeMap<String, RefOr<Response>> {
        responses(&[
            (400, "malformed-json: the body is not JSON", false),
            (
                413,
                "payload-too-large: the body is larger than the body limit",
                false,
            ),
            (
                415,
                "unsupported-media-type: the body is not application/json",
                false,
            ),
            (
                422,
                "invalid-input: fields of the wrong shape or out of range, each named in \
                 `errors` with its value and the allowed range; or solve-failed: valid values \
                 the model cannot solve",
                false,
            ),
        ])
    }
}

/// Refusals of new work: 429, 503.
pub enum Busy {}

impl IntoResponses for Busy {
    fn responses() -> BTreeMap<String, RefOr<Response>> {
        let mut list = Draining::responses();
        list.extend(responses(&[(
            429,
            "overloaded: every solver thread is busy (or the job queue is full); no queue",
            true,
        )]));
        list
    }
}

/// The service is shutting down: 503.
pub enum Draining {}

impl IntoResponses for Draining {
    fn responses() -> BTreeMap<String, RefOr<Response>> {
        responses(&[(503, "draining: the service is shutting down", true)])
    }
}

/// Failures of a solve: 500, 504.
pub enum SolveErrors {}

impl IntoResponses for SolveErrors {
    fn responses() -> BTreeMap<String, RefOr<Response>> {
        responses(&[
            (500, "internal: a fault of the service", false),
            (
                504,
                "deadline-exceeded: the solve ran past the solve deadline",
                false,
            ),
        ])
    }
}

/// An unknown resource: 404.
pub enum NotFound {}

impl IntoResponses for NotFound {
    fn responses() -> BTreeMap<String, RefOr<Response>> {
        responses(&[(
            404,
            "not-found: no such job (or it expired), or figure",
            false,
        )])
    }
}

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
