//! `POST /v1/checks` and the provenance of answers: what a CI pipeline without the binary
//! uses.

use std::process::{Command, Output};

use serde_json::{json, Value};

use crate::helpers::{problem, problem_type, spawn_app, within};

/// Checks that fail answer 422 (before issue 20, 200 with `passed: false`, which let a
/// pipeline's `curl -f` pass): the problem carries the report's fields, or the JUnit report.
#[tokio::test]
async fn failed_checks_answer_422_with_the_report_as_a_problem_or_as_junit() {
    let app = spawn_app(&[]).await;
    let checks = json!({"checks": [
        {"name": "mu stays low", "job": {"kind": "rolling", "input": {"load": "1.2 nN"}},
         "expect": {"friction_coefficient": {"max": 0.1},
                    "contact_area": {"equals": 9.411134777002667e-17, "rtol": 1e-9}}},
        {"name": "too strict", "job": {"kind": "sweep", "input": {"vary": {"load": ["1 nN", "1.4 nN"]}}},
         "expect": {"points[].friction_coefficient": {"max": 0.09}}},
        {"name": "pierced", "job": {"kind": "rolling", "input": {"load": "1 mN"}},
         "expect": {"friction_coefficient": {"max": 1}}}
    ]});
    let report = problem(app.post("/v1/checks", &checks).await, 422).await;
    assert_eq!(report["type"], problem_type("checks-failed"));
    assert_eq!(
        report["detail"],
        "2 of 3 checks failed: too strict, pierced"
    );
    assert_eq!(report["passed"], false);
    assert_eq!(
        report["summary"],
        json!({"checks": 3, "passed": 1, "failed": 2})
    );
    assert_eq!(report["checks"][0]["passed"], true);
    let strict = &report["checks"][1]["outcomes"];
    assert_eq!(strict[0]["path"], "points[0].friction_coefficient");
    assert_eq!(strict[0]["passed"], false);
    assert!(report["checks"][2]["error"]
        .as_str()
        .unwrap()
        .contains("651 nm"));

    let xml = app
        .post_with("/v1/checks", &[("accept", "application/xml")], &checks)
        .await;
    assert_eq!(xml.status(), 422);
    assert_eq!(xml.headers()["content-type"], "application/xml");
    let xml = xml.text().await.unwrap();
    assert!(xml.contains("tests=\"3\" failures=\"2\""), "{xml}");

    let bad = json!({"checks": [{"name": "x", "job": {"kind": "rolling"}, "expect": {"a..b": {"max": 1}}}]});
    let refused = problem(app.post("/v1/checks", &bad).await, 422).await;
    assert_eq!(refused["type"], problem_type("invalid-input"));
    assert!(refused["detail"]
        .as_str()
        .unwrap()
        .contains("not a field path"));
}

#[tokio::test]
async fn every_answer_says_where_it_comes_from_and_a_job_result_comes_as_csv() {
    let app = spawn_app(&[]).await;
    let accept_csv = [("accept", "text/csv")];
    let sweep = json!({"vary": {"load": ["1 nN", "1.1 nN"]}});
    let response = app.post_with("/v1/sweeps", &accept_csv, &sweep).await;
    let headers = response.headers().clone();
    assert_eq!(headers["x-model-version"], thirdbody::model::MODEL_VERSION);
    assert_eq!(headers["x-software-version"], env!("CARGO_PKG_VERSION"));
    assert!(!headers["x-software-commit"].is_empty());
    let hash = headers["x-input-hash"].to_str().unwrap().to_string();
    assert_eq!(headers["etag"], format!("\"{hash}.csv\"").as_str());
    let text = response.text().await.unwrap();
    assert!(
        text.starts_with("radius [m],load [N],velocity [m/s],"),
        "{text}"
    );

    let location = app
        .submit(&json!({"kind": "sweep", "input": {"vary": {"load": ["1 nN", "1.1 nN"]}}}))
        .await;
    let result = format!("{location}/result");
    app.wait_for_job(&location, |j| j["status"] == "succeeded")
        .await;
    let csv = app.get_with(&result, &accept_csv).await;
    assert_eq!(csv.status(), 200);
    assert_eq!(csv.headers()["x-input-hash"], hash.as_str());
    assert_eq!(
        csv.text().await.unwrap(),
        text,
        "the job's CSV is the synchronous one"
    );
    let json: Value = app.get(&result).await.json().await.unwrap();
    assert_eq!(json["meta"]["input_hash"], hash);

    let running = app.submit(&crate::helpers::long_sweep(21)).await;
    let not_ready = problem(app.get(&format!("{running}/result")).await, 409).await;
    assert_eq!(not_ready["type"], problem_type("not-ready"));
    app.wait_for_job(&running, |j| j["status"] == "running")
        .await;
    app.cancel(&running).await;
    // A cancelled sweep keeps what it finished: its answer is partial, and says so.
    let partial = app.get(&format!("{running}/result")).await;
    assert_eq!(partial.status(), 200);
    assert!(partial.headers().get("etag").is_none());
    let partial: Value = partial.json().await.unwrap();
    assert_eq!(partial["meta"]["complete"], false);
    assert_eq!(partial["meta"]["stopped"], "the job was cancelled");
    assert!(partial["meta"]["counts"]["missing"].as_u64().unwrap() > 0);
}

