//! Every error status from a real bad request, each an RFC 9457 problem.

use serde_json::{json, Value};

use std::time::Duration;

use crate::helpers::{
    assert_detail_says, long_sweep, problem, problem_type, spawn_app, spawn_app_adjusted,
    spawn_app_on_disk, within,
};

#[tokio::test]
async fn malformed_json_is_400() {
    let app = spawn_app(&[]).await;
    let response = app.post_json_text("/v1/rolling", "{\"radius\": ").await;
    let malformed = problem(response, 400).await;
    assert_eq!(malformed["type"], problem_type("malformed-json"));
}

#[tokio::test]
async fn a_body_that_is_not_json_is_415() {
    let app = spawn_app(&[]).await;
    let response = app.post_raw("/v1/sweeps", "text/plain", "{}".into()).await;
    let unsupported = problem(response, 415).await;
    assert_eq!(unsupported["type"], problem_type("unsupported-media-type"));
    assert_eq!(
        unsupported["detail"],
        "the body was sent as text/plain; send it as JSON, with Content-Type: application/json"
    );
}

#[tokio::test]
async fn a_body_over_the_limit_is_413() {
    let app = spawn_app(&["--body-limit", "1024"]).await;
    let padding = " ".repeat(2048);
    let response = app
        .post_json_text("/v1/rolling", &format!("{{{padding}}}"))
        .await;
    let too_large = problem(response, 413).await;
    assert_eq!(too_large["type"], problem_type("payload-too-large"));
    assert_eq!(
        too_large["detail"],
        "the body declares 2,050 bytes; this service takes at most 1,024 bytes (its --body-limit)"
    );
}

#[tokio::test]
async fn invalid_values_are_422_naming_each_field_its_value_and_range() {
    let app = spawn_app(&[]).await;
    let response = app
        .post("/v1/rolling", &json!({"radius": "3 GPa", "load": -1}))
        .await;
    let invalid = problem(response, 422).await;
    assert_eq!(invalid["type"], problem_type("invalid-input"));
    let errors = invalid["errors"].as_array().unwrap();
    assert_eq!(errors.len(), 2);
    assert_eq!(errors[0]["field"], "radius");
    assert_eq!(errors[0]["value"], "3 GPa");
    assert!(errors[0]["allowed"].as_str().unwrap().contains("a length"));
    assert_eq!(errors[1]["field"], "load");
    assert_eq!(errors[1]["value"], -1.0);

    let misshapen = app
        .post("/v1/sweeps", &json!({"vary": {"radius": "25 nm"}}))
        .await;
    let misshapen = problem(misshapen, 422).await;
    assert_eq!(misshapen["errors"][0]["field"], "vary.radius");

    let too_big = app
        .post(
            "/v1/jobs",
            &json!({"kind": "sweep", "input": {"vary": {
            "radius": vec![2.5e-8; 101], "load": vec![1e-9; 100]}}}),
        )
        .await;
    let too_big = problem(too_big, 422).await;
    assert_eq!(too_big["errors"][0]["field"], "vary");
}

/// Every echo of a huge value sent is cut to 100 characters (RELIABILITY.md): a key no
/// input has, a text where one of two series is given, a misspelt temperature difference,
/// a query's value; each problem a few kB, naming its field.
#[tokio::test]
async fn a_huge_value_is_never_echoed_whole() {
    let app = spawn_app(&[]).await;
    let huge = "x".repeat(300_000);
    let head = format!("{}…", "x".repeat(100));
    let wlf = json!({"reference_temperature": "25 °C", "c1": 17.44, "c2": format!("{huge} °C")});
    for (body, field) in [
        // The key is the path of its error.
        (json!({&huge: 1}), head.clone()),
        (
            json!({"layer": {"prony": [{"time": 1, "modulus": 1e9}], "prony_csv": &huge}}),
            "layer.prony_csv".to_string(),
        ),
        (
            json!({"layer": {"wlf": wlf, "temperature": "30 °C"}}),
            "layer.wlf.c2".to_string(),
        ),
    ] {
        let response = app.post("/v1/rolling", &body).await;
        let text = response.text().await.unwrap();
        assert!(text.len() < 4000, "{field}: {} bytes", text.len());
        let problem: Value = serde_json::from_str(&text).unwrap();
        let error = &problem["errors"][0];
        assert_eq!(error["field"], field.as_str(), "{problem}");
        assert!(
            error["message"].as_str().unwrap().contains(&head),
            "{problem}"
        );
    }
    // A query's value, echoed by the history's own checks.
    let path = format!("/v1/jobs?tenant={}", &huge[..60_000]);
    let text = app.get(&path).await.text().await.unwrap();
    assert!(text.len() < 4000, "tenant: {} bytes", text.len());
    let problem: Value = serde_json::from_str(&text).unwrap();
    assert_eq!(problem["errors"][0]["field"], "tenant", "{problem}");
    assert_eq!(problem["errors"][0]["value"], head.as_str(), "{problem}");
}

