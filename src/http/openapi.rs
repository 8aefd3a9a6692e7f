//! The OpenAPI description, generated from the same route registration as the router (so it
//! cannot drift from what is served), with the error responses declared once per kind.

use std::collections::BTreeMap;

use axum::Router;

use utoipa::openapi::header::HeaderBuilder;
use utoipa::openapi::response::ResponseBuilder;
use utoipa::openapi::{ContentBuilder, OpenApi as Spec, Ref, RefOr, Response};
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

/// The API's routes with their OpenAPI operations. A synchronous endpoint of a new job kind
/// is one more `.routes(routes!(...))` line here, over a handler like `rolling::solve`.
fn router() -> OpenApiRouter<AppState> {
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

/// The router and the OpenAPI document it serves.
pub fn router_and_spec() -> (Router<AppState>, Spec) {
    let (router, mut spec) = router().split_for_parts();
    document_validators(&mut spec);
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
                let cache = "`hit` (from the cache) or `miss` (solved for this request)";
                ok.headers.insert("x-cache".to_string(), header(cache));
            }
        }
    }
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

problems!(
    /// Errors of a request body.
    BadBody {
        (400, "malformed-json: the body is not JSON", false),
        (413, "payload-too-large: the body is larger than the body limit", false),
        (415, "unsupported-media-type: the body is not application/json", false),
        (422, "invalid-input: fields of the wrong shape or out of range, each named in \
            `errors` with its value and the allowed range; or solve-failed: valid values \
            the model cannot solve", false),
    }
);

problems!(
    /// Refusals of new work.
    Busy {
        (429, "overloaded: every solver thread is busy (or the job queue is full); no queue",
            true),
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
