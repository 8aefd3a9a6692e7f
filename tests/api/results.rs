//! Whole answers (issue 20): a job accepted is answered and kept; a sweep answers every point
//! it can; a stopped sweep keeps what it finished; job views stay small; answers are compact
//! and compressed.

use std::io::Read;

use serde_json::{json, Value};

use crate::helpers::{assert_detail_says, long_sweep, problem, problem_type, spawn_app, within};

/// A rolling sweep of `n` × 100 points, each a table look-up.
fn sweep(n: usize) -> Value {
    let loads: Vec<String> = (0..n).map(|i| format!("{} pN", 1000 + i)).collect();
    let speeds: Vec<String> = (0..100).map(|i| format!("{i} nm/s")).collect();
    json!({"kind": "sweep", "input": {"vary": {"load": loads, "velocity": speeds}}})
}

#[tokio::test]
async fn the_largest_sweep_the_defaults_allow_is_kept_whole_compact_and_compressed() {
    let app = spawn_app(&[]).await;
    let location = app.submit(&sweep(100)).await;
    let job = app
        .wait_for_job(&location, |j| j["status"] == "succeeded")
        .await;
    // The view is small (its id, hash and times): it links to the answer.
    assert!(job.to_string().len() < 400, "{job}");
    let response = app.get(job["result_url"].as_str().unwrap()).await;
    assert_eq!(response.status(), 200);
    let etag = response.headers()["etag"].to_str().unwrap().to_string();
    let bytes = response.bytes().await.unwrap();
    let answer: Value = serde_json::from_slice(&bytes).unwrap();
    assert_eq!(answer["points"].as_array().unwrap().len(), 10_000);
    assert_eq!(answer["meta"]["counts"]["total"], 10_000);
    assert_eq!(answer["meta"]["complete"], true);
    // Compact: the words of each assumption are in meta once, not on every point (about
    // 4 kB a point if they were not). A point's numbers: its contact, its motion (issue 48:
    // five numbers and the mode, 165 bytes) and its ratios, about 865 bytes.
    let per_point = bytes.len() / 10_000;
    assert!(per_point <= 900, "{per_point} bytes per point");
    // gzip for a client that accepts it, the same answer, its validator weak.
    let url = job["result_url"].as_str().unwrap();
    let zipped = app.get_with(url, &[("accept-encoding", "gzip")]).await;
    assert_eq!(zipped.headers()["content-encoding"], "gzip");
    assert_eq!(
        zipped.headers()["etag"].to_str().unwrap(),
        format!("W/{etag}")
    );
    let compressed = zipped.bytes().await.unwrap();
    assert!(
        compressed.len() * 4 < bytes.len(),
        "{} bytes",
        compressed.len()
    );
    let mut unzipped = Vec::new();
    flate2::read::GzDecoder::new(&compressed[..])
        .read_to_end(&mut unzipped)
        .unwrap();
    assert_eq!(unzipped, bytes);
    // Polled again, the job still has it: nothing is dropped after success.
    let again = app.get(url).await;
    assert_eq!(again.status(), 200);
}

#[tokio::test]
async fn a_sweep_answers_every_point_it_can_and_names_the_refused_ones() {
    let app = spawn_app(&[]).await;
    let input = json!({"vary": {"load": ["1 nN", "1 mN"]}});
    let answer = app.answer("/v1/sweeps", &input).await;
    let points = answer["points"].as_array().unwrap();
    assert_eq!(points[0]["status"], "warn");
    assert!(points[0]["friction_coefficient"].as_f64().unwrap() > 0.0);
    assert_eq!(points[1]["status"], "refused");
    assert_eq!(points[1]["load"], 1e-3);
    let reason = points[1]["reason"].as_str().unwrap();
    assert!(
        reason.contains("651 nm") && reason.contains("100 nm"),
        "{reason}"
    );
    assert!(points[1].get("friction_coefficient").is_none());
    assert_eq!(answer["meta"]["counts"]["refused"], 1);
    assert_eq!(answer["meta"]["validity"]["status"], "warn");
    let csv = app
        .post_with("/v1/sweeps", &[("accept", "text/csv")], &input)
        .await
        .text()
        .await
        .unwrap();
    let refused = csv.lines().nth(2).unwrap();
    assert!(refused.starts_with("2.5e-8,0.001,4e-9,,"), "{refused}");
    assert!(
        refused.contains("\"refused\",\"the penetration 651 nm"),
        "{refused}"
    );
    // Asked to, the sweep fails at the first refusal, naming the point.
    let failing = json!({"on_refusal": "fail", "vary": {"load": ["1 nN", "1 mN"]}});
    let refused = problem(app.post("/v1/sweeps", &failing).await, 422).await;
    let detail = refused["detail"].as_str().unwrap();
    // Named by its index and its inputs, in the units of their magnitude (issue 52).
    assert!(
        detail.starts_with("points[1] (R = 25 nm, P = 1 mN, V = 4 nm/s): "),
        "{detail}"
    );
    // As a job it fails, and keeps the points before the refusal, as a cancel does.
    let job = json!({"kind": "sweep", "input": failing});
    let location = app.submit(&job).await;
    let job = app
        .wait_for_job(&location, |j| j["status"] == "failed")
        .await;
    assert_eq!(job["partial"], true, "{job}");
    assert!(job["problem"]["detail"]
        .as_str()
        .unwrap()
        .starts_with("points[1] (R = 25 nm"));
    let partial = app.result(&job).await;
    let statuses: Vec<&Value> = partial["points"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| &p["status"])
        .collect();
    assert_eq!(statuses.len(), 2);
    assert!(statuses[0] == "ok" || statuses[0] == "warn", "{statuses:?}");
    assert_eq!(statuses[1], "missing");
}

