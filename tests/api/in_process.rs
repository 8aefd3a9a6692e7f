//! The router in process, without a socket: `app(state).oneshot(request)`.

use axum::body::Body;
use axum::http::{Request, StatusCode};
use serde_json::Value;
use thirdbody::http::app;
use tower::ServiceExt;

use crate::helpers::state;

async fn call(request: Request<Body>) -> (StatusCode, axum::http::HeaderMap, Vec<u8>) {
    let response = app(state(&[])).oneshot(request).await.unwrap();
    let (parts, body) = response.into_parts();
    let bytes = axum::body::to_bytes(body, usize::MAX)
        .await
        .unwrap()
        .to_vec();
    (parts.status, parts.headers, bytes)
}

#[tokio::test]
async fn a_rolling_job_is_solved_in_process() {
    let request = Request::post("/v1/rolling")
        .header("content-type", "application/json")
        .body(Body::from(r#"{"velocity": "0 nm/s"}"#))
        .unwrap();
    let (status, headers, body) = call(request).await;
    assert_eq!(status, StatusCode::OK);
    assert_eq!(headers["x-cache"], "miss");
    let body: Value = serde_json::from_slice(&body).unwrap();
    // docs/model.md §3, V = 0: A₀ = 102.333 nm².
    let area = body["contact_area"].as_f64().unwrap() * 1e18;
    assert!((area - 102.333).abs() < 5e-4, "{area}");
}

#[tokio::test]
async fn an_unknown_route_is_a_problem() {
    let (status, headers, body) = call(Request::get("/nope").body(Body::empty()).unwrap()).await;
    assert_eq!(status, StatusCode::NOT_FOUND);
    assert_eq!(headers["content-type"], "application/problem+json");
    let problem: Value = serde_json::from_slice(&body).unwrap();
    assert_eq!(problem["status"], 404);
}

#[tokio::test]
async fn the_spec_is_served_from_the_routes() {
    let (status, _, body) = call(Request::get("/openapi.json").body(Body::empty()).unwrap()).await;
    assert_eq!(status, StatusCode::OK);
    let spec: Value = serde_json::from_slice(&body).unwrap();
    let paths = spec["paths"].as_object().unwrap();
    for path in [
        "/v1/rolling",
        "/v1/three-body",
        "/v1/sweeps",
        "/v1/jobs",
        "/v1/jobs/{id}",
        "/v1/jobs/{id}/events",
        "/v1/figures/{n}",
        "/healthz",
        "/readyz",
        "/metrics",
    ] {
        assert!(paths.contains_key(path), "{path}");
    }
    // Every operation lists its statuses; every error is a problem.
    for (path, operations) in paths {
        for (method, operation) in operations.as_object().unwrap() {
            let responses = operation["responses"].as_object().unwrap();
            assert!(!responses.is_empty(), "{method} {path}");
            for (status, response) in responses {
                if status.starts_with('4') || status.starts_with('5') {
                    let content = &response["content"]["application/problem+json"];
                    assert!(content.is_object(), "{method} {path} {status}");
                }
            }
        }
    }
}
