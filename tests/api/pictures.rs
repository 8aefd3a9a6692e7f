//! Pictures over HTTP: `Accept: image/svg+xml` (or `?format=svg` for links) on every route
//! that answers, finished jobs included; an unknown form is 406; the dashboard at `/`.

use serde_json::{json, Value};

use crate::helpers::{problem, problem_type, spawn_app};

fn is_svg(content_type: &str, body: &str) {
    assert_eq!(content_type, "image/svg+xml");
    assert!(
        body.starts_with("<svg xmlns=\"http://www.w3.org/2000/svg\""),
        "{body:.80}"
    );
    assert!(body.ends_with("</svg>"));
}

async fn svg(response: reqwest::Response) -> (String, String) {
    assert_eq!(response.status(), 200);
    let content_type = response.headers()["content-type"]
        .to_str()
        .unwrap()
        .to_string();
    let etag = response.headers()["etag"].to_str().unwrap().to_string();
    let body = response.text().await.unwrap();
    is_svg(&content_type, &body);
    (etag, body)
}

#[tokio::test]
async fn every_answer_is_a_picture_when_asked_by_accept_or_by_query() {
    let app = spawn_app(&[]).await;
    let accept = [("accept", "image/svg+xml")];
    let body = json!({"load": "1.1 nN"});
    let (etag, picture) = svg(app.post_with("/v1/rolling", &accept, &body).await).await;
    assert!(etag.ends_with(".svg\""), "{etag}");
    assert!(picture.contains("Contact region, R = 25 nm, P = 1.1 nN"));
    let (_, by_query) = svg(app.post_with("/v1/rolling?format=svg", &[], &body).await).await;
    assert_eq!(by_query, picture);
    svg(app.get("/v1/figures/6?format=svg").await).await;
    let three_body = json!({"operating": {"total_load": "1 mN"}});
    svg(app.post_with("/v1/three-body", &accept, &three_body).await).await;
    let sweep = json!({"vary": {"load": ["1 nN", "2 nN"]}});
    svg(app.post_with("/v1/sweeps", &accept, &sweep).await).await;

    // A finished job's result, too.
    let location = app.submit(&json!({"kind": "sweep", "input": sweep})).await;
    app.wait_for_job(&location, |job| job["status"] == "succeeded")
        .await;
    let result = format!("{location}/result");
    let (_, job_picture) = svg(app.get_with(&result, &accept).await).await;
    assert!(job_picture.contains("Sweep: friction coefficient against load"));

    // A form the service does not draw.
    let png = app
        .get_with("/v1/figures/3", &[("accept", "image/png")])
        .await;
    let refused = problem(png, 406).await;
    assert_eq!(refused["type"], problem_type("not-acceptable"));
    let unknown = problem(app.get("/v1/figures/3?format=png").await, 406).await;
    assert!(unknown["detail"]
        .as_str()
        .unwrap()
        .contains("json, csv and svg"));
}

#[tokio::test]
async fn the_dashboard_is_served_with_its_assets_under_a_strict_policy() {
    let app = spawn_app(&[]).await;
    for (path, content_type) in [
        ("/", "text/html; charset=utf-8"),
        ("/assets/app.js", "text/javascript; charset=utf-8"),
        ("/assets/plot.js", "text/javascript; charset=utf-8"),
        ("/assets/app.css", "text/css; charset=utf-8"),
        ("/assets/icon.svg", "image/svg+xml"),
    ] {
        let response = app.get(path).await;
        assert_eq!(response.status(), 200, "{path}");
        let headers = response.headers();
        assert_eq!(headers["content-type"], content_type, "{path}");
        assert_eq!(
            headers["content-security-policy"], "default-src 'self'; frame-ancestors 'self'",
            "{path}: no other site frames it"
        );
    }
    let page = app.get("/").await.text().await.unwrap();
    for form in ["form-rolling", "form-three-body", "form-sweep"] {
        assert!(page.contains(&format!("id=\"{form}\"")), "{form}");
    }
    // Nothing from elsewhere, nothing inline.
    assert!(!page.contains("http://") && !page.contains("https://"));
    assert!(!page.contains("<script>") && !page.contains("style="));
}