#[tokio::test]
async fn the_readme_s_checks_pass_against_the_service_with_200() {
    let app = spawn_app(&[]).await;
    let checks: Value =
        serde_json::from_str(include_str!("../../examples/checks-inline.json")).unwrap();
    let response = app.post("/v1/checks", &checks).await;
    assert_eq!(response.status(), 200);
    assert_eq!(response.headers()["content-type"], "application/json");
    let report: Value = response.json().await.unwrap();
    assert_eq!(report["passed"], true, "{report}");
    assert_eq!(report["summary"]["checks"], 4);

    let accept = [("accept", "application/xml")];
    let xml = app.post_with("/v1/checks", &accept, &checks).await;
    assert_eq!(xml.status(), 200);
    assert!(xml
        .text()
        .await
        .unwrap()
        .contains("tests=\"4\" failures=\"0\""));
}

#[tokio::test]
async fn a_misspelt_path_names_the_nearest_fields_of_the_answer() {
    let app = spawn_app(&[]).await;
    let checks = json!({"checks": [{"name": "typo", "job": {"kind": "rolling"},
        "expect": {"friction_coeficient": {"max": 0.1}}}]});
    let report = problem(app.post("/v1/checks", &checks).await, 422).await;
    assert_eq!(
        report["checks"][0]["outcomes"][0]["message"],
        "friction_coeficient: the answer has no field at this path; \
         nearest: friction_coefficient, static.friction_coefficient"
    );
}

/// Runs the real `curl` with `args` (off the test's runtime, which serves the app).
async fn curl(args: Vec<String>) -> Output {
    let run = tokio::task::spawn_blocking(move || {
        Command::new("curl")
            .args(["--silent", "--show-error", "--max-time", "120"])
            .args(&args)
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .output()
            .unwrap_or_else(|e| {
                panic!(
                    "cannot run curl ({e}): this test runs README's recipe with it; install curl"
                )
            })
    });
    within(run).await.unwrap()
}

/// README's recipe as a pipeline runs it: failed checks fail the step (`-f`), and
/// `--fail-with-body` still prints the report, as JSON or JUnit; checks that pass exit 0.
#[tokio::test]
async fn curl_fails_the_pipeline_on_failed_checks_and_prints_the_report() {
    let app = spawn_app(&[]).await;
    let failing = json!({"checks": [{"name": "too strict", "job": {"kind": "rolling"},
        "expect": {"friction_coefficient": {"max": 0.01}}}]});
    let request = |fail: &str, accept: &str, data: String| -> Vec<String> {
        let url = app.url("/v1/checks");
        [
            fail,
            "-X",
            "POST",
            &url,
            "-H",
            "content-type: application/json",
        ]
        .into_iter()
        .chain(["-H", accept, "--data", &data])
        .map(str::to_string)
        .collect()
    };
    let json = "accept: application/json";
    let xml = "accept: application/xml";

    let quiet = curl(request("--fail", json, failing.to_string())).await;
    assert_eq!(quiet.status.code(), Some(22), "curl -f exits 22 on 422");
    assert!(quiet.stdout.is_empty());

    let out = curl(request("--fail-with-body", json, failing.to_string())).await;
    assert_eq!(out.status.code(), Some(22));
    let report: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["type"], problem_type("checks-failed"));
    assert_eq!(report["passed"], false);
    assert_eq!(report["checks"][0]["name"], "too strict");

    let out = curl(request("--fail-with-body", xml, failing.to_string())).await;
    assert_eq!(out.status.code(), Some(22));
    let junit = String::from_utf8(out.stdout).unwrap();
    assert!(junit.contains("tests=\"1\" failures=\"1\""), "{junit}");

    let readme = "@examples/checks-inline.json".to_string();
    let out = curl(request("--fail-with-body", xml, readme)).await;
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let junit = String::from_utf8(out.stdout).unwrap();
    assert!(junit.contains("tests=\"4\" failures=\"0\""), "{junit}");
}

