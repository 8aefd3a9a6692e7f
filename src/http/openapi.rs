//! The OpenAPI description, generated from the same route registration as the router (so it
//! cannot drift from what is served).

use axum::Router;
use utoipa::openapi::header::HeaderBuilder;
use utoipa::openapi::{OpenApi as Spec, RefOr};
use utoipa::OpenApi;
use utoipa_axum::router::OpenApiRouter;

use super::error::Problem;
use super::{routes, AppState};

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
                if operation.operation_id.as_deref() != Some("get_job_result") {
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
