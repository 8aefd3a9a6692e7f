//! The synchronous endpoints: answers equal the engine's, the cache and its validators.

use futures_util::future::join_all;
use serde_json::{json, Value};
use thirdbody::engine;
use thirdbody::job::{Control, FigureJob, Job, Limits};

use crate::helpers::spawn_app;

/// The engine's answer to `job`, as JSON text read back the way the client reads the
/// service's (serde_json's default float parsing may differ from the exact value in the
/// last bit: both sides go through it).
pub fn engine_answer(job: Job) -> Value {
    let output = engine::run(&job, &Control::default()).unwrap();
    serde_json::from_str(&serde_json::to_string(&output).unwrap()).unwrap()
}

#[tokio::test]
async fn rolling_answers_the_model_section_3_reference_row() {
    let app = spawn_app(&[]).await;
    let response = app.post("/v1/rolling", &json!({})).await;
    assert_eq!(response.status(), 200);
    assert_eq!(response.headers()["x-cache"], "miss");
    let etag = response.headers()["etag"].to_str().unwrap().to_string();
    let body: Value = response.json().await.unwrap();
    // docs/model.md §3, R = 25 nm, P = 1 nN, V = 4 nm/s: A = 85.234 nm², μ = 0.09470.
    let area = body["contact_area"].as_f64().unwrap() * 1e18;
    assert!((area - 85.234).abs() < 5e-4, "{area}");
    let mu = body["friction_coefficient"].as_f64().unwrap();
    assert!((mu - 0.09470).abs() < 5e-6, "{mu}");
    assert_eq!(
        etag,
        format!("\"{}\"", body["meta"]["input_hash"].as_str().unwrap())
    );
    let job = Job::from_value(json!({"kind": "rolling"}), &Limits::default()).unwrap();
    assert_eq!(body, engine_answer(job));
}