#[tokio::test]
async fn a_sweep_past_its_deadline_fails_but_keeps_the_points_it_finished() {
    let app = spawn_app(&["--max-sweep-points", "1000000", "--job-deadline", "1s"]).await;
    let location = app.submit(&long_sweep(40)).await;
    let job = app
        .wait_for_job(&location, |j| j["status"] == "failed")
        .await;
    assert_eq!(job["problem"]["type"], problem_type("deadline-exceeded"));
    assert_eq!(job["partial"], true);
    let partial = app.result(&job).await;
    assert_eq!(partial["meta"]["complete"], false);
    let counts = &partial["meta"]["counts"];
    let done = counts["ok"].as_u64().unwrap() + counts["warn"].as_u64().unwrap();
    assert!(
        done > 0 && counts["missing"].as_u64().unwrap() > 0,
        "{counts}"
    );
    assert_eq!(counts["total"], 20 * 20 * 20);
    let rows = partial["points"].as_array().unwrap();
    assert_eq!(rows.len(), 8000);
    let missing = rows.iter().filter(|p| p["status"] == "missing").count();
    assert_eq!(missing as u64, counts["missing"].as_u64().unwrap());
    // The CSV lists the missing points too.
    let url = job["result_url"].as_str().unwrap();
    let csv = app
        .get_with(url, &[("accept", "text/csv")])
        .await
        .text()
        .await
        .unwrap();
    assert_eq!(
        csv.lines().filter(|l| l.contains("\"missing\"")).count(),
        missing
    );
}

#[tokio::test]
async fn a_job_whose_result_cannot_be_kept_is_refused_at_submission_never_after_its_work() {
    // 8 MB of budget: 1.5 MB for results, and a database in memory, which keeps no result
    // beyond them.
    let app = spawn_app(&["--memory-budget", "8000000", "--database", ":memory:"]).await;
    // Its result takes about 0.5 MB; one that may take 1.2 MB does not fit beside it.
    let first = app.submit(&sweep(5)).await;
    app.wait_for_job(&first, |j| j["status"] == "succeeded")
        .await;
    let full = app.post("/v1/jobs", &sweep(8)).await;
    let retry = full.headers()["retry-after"]
        .to_str()
        .unwrap()
        .parse::<u64>();
    assert!(retry.is_ok_and(|s| (1..=900).contains(&s)));
    let full = problem(full, 503).await;
    assert_eq!(full["type"], problem_type("results-full"));
    assert_detail_says(&full, "this job's result may take up to");
    // The first result is still there, whole.
    let kept = app.get(&format!("{first}/result")).await;
    assert_eq!(kept.status(), 200);
    let huge = problem(app.post("/v1/jobs", &sweep(100)).await, 422).await;
    assert_eq!(huge["type"], problem_type("result-too-large"));
    assert!(huge["detail"].as_str().unwrap().contains("--database"));
}

#[tokio::test]
async fn results_beyond_the_memory_budget_are_kept_on_disk_and_served_from_there() {
    // On disk: the database of saved analyses, a file here.
    let dir = std::env::temp_dir().join(format!("thirdbody-spill-test-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let database = dir.join("thirdbody.db");
    let app = spawn_app(&[
        "--memory-budget",
        "1000000",
        "--database",
        database.to_str().unwrap(),
    ])
    .await;
    let job = sweep(20);
    let location = app.submit(&job).await;
    let view = app
        .wait_for_job(&location, |j| j["status"] == "succeeded")
        .await;
    let answer = app.result(&view).await;
    let whole: Value = app.post_json("/v1/sweeps", &job["input"]).await;
    assert_eq!(answer, whole);
    let url = view["result_url"].as_str().unwrap();
    for (accept, kind) in [("text/csv", "text/csv"), ("image/svg+xml", "image/svg+xml")] {
        let response = app.get_with(url, &[("accept", accept)]).await;
        assert_eq!(response.status(), 200);
        assert!(response.headers()["content-type"]
            .to_str()
            .unwrap()
            .starts_with(kind));
        assert!(response.bytes().await.unwrap().len() > 10_000);
    }
    // Accepted (a database in memory refuses it: the test above), and its result kept in
    // the database file (saved there as the job ends).
    within(async {
        while stored_results(&database, &location) != 1 {
            tokio::time::sleep(std::time::Duration::from_millis(20)).await;
        }
    })
    .await;
    // Deleted, the job's result goes with it.
    app.delete(&location).await;
    assert_eq!(stored_results(&database, &location), 0);
    drop(app);
    std::fs::remove_dir_all(&dir).ok();
}

/// The results the database at `path` holds for the job at `location`.
fn stored_results(path: &std::path::Path, location: &str) -> usize {
    let id = location.rsplit('/').next().unwrap();
    // The service holds the file exclusively: read a copy of it and its log.
    let copy = path.with_extension("copy");
    for (from, to) in [("", ""), ("-wal", "-wal")] {
        let from = format!("{}{from}", path.display());
        if std::path::Path::new(&from).exists() {
            std::fs::copy(&from, format!("{}{to}", copy.display())).unwrap();
        }
    }
    let db = rusqlite::Connection::open(&copy).unwrap();
    let count: i64 = db
        .query_row("SELECT COUNT(*) FROM results WHERE id = ?1", [id], |row| {
            row.get(0)
        })
        .unwrap();
    count as usize
}
