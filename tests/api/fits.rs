//! `POST /v1/fits` and fits as asynchronous jobs: the answer's contract, problems for bad
//! data, progress without a known total, cancel.

use serde_json::{json, Value};
use thirdbody::job::{Job, Limits};

use crate::helpers::{problem, problem_type, spawn_app};
use crate::solve::engine_answer;

/// The fit of `examples/fit.json`: 30 points, three parameters.
fn example() -> Value {
    let text = include_str!("../../examples/fit.json");
    serde_json::from_str(text).unwrap()
}

#[tokio::test]
async fn a_fit_is_answered_now_with_the_contracts_fields() {
    let app = spawn_app(&[]).await;
    let job = example();
    let answer = app.answer("/v1/fits", &job["input"]).await;
    let names = ["relaxation_time", "retardation_time", "elastic_modulus"];
    assert_eq!(answer["parameter_names"], json!(names));
    for name in names {
        let p = &answer["parameters"][name];
        let (value, se) = (
            p["value"].as_f64().unwrap(),
            p["standard_error"].as_f64().unwrap(),
        );
        let interval = p["interval_95"].as_array().unwrap();
        let (lo, hi) = (interval[0].as_f64().unwrap(), interval[1].as_f64().unwrap());
        assert!(lo < value && value < hi && se > 0.0, "{name}: {p}");
    }
    assert_eq!(answer["correlation"].as_array().unwrap().len(), 3);
    assert_eq!(answer["dof"], 27);
    assert!(answer["chi_squared"].as_f64().unwrap() > 0.0);
    assert_eq!(answer["residuals"].as_array().unwrap().len(), 30);
    assert_eq!(answer["identifiability"]["identifiable"], true);
    assert_eq!(answer["curves"].as_array().unwrap().len(), 2);
    // The data were drawn from T_σ = 80 ms, T_ε = 600 ms, E_L = 2.5 GPa.
    for (name, truth) in [
        ("relaxation_time", 0.08),
        ("retardation_time", 0.6),
        ("elastic_modulus", 2.5e9),
    ] {
        let interval = &answer["parameters"][name]["interval_95"];
        assert!(interval[0].as_f64().unwrap() < truth && truth < interval[1].as_f64().unwrap());
    }
    let expected = engine_answer(Job::from_value(job, &Limits::default()).unwrap());
    assert_eq!(answer, expected);
}

#[tokio::test]
async fn bad_data_get_a_problem_naming_the_field() {
    let app = spawn_app(&[]).await;
    let input = json!({"series": [{"points": [{"velocity": "1 nm/s", "value": 0.1}]}],
                       "parameters": {"relaxation_time": {}, "retardation_time": {}}});
    let few = problem(app.post("/v1/fits", &input).await, 422).await;
    assert_eq!(few["type"], problem_type("invalid-input"));
    assert_eq!(few["errors"][0]["field"], "series", "{few}");
    let input = json!({"series": [{"velocity": 0, "points": [
        {"load": "1 nN", "value": 0.11}, {"load": "1.2 nN", "value": 0.1}, {"load": "1.4 nN", "value": 0.09}]}],
        "parameters": {"retardation_time": {}}});
    let problem = problem(app.post("/v1/fits", &input).await, 422).await;
    assert_eq!(
        problem["errors"][0]["field"], "parameters.retardation_time",
        "{problem}"
    );
}

#[tokio::test]
async fn a_fit_job_reports_progress_and_stops_on_cancel() {
    let app = spawn_app(&["--max-sweep-points", "100000"]).await;
    let points: Vec<Value> = (1..=20_000)
        .map(|i| json!({"velocity": format!("{} nm/s", 0.001 * i as f64), "value": 0.1}))
        .collect();
    let long = json!({"kind": "fit", "input": {"series": [{"points": points}],
        "parameters": {"relaxation_time": {}, "retardation_time": {}}}});
    let location = app.submit(&long).await;
    let running = app
        .wait_for_job(&location, |j| {
            j["status"] == "running" && j["progress"]["done"].as_u64() > Some(0)
        })
        .await;
    assert_eq!(running["kind"], "fit");
    assert_eq!(
        running["progress"]["total"], 0,
        "a fit cannot tell its size: {running}"
    );
    let cancelled: Value = app.cancel(&location).await.json().await.unwrap();
    assert_eq!(cancelled["status"], "cancelled", "{cancelled}");
    // Cancelled after a first minimisation finished, the fit keeps the best of those run.
    if cancelled.get("result_url").is_some() {
        assert_eq!(cancelled["partial"], true);
        let partial = app.result(&cancelled).await;
        assert_eq!(partial["meta"]["complete"], false);
        assert!(partial["search"]["finished"].as_u64() < partial["search"]["starts"].as_u64());
    }

    let location = app.submit(&example()).await;
    let done = app
        .wait_for_job(&location, |j| {
            j["status"] != "queued" && j["status"] != "running"
        })
        .await;
    assert_eq!(done["status"], "succeeded", "{done}");
    assert!(done["progress"]["done"].as_u64().unwrap() > 30);
    assert_eq!(app.result(&done).await["dof"], 27);
}