#[tokio::test]
async fn a_repeated_input_is_a_hit_whatever_its_key_order_and_spacing() {
    let app = spawn_app(&[]).await;
    let first = app
        .post_json_text("/v1/rolling", r#"{"radius": "25 nm", "load": "1 nN"}"#)
        .await;
    assert_eq!(first.headers()["x-cache"], "miss");
    let first = first.text().await.unwrap();
    for body in [
        r#"{"load":"1 nN","radius":"25 nm"}"#,
        "{ \"radius\" : \"25 nm\",\n \"load\": \"1 nN\" }",
    ] {
        let again = app.post_json_text("/v1/rolling", body).await;
        assert_eq!(again.headers()["x-cache"], "hit", "{body}");
        assert_eq!(again.text().await.unwrap(), first);
    }
    assert_eq!(app.metric("thirdbody_cache_hits_total", &[]).await, 2.0);
    // The same text as another kind is another job.
    let sweep = app
        .post_json_text("/v1/sweeps", r#"{"load":"1 nN","radius":"25 nm"}"#)
        .await;
    assert_eq!(sweep.status(), 422, "a sweep has no field radius");
}

#[tokio::test]
async fn three_body_answers_the_engine_and_carries_its_total_load() {
    let app = spawn_app(&[]).await;
    let input = json!({"operating": {"total_load": "1 mN"}});
    let response = app.post("/v1/three-body", &input).await;
    assert_eq!(response.status(), 200);
    assert_eq!(response.headers()["x-cache"], "miss");
    let body: Value = response.json().await.unwrap();
    let load = body["loads"]["total"].as_f64().unwrap();
    assert!((load / 1e-3 - 1.0).abs() < 1e-10, "{load}");
    let mu = &body["friction_coefficient"];
    assert!(mu["rolling"].as_f64().unwrap() < mu["static"].as_f64().unwrap());
    let job = Job::from_value(
        json!({"kind": "three_body", "input": input}),
        &Limits::default(),
    )
    .unwrap();
    assert_eq!(body, engine_answer(job));

    // A load the system cannot carry is a solve failure that says why.
    let response = app
        .post(
            "/v1/three-body",
            &json!({"operating": {"total_load": "1 kN"}}),
        )
        .await;
    assert_eq!(response.status(), 422);
    let problem: Value = response.json().await.unwrap();
    assert!(
        problem["detail"]
            .as_str()
            .unwrap()
            .contains("cannot be carried"),
        "{problem}"
    );
    // No operating point: invalid input naming the field.
    let response = app.post("/v1/three-body", &json!({})).await;
    assert_eq!(response.status(), 422);
    let problem: Value = response.json().await.unwrap();
    assert_eq!(problem["errors"][0]["field"], "operating");
}

#[tokio::test]
async fn the_same_job_again_is_a_cache_hit_whatever_its_units_and_if_none_match_is_304() {
    let app = spawn_app(&[]).await;
    let first = app.post("/v1/rolling", &json!({"radius": 2.5e-8})).await;
    assert_eq!(first.headers()["x-cache"], "miss");
    let etag = first.headers()["etag"].clone();
    let first = first.text().await.unwrap();

    // The same input in other units has the same canonical form, so the same key.
    let second = app.post("/v1/rolling", &json!({"radius": "25 nm"})).await;
    assert_eq!(second.headers()["x-cache"], "hit");
    assert_eq!(second.headers()["etag"], etag);
    assert_eq!(second.text().await.unwrap(), first);

    let not_modified = app
        .post_with(
            "/v1/rolling",
            &[("if-none-match", etag.to_str().unwrap())],
            &json!({"radius": "25 nm"}),
        )
        .await;
    assert_eq!(not_modified.status(), 304);
    assert_eq!(not_modified.headers()["etag"], etag);
    assert!(not_modified.bytes().await.unwrap().is_empty());

    let another = [("if-none-match", "\"another\"")];
    let other = app
        .post_with("/v1/rolling", &another, &json!({"radius": "26 nm"}))
        .await;
    assert_eq!(other.status(), 200);
    assert_eq!(app.metric("thirdbody_cache_hits_total", &[]).await, 2.0);
    assert_eq!(app.metric("thirdbody_cache_misses_total", &[]).await, 2.0);
}

#[tokio::test]
async fn a_hundred_identical_concurrent_requests_are_solved_once() {
    let app = spawn_app(&[]).await;
    let input = json!({"radius": "31 nm", "velocity": "7 nm/s"});
    let responses = join_all((0..100).map(|_| app.post("/v1/rolling", &input))).await;
    let mut misses = 0;
    let mut bodies = Vec::new();
    for response in responses {
        assert_eq!(response.status(), 200);
        misses += usize::from(response.headers()["x-cache"] == "miss");
        bodies.push(response.text().await.unwrap());
    }
    assert_eq!(misses, 1);
    assert!(bodies.iter().all(|b| *b == bodies[0]));
    let solves = app.solves(&[("kind", "rolling")]).await;
    assert_eq!(solves, 1.0);
    assert_eq!(app.metric("thirdbody_cache_hits_total", &[]).await, 99.0);
}

#[tokio::test]
async fn a_sweep_answers_json_or_csv_with_one_row_per_point() {
    let app = spawn_app(&[]).await;
    let job: Value = serde_json::from_str(include_str!("../../examples/sweep.json")).unwrap();
    let input = &job["input"];
    let response = app.post("/v1/sweeps", input).await;
    assert_eq!(response.status(), 200);
    let json_etag = response.headers()["etag"].clone();
    let body: Value = response.json().await.unwrap();
    assert_eq!(body["points"].as_array().unwrap().len(), 15);
    assert_eq!(
        body,
        engine_answer(Job::from_value(job.clone(), &Limits::default()).unwrap())
    );

    let csv = app
        .post_with("/v1/sweeps", &[("accept", "text/csv")], input)
        .await;
    assert_eq!(csv.status(), 200);
    assert!(csv.headers()["content-type"]
        .to_str()
        .unwrap()
        .starts_with("text/csv"));
    assert_eq!(csv.headers()["x-cache"], "hit");
    assert_ne!(csv.headers()["etag"], json_etag);
    let text = csv.text().await.unwrap();
    assert_eq!(text.lines().count(), 16);
    assert!(text.starts_with("radius [m],load [N],velocity [m/s],"));
}

#[tokio::test]
async fn a_figure_answers_json_or_csv() {
    let app = spawn_app(&[]).await;
    let response = app.get("/v1/figures/6").await;
    assert_eq!(response.status(), 200);
    let body: Value = response.json().await.unwrap();
    assert_eq!(body["figure"], 6);
    assert_eq!(body, engine_answer(Job::new(FigureJob::new(6).unwrap())));

    let csv = app
        .get_with("/v1/figures/3", &[("accept", "text/csv")])
        .await;
    assert_eq!(csv.status(), 200);
    let text = csv.text().await.unwrap();
    assert!(text.starts_with("series,label,"), "{text}");
}

/// One input, one answer: after the figures (whose points build the layer's similarity
/// table in this process) a single rolling answer is still the exact strip solve, the digits
/// a fresh process and `thirdbody solve` give (issue 52: it read the table the figures had
/// built, and answered A = 1.2402381982101833e-16 for …1803).
#[tokio::test]
async fn a_single_answer_does_not_depend_on_what_the_process_did_before() {
    use thirdbody::model::{solve, Rolling, SolveOptions};
    let app = spawn_app(&[]).await;
    for number in 3..=9 {
        let figure = app.get(&format!("/v1/figures/{number}")).await;
        assert_eq!(figure.status(), 200);
    }
    for (radius, load) in [(5e-8, 1e-9), (2.5e-8, 1.2e-9)] {
        let body = json!({"radius": radius, "load": load});
        let answer = app.post_json("/v1/rolling", &body).await;
        let rolling = Rolling {
            radius,
            load,
            ..Rolling::default()
        };
        let exact = solve(&rolling, &SolveOptions::default()).unwrap();
        let text = |x: f64| serde_json::to_string(&x).unwrap();
        assert_eq!(
            answer["contact_area"].to_string(),
            text(exact.contact_area),
            "R = {radius:e}, P = {load:e}"
        );
        assert_eq!(
            answer["friction_coefficient"].to_string(),
            text(exact.friction_coefficient)
        );
    }
}
