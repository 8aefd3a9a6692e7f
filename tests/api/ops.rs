//! Operations: probes, metrics, request ids, CORS, the spec, graceful drain.

use reqwest::Method;
use serde_json::{json, Value};
use thirdbody::http::openapi;

use crate::helpers::{long_sweep, spawn_app, spawn_app_on_disk, within, Events};

#[tokio::test]
async fn probes_answer_and_requests_carry_an_id() {
    let app = spawn_app(&[]).await;
    let health = app.get("/healthz").await;
    assert_eq!(health.status(), 200);
    assert!(!health.headers()["x-request-id"].is_empty());
    assert_eq!(
        health.json::<Value>().await.unwrap(),
        json!({"status": "ok"})
    );
    assert_eq!(app.get("/readyz").await.status(), 200);
    assert_eq!(app.request_id_for("abc-123").await, "abc-123");
}

#[tokio::test]
async fn metrics_count_requests_by_route_and_status() {
    let app = spawn_app(&[]).await;
    app.post("/v1/rolling", &json!({})).await;
    app.get("/v1/figures/12").await;
    app.get("/nowhere").await;
    for (route, status) in [
        ("/v1/rolling", "200"),
        ("/v1/figures/{n}", "404"),
        ("unmatched", "404"),
    ] {
        let labels = [
            (
                "method",
                if route == "/v1/rolling" {
                    "POST"
                } else {
                    "GET"
                },
            ),
            ("route", route),
            ("status", status),
        ];
        assert_eq!(
            app.metric("http_requests_total", &labels).await,
            1.0,
            "{route}"
        );
    }
    let latency = app
        .metric(
            "http_request_duration_seconds_count",
            &[("route", "/v1/rolling")],
        )
        .await;
    assert_eq!(latency, 1.0);
}

#[tokio::test]
async fn a_dashboard_on_an_allowed_origin_may_post_and_read_the_location() {
    let app = spawn_app(&["--cors-origin", "https://dashboard.example"]).await;
    let preflight = app
        .send(
            Method::OPTIONS,
            "/v1/jobs",
            &[
                ("origin", "https://dashboard.example"),
                ("access-control-request-method", "POST"),
                ("access-control-request-headers", "content-type"),
            ],
            None,
        )
        .await;
    assert_eq!(preflight.status(), 200);
    let h = preflight.headers();
    assert_eq!(
        h["access-control-allow-origin"],
        "https://dashboard.example"
    );
    assert!(h["access-control-allow-methods"]
        .to_str()
        .unwrap()
        .contains("POST"));
    assert!(h["access-control-allow-headers"]
        .to_str()
        .unwrap()
        .contains("content-type"));

    let dashboard = [("origin", "https://dashboard.example")];
    let posted = app
        .post_with("/v1/jobs", &dashboard, &json!({"kind": "rolling"}))
        .await;
    assert_eq!(posted.status(), 202);
    let exposed = posted.headers()["access-control-expose-headers"]
        .to_str()
        .unwrap()
        .to_ascii_lowercase();
    for name in ["location", "etag", "x-cache", "retry-after"] {
        assert!(exposed.contains(name), "{exposed}");
    }

    let stranger = app
        .get_with("/healthz", &[("origin", "https://elsewhere.example")])
        .await;
    assert!(!stranger
        .headers()
        .contains_key("access-control-allow-origin"));
}

#[tokio::test]
async fn the_served_spec_is_the_committed_one_and_the_docs_are_served() {
    let committed = include_str!("../../openapi/openapi.json");
    assert!(
        openapi::spec_json() == committed,
        "openapi/openapi.json is out of date: run `cargo run -- openapi > openapi/openapi.json`"
    );
    let app = spawn_app(&[]).await;
    let served: Value = app.get("/openapi.json").await.json().await.unwrap();
    assert_eq!(served, serde_json::from_str::<Value>(committed).unwrap());
    let docs = app.get("/docs/").await;
    assert_eq!(docs.status(), 200);
    assert!(docs.text().await.unwrap().contains("swagger-ui"));
}

#[tokio::test]
async fn on_shutdown_a_running_job_finishes_before_the_server_exits() {
    let mut app = spawn_app_on_disk(&[
        "--pool-size=1",
        "--max-sweep-points=1000000",
        "--shutdown-timeout=10m",
    ])
    .await;
    // The job followed waits behind a blocker until it is seen queued, so it is sure to
    // be running when the shutdown starts.
    let blocker = app.submit(&long_sweep(100)).await;
    let location = app.submit(&long_sweep(25)).await;
    let mut events = Events::new(app.get(&format!("{location}/events")).await);
    assert_eq!(events.next().await.unwrap().1["status"], "queued");
    app.delete(&blocker).await;
    loop {
        let (_, job) = events.next().await.unwrap();
        if job["status"] == "running" {
            break;
        }
        assert_eq!(job["status"], "queued");
    }
    app.shut_down();
    let (_, completion) = events.until_completion().await;
    assert_eq!(completion["status"], "succeeded");
    assert_eq!(completion["progress"]["done"], 13 * 13 * 13);
    within(&mut app.server).await.unwrap().unwrap();
    assert!(app.client.get(app.url("/healthz")).send().await.is_err());
}
