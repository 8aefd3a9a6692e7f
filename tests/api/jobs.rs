//! Asynchronous jobs: lifecycle by polling and by server-sent events, cancel, failure,
//! expiry.

use std::time::Duration;

use serde_json::{json, Value};
use thirdbody::job::{Job, Limits};

use crate::helpers::{long_sweep, problem, problem_type, spawn_app, spawn_app_on_disk, Events};
use crate::solve::engine_answer;

fn small_sweep() -> Value {
    json!({"kind": "sweep", "input": {"vary": {
        "radius": ["25 nm", "50 nm", "150 nm", "250 nm", "350 nm"],
        "load": ["1 nN", "1.1 nN", "1.2 nN", "1.3 nN", "1.4 nN"]}}})
}

#[tokio::test]
async fn a_job_is_accepted_then_polled_to_its_result() {
    let app = spawn_app(&[]).await;
    let response = app.post("/v1/jobs", &small_sweep()).await;
    assert_eq!(response.status(), 202);
    assert_eq!(response.headers()["retry-after"], "1");
    let location = response.headers()["location"].to_str().unwrap().to_string();
    let accepted: Value = response.json().await.unwrap();
    assert_eq!(
        location,
        format!("/v1/jobs/{}", accepted["id"].as_str().unwrap())
    );
    assert_eq!(accepted["kind"], "sweep");
    assert_eq!(accepted["progress"]["total"], 25);
    assert!(["queued", "running", "succeeded"].contains(&accepted["status"].as_str().unwrap()));

    let job = app
        .wait_for_job(&location, |j| {
            j["status"] != "queued" && j["status"] != "running"
        })
        .await;
    assert_eq!(job["status"], "succeeded");
    assert_eq!(job["progress"], json!({"done": 25, "total": 25}));
    let expected = engine_answer(Job::from_value(small_sweep(), &Limits::default()).unwrap());
    assert_eq!(app.result(&job).await, expected);
}

#[tokio::test]
async fn a_job_streams_progress_then_its_completion() {
    let app = spawn_app_on_disk(&["--pool-size", "1", "--max-sweep-points", "1000000"]).await;
    // A long job holds the only solver thread, so the job followed is seen queued first.
    let blocker = app.submit(&long_sweep(100)).await;
    let location = app.submit(&long_sweep(20)).await;
    let mut events = Events::new(app.get(&format!("{location}/events")).await);
    let (name, first) = events.next().await.unwrap();
    assert_eq!(
        (name.as_str(), &first["status"]),
        ("progress", &json!("queued"))
    );
    app.delete(&blocker).await;
    let (mut progress, completion) = events.until_completion().await;
    progress.insert(0, first);
    assert!(
        events.next().await.is_none(),
        "the stream ends after completion"
    );
    let done: Vec<u64> = progress
        .iter()
        .map(|j| j["progress"]["done"].as_u64().unwrap())
        .collect();
    assert!(done.windows(2).all(|w| w[0] <= w[1]), "{done:?}");
    assert!(progress.iter().all(|j| j.get("result_url").is_none()));
    assert_eq!(completion["status"], "succeeded");
    assert_eq!(completion["progress"], json!({"done": 1000, "total": 1000}));
    // The completion event is small (its id, hash and times): it links to the answer
    // rather than carrying it.
    assert!(completion.to_string().len() < 400, "{completion}");
    assert_eq!(
        app.result(&completion).await["points"]
            .as_array()
            .unwrap()
            .len(),
        1000
    );
}

#[tokio::test]
async fn a_running_job_is_cancelled_at_the_solvers_next_check() {
    let app = spawn_app_on_disk(&["--max-sweep-points", "1000000"]).await;
    let location = app.submit_running(&long_sweep(100)).await;
    let response = app.cancel(&location).await;
    assert_eq!(response.status(), 200);
    let job: Value = response.json().await.unwrap();
    assert_eq!(job["status"], "cancelled");
    assert!(job["progress"]["done"].as_u64() < job["progress"]["total"].as_u64());
    assert!(job.get("result").is_none() && job.get("problem").is_none());
    let again: Value = app.get(&location).await.json().await.unwrap();
    assert_eq!(again["status"], "cancelled");
    let cancelled = app.solves(&[("outcome", "cancelled")]).await;
    assert_eq!(cancelled, 1.0);
}

#[tokio::test]
async fn a_job_past_its_deadline_fails_with_a_problem() {
    let app = spawn_app(&["--job-deadline", "1ms"]).await;
    let location = app.submit(&long_sweep(20)).await;
    let job = app
        .wait_for_job(&location, |j| j["status"] == "failed")
        .await;
    assert_eq!(job["problem"]["status"], 504);
    assert_eq!(job["problem"]["type"], problem_type("deadline-exceeded"));
}

#[tokio::test]
async fn a_finished_job_expires_after_the_retention_time() {
    // Out of memory after a second, out of the history (the database) after two.
    let app = spawn_app(&["--job-retention", "1s", "--history-retention", "2s"]).await;
    let location = app.submit(&json!({"kind": "rolling"})).await;
    let mut events = Events::new(app.get(&format!("{location}/events")).await);
    events.until_completion().await;
    tokio::time::sleep(Duration::from_millis(2500)).await;
    let gone = problem(app.get(&location).await, 404).await;
    assert!(gone["detail"].as_str().unwrap().contains("expired"));
}

#[tokio::test]
async fn a_deleted_job_is_cancelled_and_forgotten() {
    let app = spawn_app_on_disk(&["--max-sweep-points", "1000000"]).await;
    let location = app.submit_running(&long_sweep(100)).await;
    let deleted: Value = app.delete(&location).await.json().await.unwrap();
    assert_eq!(deleted["status"], "cancelled");
    let gone = problem(app.get(&location).await, 404).await;
    assert!(gone["detail"].as_str().unwrap().contains("deleted"));
    problem(app.delete(&location).await, 404).await;
}