/// Swagger's "Try it out" starts from each request body's example: every one is a job the
/// service accepts, with values in units.
#[tokio::test]
async fn every_request_body_example_in_the_spec_is_accepted() {
    let app = spawn_app(&[]).await;
    let spec: serde_json::Value =
        serde_json::from_str(&thirdbody::http::openapi::spec_json()).unwrap();
    let mut tried = 0;
    for (path, operations) in spec["paths"].as_object().unwrap() {
        let Some(body) = operations["post"].get("requestBody") else {
            continue;
        };
        let reference = body["content"]["application/json"]["schema"]["$ref"]
            .as_str()
            .unwrap();
        let name = reference.rsplit('/').next().unwrap();
        let example = &spec["components"]["schemas"][name]["example"];
        assert!(example.is_object(), "{name} has no example");
        let response = app.post(path, example).await;
        assert!(
            response.status().is_success(),
            "{path}: {}",
            response.status()
        );
        tried += 1;
        if path != "/v1/checks" {
            assert!(
                example.to_string().contains(" nm"),
                "{name}'s example has unit strings"
            );
        }
    }
    assert_eq!(tried, 6);
}

/// The spec says what the service accepts of a quantity sent as a number: each range it
/// gives a field (`exclusiveMinimum` 0 for a radius, `minimum` 0 for a speed, below ½ for a
/// Poisson ratio) is the service's own at its ends, and a text not starting with a number
/// (`""`, `"twelve"`) is outside the spec as the service refuses it. Schemathesis sent
/// `"radius": 0`, which the spec allowed and the service refused.
#[tokio::test]
async fn the_spec_s_ranges_of_quantities_are_the_service_s() {
    let app = spawn_app(&[]).await;
    let spec: Value = serde_json::from_str(&thirdbody::http::openapi::spec_json()).unwrap();
    let schemas = &spec["components"]["schemas"];
    let field = |schema: &str, name: &str| schemas[schema]["properties"][name].clone();
    // The field's number: `oneOf` null, a number in its range, or a text.
    let ranged = |schema: &str, name: &str| {
        let field = field(schema, name);
        let number = field["oneOf"]
            .as_array()
            .unwrap()
            .iter()
            .find(|form| form["type"] == "number")
            .unwrap()
            .clone();
        ["minimum", "exclusiveMinimum", "exclusiveMaximum"]
            .map(|keyword| number.get(keyword).and_then(Value::as_f64))
    };
    assert_eq!(ranged("RollingInput", "radius"), [None, Some(0.0), None]);
    assert_eq!(ranged("RollingInput", "velocity"), [Some(0.0), None, None]);
    assert_eq!(
        ranged("LayerInput", "poisson_ratio"),
        [Some(0.0), None, Some(0.5)]
    );
    assert_eq!(
        ranged("OperatingInput", "separation"),
        [Some(0.0), None, None]
    );
    let pattern = schemas["Quantity"]["oneOf"][1]["pattern"].as_str().unwrap();
    assert_eq!(pattern, r"^\s*[+-]?(\d|\.\d)");
    // At the ends of the ranges, the service agrees with the spec.
    for (input, accepted) in [
        (json!({"radius": 0}), false),
        (json!({"radius": 2.5e-8}), true),
        (json!({"velocity": 0}), true),
        (json!({"velocity": -1e-9}), false),
        (json!({"layer": {"poisson_ratio": 0}}), true),
        (json!({"layer": {"poisson_ratio": 0.5}}), false),
        (json!({"layer": {"thickness": 0}}), false),
        (json!({"radius": ""}), false),
        (json!({"radius": "twelve nm"}), false),
    ] {
        let status = app.post("/v1/rolling", &input).await.status().as_u16();
        assert_eq!(status == 200, accepted, "{input}: {status}");
    }
}