#[tokio::test]
async fn a_suite_runs_within_one_solve_deadline_however_many_checks_it_holds() {
    let app = spawn_app(&["--solve-deadline", "1s"]).await;
    // Five sweeps that each take longer than the deadline: one deadline each would hold the
    // request (and a solver thread) five seconds.
    let checks: Vec<Value> = (0..5)
        .map(|i| {
            json!({"name": format!("slow {i}"), "job": crate::helpers::long_sweep(36 + i),
                   "expect": {"points[].friction_coefficient": {"min": 0}}})
        })
        .collect();
    let start = std::time::Instant::now();
    let response = within(app.post("/v1/checks", &json!({ "checks": checks }))).await;
    let elapsed = start.elapsed();
    let report = problem(response, 422).await;
    assert!(elapsed < std::time::Duration::from_secs(4), "{elapsed:?}");
    let errors: Vec<&str> = report["checks"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["error"].as_str().unwrap_or(""))
        .collect();
    assert!(
        errors[1..]
            .iter()
            .all(|e| e.starts_with("not run: the suite ran past its deadline of 1s")),
        "{errors:?}"
    );
}

/// A suite's answers are judged as they come and let go (issue 45: 332 checks of
/// 10,000-point sweeps took the service to 1.4 GB, and kept it): a check over every point of
/// a sweep reports the failures, ten at most, and one outcome for all the points, not one
/// outcome a point; and the sweep's answer is not kept in the cache, where nobody would ask
/// for it but the same check, while a rolling contact's few kB are (the suite run again is
/// answered from the cache).
#[tokio::test]
async fn a_suite_s_answers_are_judged_and_let_go() {
    let app = spawn_app(&[]).await;
    let loads: Vec<String> = (0..20).map(|i| format!("{} nN", 1 + i)).collect();
    let speeds: Vec<String> = (0..20).map(|i| format!("{} nm/s", 4 + i)).collect();
    let sweep = json!({"vary": {"load": loads, "velocity": speeds}});
    let rolling = json!({"load": "1.3 nN"});
    let checks = json!({"checks": [
        {"name": "every point", "job": {"kind": "sweep", "input": sweep},
         "expect": {"points[].friction_coefficient": {"max": 1},
                    "points[].contact_area": {"min": 1}}},
        {"name": "one contact", "job": {"kind": "rolling", "input": rolling},
         "expect": {"friction_coefficient": {"max": 1}}}]});
    let report = problem(app.post("/v1/checks", &checks).await, 422).await;
    let check = &report["checks"][0];
    let outcomes = check["outcomes"].as_array().unwrap();
    assert_eq!(outcomes.len(), 12, "{outcomes:?}");
    assert_eq!(outcomes[9]["path"], "points[9].contact_area");
    assert_eq!(
        outcomes[10]["message"],
        "points[].contact_area: 400 of 400 values fail (the first 10 listed)"
    );
    assert_eq!(
        outcomes[11],
        json!({"path": "points[].friction_coefficient", "expected": "at most 1",
               "passed": true, "message": ""})
    );

    let hash = |check: &Value| check["input_hash"].as_str().unwrap().to_string();
    let solved = app.post("/v1/sweeps", &sweep).await;
    assert_eq!(solved.headers()["x-input-hash"], hash(check).as_str());
    assert_eq!(
        solved.headers()["x-cache"],
        "miss",
        "the check kept its sweep"
    );
    let again = app.post("/v1/sweeps", &sweep).await;
    assert_eq!(
        again.headers()["x-cache"],
        "hit",
        "a client's answer is kept"
    );
    let contact = app.post("/v1/rolling", &rolling).await;
    assert_eq!(
        contact.headers()["x-input-hash"],
        hash(&report["checks"][1]).as_str()
    );
    assert_eq!(
        contact.headers()["x-cache"],
        "hit",
        "the check let its contact go"
    );
}
