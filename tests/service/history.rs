//! Saved analyses: jobs and their results kept across restarts, listed to their owner,
//! found by their input, and forgotten after the history's retention; in the embedded
//! database of a single `thirdbody serve`, and in Redis for a fleet.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use reqwest::{Client, StatusCode};
use serde_json::{json, Value};

use crate::fleet::{
    answering, finished, free_port, fresh_redis, get_json, redis_cli, serve, Process,
};
use crate::fleet_faults::long_sweep;
use crate::json::field_of_each;
use crate::processes::{logs_near, spawn_logged, thirdbody, PATIENCE};

const OWNER: &str = "owner-token-of-the-test-0001";
const OTHER: &str = "another-owner-token-00000002";

/// A directory of the test's own, removed when dropped.
struct TempDir(PathBuf);

impl TempDir {
    fn new(name: &str) -> TempDir {
        let dir = std::env::temp_dir().join(format!("thirdbody-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        TempDir(dir)
    }

    fn database(&self) -> String {
        self.0.join("analyses.db").display().to_string()
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// `thirdbody serve` alone (no Redis) on the database `database`, with `flags`.
async fn single(http: &Client, database: &str, flags: &[&str]) -> (Process, String) {
    let port = free_port();
    let mut cmd = thirdbody();
    cmd.args(["serve", "--bind", &format!("127.0.0.1:{port}")])
        .args(["--database", database, "--log-format", "text"])
        .args(flags);
    let name = format!("serve on port {port} ({database})");
    let (process, _) = spawn_logged(&mut cmd, &name, Some(port), None);
    (process, answering(http, port).await)
}

/// Submits `job` as `owner` (none: anonymous); returns its view.
async fn submit(http: &Client, base: &str, job: &Value, owner: Option<&str>) -> Value {
    let mut request = http.post(format!("{base}/v1/jobs")).json(job);
    if let Some(owner) = owner {
        request = request.header("thirdbody-owner", owner);
    }
    let response = request.send().await.unwrap();
    assert_eq!(response.status(), StatusCode::ACCEPTED);
    response.json().await.unwrap()
}

/// `GET path` on `base` as `owner`: the status and the JSON body.
async fn list(http: &Client, base: &str, path: &str, owner: Option<&str>) -> (StatusCode, Value) {
    let mut request = http.get(format!("{base}{path}"));
    if let Some(owner) = owner {
        request = request.header("thirdbody-owner", owner);
    }
    let response = request.send().await.unwrap();
    (response.status(), response.json().await.unwrap())
}

/// The ids of a page of jobs, in its order.
fn ids(page: &Value) -> Vec<&str> {
    field_of_each(&page["jobs"], "id")
}

/// The body of `GET url` (as `accept`).
async fn body(http: &Client, url: String, accept: &str) -> (StatusCode, String) {
    let response = http.get(url).header("accept", accept).send().await.unwrap();
    (response.status(), response.text().await.unwrap())
}

/// The status and text of job `id`'s view on `base`, asked for as JSON.
async fn job_view(http: &Client, base: &str, id: &str) -> (StatusCode, String) {
    body(http, format!("{base}/v1/jobs/{id}"), "application/json").await
}

fn sweep(loads: &[&str]) -> Value {
    json!({"kind": "sweep", "input": {"base": {"radius": "30 nm"},
        "vary": {"load": loads, "velocity": ["0 nm/s", "5 nm/s"]}}})
}

fn rolling(radius: &str) -> Value {
    json!({"kind": "rolling", "input": {"radius": radius}})
}

/// Sends SIGTERM to `process` and waits (at most `bound`) for it to exit; its exit code.
fn terminate(process: &mut Process, bound: Duration) -> Option<i32> {
    process.sigterm();
    let start = Instant::now();
    loop {
        if let Some(status) = process.0.try_wait().unwrap() {
            return status.code();
        }
        assert!(start.elapsed() < bound, "still draining after {bound:?}");
        std::thread::sleep(Duration::from_millis(20));
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn saved_analyses_outlive_a_restart_of_the_embedded_database() {
    let dir = TempDir::new("history");
    let database = dir.database();
    let http = Client::new();
    let (mut first, base) = single(&http, &database, &[]).await;

    // Another process on the same file is refused at start, saying why.
    let out = thirdbody()
        .args(["serve", "--bind", "127.0.0.1:0", "--database", &database])
        .output()
        .unwrap();
    let said = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        said.contains("another thirdbody process has it open"),
        "{said}"
    );

    let swept = submit(&http, &base, &sweep(&["1 nN", "2 nN"]), Some(OWNER)).await;
    let rolled = submit(&http, &base, &rolling("31 nm"), Some(OWNER)).await;
    let theirs = submit(&http, &base, &rolling("32 nm"), Some(OTHER)).await;
    let anonymous = submit(&http, &base, &rolling("33 nm"), None).await;
    let mut before = Vec::new();
    for view in [&swept, &rolled, &theirs, &anonymous] {
        let id = view["id"].as_str().unwrap();
        let view = finished(&http, &base, id).await;
        assert_eq!(view["status"], "succeeded", "{view}");
        let url = format!("{base}{}", view["result_url"].as_str().unwrap());
        let json = body(&http, url.clone(), "application/json").await;
        let csv = body(&http, url, "text/csv").await;
        before.push((view, json, csv));
    }
    // A long job running when the process is killed.
    let long = submit(&http, &base, &long_sweep(), Some(OWNER)).await;
    let long_id = long["id"].as_str().unwrap().to_string();
    let start = Instant::now();
    while get_json(&http, format!("{base}/v1/jobs/{long_id}")).await["status"] != "running" {
        assert!(
            start.elapsed() < PATIENCE,
            "job {long_id} never ran\n{}",
            logs_near(&base)
        );
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
    first.0.kill().unwrap();
    first.0.wait().unwrap();

    let (mut second, base) = single(&http, &database, &[]).await;
    // Every job and its answer, as they were, by id.
    for (view, json, csv) in &before {
        let id = view["id"].as_str().unwrap();
        let now = get_json(&http, format!("{base}/v1/jobs/{id}")).await;
        assert_eq!(&now, view, "the job's view changed with the restart");
        let url = format!("{base}{}", now["result_url"].as_str().unwrap());
        assert_eq!(&body(&http, url.clone(), "application/json").await, json);
        assert_eq!(&body(&http, url.clone(), "text/csv").await, csv);
        let (status, svg) = body(&http, format!("{url}?format=svg"), "*/*").await;
        assert_eq!(status, StatusCode::OK);
        assert!(svg.starts_with("<svg"), "{svg:.80}");
    }
    // The killed job is told as it ended: interrupted, its result 410.
    let view = get_json(&http, format!("{base}/v1/jobs/{long_id}")).await;
    assert_eq!(view["status"], "interrupted", "{view}");
    let url = format!("{base}/v1/jobs/{long_id}/result");
    assert_eq!(
        body(&http, url, "application/json").await.0,
        StatusCode::GONE
    );

    // Listed to their owner only, newest first, filtered and paged.
    let (status, page) = list(&http, &base, "/v1/jobs", Some(OWNER)).await;
    assert_eq!(status, StatusCode::OK, "{page}");
    let (swept_id, rolled_id) = (
        swept["id"].as_str().unwrap(),
        rolled["id"].as_str().unwrap(),
    );
    assert_eq!(ids(&page), [long_id.as_str(), rolled_id, swept_id]);
    assert_eq!(page["total"], 3);
    assert!(page.get("next").is_none(), "{page}");
    let (_, theirs_page) = list(&http, &base, "/v1/jobs", Some(OTHER)).await;
    assert_eq!(ids(&theirs_page), [theirs["id"].as_str().unwrap()]);
    let (_, sweeps) = list(&http, &base, "/v1/jobs?kind=sweep", Some(OWNER)).await;
    assert_eq!(ids(&sweeps), [long_id.as_str(), swept_id]);
    let (_, ok) = list(&http, &base, "/v1/jobs?status=succeeded", Some(OWNER)).await;
    assert_eq!(ids(&ok), [rolled_id, swept_id]);
    let (_, first_page) = list(&http, &base, "/v1/jobs?limit=2", Some(OWNER)).await;
    assert_eq!(ids(&first_page), [long_id.as_str(), rolled_id]);
    let next = first_page["next"].as_str().unwrap();
    assert_eq!(next, "/v1/jobs?limit=2&offset=2");
    let (_, last_page) = list(&http, &base, next, Some(OWNER)).await;
    assert_eq!(ids(&last_page), [swept_id]);
    assert_eq!(last_page["total"], 3);
    // Nobody lists jobs without saying whose, nor with a bad filter.
    for (path, owner, field) in [
        ("/v1/jobs", None, "header thirdbody-owner"),
        ("/v1/jobs", Some("short"), "header thirdbody-owner"),
        ("/v1/jobs?kind=fits", Some(OWNER), "kind"),
        ("/v1/jobs?status=done", Some(OWNER), "status"),
        ("/v1/jobs?limit=101", Some(OWNER), "limit"),
        (
            "/v1/jobs?status=failed&status=failed",
            Some(OWNER),
            "status",
        ),
    ] {
        let (status, problem) = list(&http, &base, path, owner).await;
        assert_eq!(
            status,
            StatusCode::UNPROCESSABLE_ENTITY,
            "{path}: {problem}"
        );
        assert_eq!(problem["errors"][0]["field"], field, "{problem}");
    }
    // A token refused is not echoed (it may be a secret mistyped).
    let (_, problem) = list(&http, &base, "/v1/jobs", Some("short")).await;
    assert_eq!(problem["errors"][0]["value"], "(5 characters)", "{problem}");
    assert!(!problem.to_string().contains("short"), "{problem}");

    // An owned job is cancelled or deleted by its owner only (its link may be shared).
    let rolled_url = format!("{base}/v1/jobs/{rolled_id}");
    for owner in [None, Some(OTHER)] {
        for request in [
            http.delete(&rolled_url),
            http.post(format!("{rolled_url}/cancel")),
        ] {
            let request = match owner {
                Some(owner) => request.header("thirdbody-owner", owner),
                None => request,
            };
            let response = request.send().await.unwrap();
            assert_eq!(response.status(), StatusCode::FORBIDDEN);
        }
    }
    assert_eq!(get_json(&http, rolled_url).await["status"], "succeeded");

    // The input's stable link answers from the database (the cache went with the process).
    let hash = before[0].0["input_hash"].as_str().unwrap();
    let by_input = format!("{base}/v1/results/{hash}");
    assert_eq!(
        body(&http, by_input.clone(), "application/json").await,
        before[0].1
    );
    let unknown = format!("{base}/v1/results/{}", "0".repeat(64));
    assert_eq!(
        body(&http, unknown, "application/json").await.0,
        StatusCode::NOT_FOUND
    );

    // Deleted by its owner: gone from the list, its URL and its input's link.
    let deleted = http
        .delete(format!("{base}/v1/jobs/{swept_id}"))
        .header("thirdbody-owner", OWNER)
        .send()
        .await
        .unwrap();
    assert_eq!(deleted.status(), StatusCode::OK);
    let (_, page) = list(&http, &base, "/v1/jobs", Some(OWNER)).await;
    assert_eq!(ids(&page), [long_id.as_str(), rolled_id]);
    let gone = job_view(&http, &base, swept_id).await;
    assert_eq!(gone.0, StatusCode::NOT_FOUND, "{}", gone.1);
    assert!(gone.1.contains("deleted, or it expired"), "{}", gone.1);
    assert_eq!(
        body(&http, by_input, "application/json").await.0,
        StatusCode::NOT_FOUND
    );

    // A job read finished before a graceful stop is there after the restart.
    let read = submit(&http, &base, &rolling("34 nm"), Some(OWNER)).await;
    let read_id = read["id"].as_str().unwrap().to_string();
    assert_eq!(
        finished(&http, &base, &read_id).await["status"],
        "succeeded"
    );
    assert_eq!(terminate(&mut second, PATIENCE), Some(0));
    let (_third, base) = single(&http, &database, &[]).await;
    let view = get_json(&http, format!("{base}/v1/jobs/{read_id}")).await;
    assert_eq!(view["status"], "succeeded", "{view}");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_embedded_history_forgets_jobs_past_its_retention() {
    let dir = TempDir::new("retention");
    let database = dir.database();
    let http = Client::new();
    // A history long beside a stall of a loaded machine between two requests: the job is
    // read from it once out of memory, however late that read comes.
    let history = Duration::from_secs(10);
    let flags = ["--history-retention", "10s", "--job-retention", "1s"];
    let (_service, base) = single(&http, &database, &flags).await;
    let submitted = Instant::now();
    let view = submit(&http, &base, &rolling("35 nm"), Some(OWNER)).await;
    let id = view["id"].as_str().unwrap();
    assert_eq!(finished(&http, &base, id).await["status"], "succeeded");
    let ended = Instant::now();
    // Out of memory after a second, still in the database.
    tokio::time::sleep(Duration::from_millis(1300)).await;
    assert_eq!(
        get_json(&http, format!("{base}/v1/jobs/{id}")).await["status"],
        "succeeded"
    );
    let (_, page) = list(&http, &base, "/v1/jobs", Some(OWNER)).await;
    assert_eq!(page["total"], 1);
    assert!(
        submitted.elapsed() < history,
        "the reads came {:?} after the submission, past the history's retention",
        submitted.elapsed()
    );
    // Past the history's retention (counted from the job's end, before `ended`): forgotten.
    let past =
        (ended + history + Duration::from_millis(300)).saturating_duration_since(Instant::now());
    tokio::time::sleep(past).await;
    let (_, page) = list(&http, &base, "/v1/jobs", Some(OWNER)).await;
    assert_eq!(page["total"], 0, "{page}");
    let gone = job_view(&http, &base, id).await;
    assert_eq!(gone.0, StatusCode::NOT_FOUND, "{}", gone.1);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_fleets_history_outlives_its_processes_and_expires_in_redis() {
    let Some((redis, _redis)) = fresh_redis() else {
        return;
    };
    let http = Client::new();
    let flags = ["--history-retention", "6s"];
    let service = serve(redis, &http, &flags).await;
    let kept = submit(&http, &service.base, &sweep(&["1 nN", "3 nN"]), Some(OWNER)).await;
    let dropped = submit(&http, &service.base, &rolling("36 nm"), Some(OWNER)).await;
    let theirs = submit(&http, &service.base, &rolling("37 nm"), Some(OTHER)).await;
    let (kept_id, dropped_id) = (
        kept["id"].as_str().unwrap(),
        dropped["id"].as_str().unwrap(),
    );
    let mut answers = Vec::new();
    for id in [kept_id, dropped_id, theirs["id"].as_str().unwrap()] {
        let view = finished(&http, &service.base, id).await;
        assert_eq!(view["status"], "succeeded", "{view}");
        let url = format!("{}{}", service.base, view["result_url"].as_str().unwrap());
        answers.push(body(&http, url, "text/csv").await);
    }
    drop(service);

    // Another process of the fleet, started after the first stopped, lists and answers.
    let service = serve(redis, &http, &flags).await;
    let base = &service.base;
    let (_, page) = list(&http, base, "/v1/jobs", Some(OWNER)).await;
    assert_eq!(ids(&page), [dropped_id, kept_id]);
    let (_, sweeps) = list(
        &http,
        base,
        "/v1/jobs?kind=sweep&status=succeeded",
        Some(OWNER),
    )
    .await;
    assert_eq!(ids(&sweeps), [kept_id]);
    let (_, first) = list(&http, base, "/v1/jobs?limit=1", Some(OWNER)).await;
    assert_eq!(first["next"], "/v1/jobs?limit=1&offset=1");
    let url = format!("{base}/v1/jobs/{kept_id}/result");
    assert_eq!(body(&http, url, "text/csv").await, answers[0]);
    let hash = kept["input_hash"].as_str().unwrap();
    let by_input = body(&http, format!("{base}/v1/results/{hash}"), "text/csv").await;
    assert_eq!(by_input, answers[0]);

    // Deleted: out of its owner's list, and its input's pointer gone.
    let dropped_hash = dropped["input_hash"].as_str().unwrap();
    assert_eq!(
        redis_cli(redis, &["GET", &format!("thirdbody:input:{dropped_hash}")]).trim(),
        dropped_id
    );
    http.delete(format!("{base}/v1/jobs/{dropped_id}"))
        .header("thirdbody-owner", OWNER)
        .send()
        .await
        .unwrap();
    let (_, page) = list(&http, base, "/v1/jobs", Some(OWNER)).await;
    assert_eq!(ids(&page), [kept_id]);
    assert_eq!(
        redis_cli(
            redis,
            &["EXISTS", &format!("thirdbody:input:{dropped_hash}")]
        )
        .trim(),
        "0"
    );
    // Every key of the history expires with it.
    let keys = redis_cli(redis, &["--scan", "--pattern", "thirdbody:*"]);
    for key in keys.lines().filter(|k| {
        ["thirdbody:job:", "thirdbody:owner:", "thirdbody:input:"]
            .iter()
            .any(|p| k.starts_with(p))
    }) {
        let ttl: i64 = redis_cli(redis, &["PTTL", key]).trim().parse().unwrap();
        assert!(ttl > 0, "{key} has no expiry ({ttl})");
    }

    // Past the retention, Redis forgot them: not listed, not found.
    tokio::time::sleep(Duration::from_millis(6500)).await;
    let (_, page) = list(&http, base, "/v1/jobs", Some(OWNER)).await;
    assert_eq!(page["total"], 0, "{page}");
    let gone = job_view(&http, base, kept_id).await;
    assert_eq!(gone.0, StatusCode::NOT_FOUND, "{}", gone.1);
}