#[tokio::test]
async fn unknown_routes_jobs_and_figures_are_404_and_wrong_methods_405() {
    let app = spawn_app(&[]).await;
    for path in [
        "/v2/rolling",
        "/v1/jobs/not-a-uuid",
        "/v1/figures/10",
        "/v1/figures/six",
    ] {
        let not_found = problem(app.get(path).await, 404).await;
        assert_eq!(not_found["type"], problem_type("not-found"), "{path}");
    }
    // A job id no run of the service gave out: never issued, not "interrupted".
    for path in [
        "/v1/jobs/00000000-0000-4000-8000-000000000000",
        "/v1/jobs/00000000-0000-4000-8000-000000000000/events",
    ] {
        let unknown = problem(app.get(path).await, 404).await;
        assert_eq!(unknown["type"], problem_type("not-found"), "{path}");
        assert_detail_says(&unknown, "no run of this service issued");
    }
    // One that an earlier run gave out: its unfinished jobs were interrupted by its
    // shutdown (here, another service in this test, standing for the earlier run).
    let job = json!({"kind": "rolling", "input": {}});
    let earlier = spawn_app(&[]).await;
    let location = earlier.submit(&job).await;
    for path in [location.clone(), format!("{location}/events")] {
        let gone = problem(app.get(&path).await, 410).await;
        assert_eq!(gone["type"], problem_type("interrupted"), "{path}");
    }
    // And one this run gave out, then deleted.
    let location = app.submit(&job).await;
    app.delete(&location).await;
    let deleted = problem(app.get(&location).await, 404).await;
    assert_detail_says(&deleted, "deleted, or it expired");
    let response = app.get("/v1/rolling").await;
    assert_eq!(response.headers()["allow"], "POST");
    let not_allowed = problem(response, 405).await;
    assert_eq!(not_allowed["type"], "about:blank");
    assert_eq!(
        not_allowed["detail"],
        "this route does not take this method; the Allow header names those it takes"
    );
}

#[tokio::test]
async fn a_full_pool_is_429_at_once_and_a_full_job_queue_too() {
    let app = spawn_app_on_disk(&[
        "--pool-size=1",
        "--max-sweep-points=1000000",
        "--max-queued-jobs=1",
    ])
    .await;
    // One long job takes the only solver thread...
    let running = app.submit_running(&long_sweep(100)).await;
    // ...so a synchronous solve is refused, not queued.
    let response = app.post("/v1/rolling", &json!({"radius": "40 nm"})).await;
    assert_eq!(response.headers()["retry-after"], "1");
    let refused = problem(response, 429).await;
    assert_eq!(refused["type"], problem_type("overloaded"));
    // A cached answer needs no thread: none is cached yet, so that is the same 429 above.
    // One more job may wait; the next is refused.
    let queued = app.submit(&long_sweep(99)).await;
    let response = app.post("/v1/jobs", &long_sweep(98)).await;
    problem(response, 429).await;
    assert_eq!(
        app.metric("thirdbody_rejections_total", &[("reason", "overloaded")])
            .await,
        2.0
    );
    assert_eq!(app.metric("thirdbody_jobs_queued", &[]).await, 1.0);
    assert_eq!(app.metric("thirdbody_jobs_running", &[]).await, 1.0);
    for job in [queued, running] {
        app.delete(&job).await;
    }
}

#[tokio::test]
async fn a_draining_service_is_503_for_new_work_and_readiness() {
    let mut app = spawn_app_adjusted(&[], |c| c.drain_delay = Duration::from_secs(600)).await;
    assert_eq!(app.get("/readyz").await.status(), 200);
    // Seen and cached before the drain: refused all the same, not answered from the cache.
    assert_eq!(app.post("/v1/rolling", &json!({})).await.status(), 200);
    app.shut_down();
    within(async {
        while app.get("/readyz").await.status() != 503 {
            tokio::task::yield_now().await;
        }
    })
    .await;
    let response = app.get("/readyz").await;
    assert!(response.headers().contains_key("retry-after"));
    problem(response, 503).await;
    for (path, body) in [
        ("/v1/rolling", json!({})),
        ("/v1/jobs", json!({"kind": "rolling"})),
    ] {
        let refused = problem(app.post(path, &body).await, 503).await;
        assert_eq!(refused["type"], problem_type("draining"));
    }
    // Still alive, and still answering what it has.
    assert_eq!(app.get("/healthz").await.status(), 200);
}

#[tokio::test]
async fn a_solve_past_its_deadline_is_504() {
    let app = spawn_app(&["--solve-deadline", "1ms"]).await;
    let input = json!({"vary": {"radius": vec!["25 nm"; 100], "load": vec!["1 nN"; 100]}});
    let response = app.post("/v1/sweeps", &input).await;
    let late = problem(response, 504).await;
    assert_eq!(late["type"], problem_type("deadline-exceeded"));
    let stopped = app.solves(&[("outcome", "deadline_exceeded")]).await;
    assert_eq!(stopped, 1.0);
}
