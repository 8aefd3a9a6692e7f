//! API keys on the binary: keys made by `thirdbody new-key`, their file read again without a
//! restart (a key added, rotated, revoked), and tenants in a fleet whose Redis asks for a
//! password (AUTH): a job belongs to its key's tenant in every process of the fleet.

use std::time::{Duration, Instant};

use reqwest::{Client, StatusCode};
use serde_json::{json, Value};

use crate::fleet::{
    answering, finished, free_port, fresh_redis, get_json, heavy_sweep, metric_in,
    redis_server_available, redis_with, start, submit, taken_by, text_of, Process,
};
use crate::processes::{logs_near, scratch, spawn_logged, thirdbody, PATIENCE};

/// `thirdbody new-key` with `args`: the key and its entry.
fn new_key(args: &[&str]) -> (String, Value) {
    let out = thirdbody().arg("new-key").args(args).output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    let mut lines = text.lines();
    let key = lines.next().unwrap().to_string();
    let entry = serde_json::from_str(lines.next().unwrap()).unwrap();
    (key, entry)
}

fn write_keys(path: &std::path::Path, entries: &[&Value]) {
    // Written whole then renamed, as an operator's tooling (or a Secret's update) does.
    let partial = path.with_extension("partial");
    std::fs::write(&partial, json!({ "keys": entries }).to_string()).unwrap();
    std::fs::rename(&partial, path).unwrap();
}

/// `GET url` with `key`, read as JSON.
async fn read(http: &Client, url: &str, key: &str) -> Value {
    let response = http.get(url).header("x-api-key", key).send().await.unwrap();
    response.json().await.unwrap()
}

async fn status(http: &Client, url: &str, key: &str) -> StatusCode {
    http.get(url)
        .header("x-api-key", key)
        .send()
        .await
        .unwrap()
        .status()
}

/// Polls until `url` answers `expected` to `key` (the file is read again every second).
async fn until(http: &Client, url: &str, key: &str, expected: StatusCode) {
    let start = Instant::now();
    while status(http, url, key).await != expected {
        assert!(
            start.elapsed() < PATIENCE,
            "{url} never answered {expected} to {key}\n{}",
            logs_near(url)
        );
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
}

/// Two `serve` processes of a fleet on `redis`, with `flags`: the processes, their URLs.
async fn two_services(http: &Client, redis: u16, flags: &[&str]) -> ([Process; 2], [String; 2]) {
    let ports = [free_port(), free_port()];
    let processes = ports.map(|port| start("serve", redis, Some(port), flags).0);
    let one = answering(http, ports[0]).await;
    let two = answering(http, ports[1]).await;
    (processes, [one, two])
}

#[test]
fn new_key_refuses_what_the_service_would_refuse() {
    for (args, needle) in [
        (&["--name", "a b"][..], "name: allowed"),
        (
            &["--name", "lab", "--scopes", "write"],
            "unknown scope \"write\"",
        ),
        (
            &["--name", "lab", "--expires", "tomorrow"],
            "expires \"tomorrow\"",
        ),
    ] {
        let out = thirdbody().arg("new-key").args(args).output().unwrap();
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let error = String::from_utf8_lossy(&out.stderr);
        assert!(error.contains(needle), "{args:?}: {error}");
    }
}

#[test]
fn new_key_appends_its_entry_to_the_keys_file_and_prints_the_key_alone() {
    use sha2::{Digest, Sha256};
    let dir = scratch("append");
    let file = dir.join("keys.json");
    let append = |name: &str| {
        let out = thirdbody()
            .args([
                "new-key",
                "--name",
                name,
                "--append",
                file.to_str().unwrap(),
            ])
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let text = String::from_utf8(out.stdout).unwrap();
        assert_eq!(text.lines().count(), 1, "{text}");
        text.trim().to_string()
    };
    // Made when absent, then added to.
    let keys = [append("lab-a"), append("lab-b")];
    let written: Value = serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap();
    let entries = written["keys"].as_array().unwrap();
    assert_eq!(entries.len(), 2);
    for ((entry, key), name) in entries.iter().zip(&keys).zip(["lab-a", "lab-b"]) {
        assert_eq!(entry["name"], name);
        let hash: String = Sha256::digest(key.as_bytes())
            .iter()
            .map(|b| format!("{b:02x}"))
            .collect();
        assert_eq!(entry["sha256"], hash.as_str());
    }
    // A file `serve` would refuse is left as it is.
    std::fs::write(&file, "{\"keys\": 3}").unwrap();
    let out = thirdbody()
        .args(["new-key", "--name", "c", "--append", file.to_str().unwrap()])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(std::fs::read_to_string(&file).unwrap(), "{\"keys\": 3}");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn keys_are_added_rotated_and_revoked_without_a_restart() {
    let dir = scratch("keys");
    let file = dir.join("keys.json");
    let (old, old_entry) = new_key(&["--name", "lab-a"]);
    let (ops, ops_entry) = new_key(&["--name", "ops", "--scopes", "admin"]);
    write_keys(&file, &[&old_entry, &ops_entry]);

    let port = free_port();
    let (_service, _) = spawn_logged(
        thirdbody()
            .args(["serve", "--bind", &format!("127.0.0.1:{port}")])
            .args(["--database", ":memory:", "--anonymous", "none"])
            .args(["--api-keys", file.to_str().unwrap(), "--log-format", "text"]),
        &format!("serve on port {port}"),
        Some(port),
        None,
    );
    let http = Client::new();
    let base = answering(&http, port).await;
    let docs = format!("{base}/openapi.json");
    assert_eq!(status(&http, &docs, &old).await, StatusCode::OK);

    // A job of lab-a's, submitted with the old key.
    let request = http
        .post(format!("{base}/v1/jobs"))
        .header("x-api-key", &old);
    let response = request
        .json(&json!({"kind": "rolling", "input": {}}))
        .send();
    let submitted: Value = response.await.unwrap().json().await.unwrap();
    let job = format!("{base}/v1/jobs/{}", submitted["id"].as_str().unwrap());

    // Rotation: a new key of the same name added, then the old one removed.
    let (new, new_entry) = new_key(&["--name", "lab-a"]);
    write_keys(&file, &[&old_entry, &new_entry, &ops_entry]);
    until(&http, &job, &new, StatusCode::OK).await;
    assert_eq!(status(&http, &job, &old).await, StatusCode::OK);
    write_keys(&file, &[&new_entry, &ops_entry]);
    until(&http, &docs, &old, StatusCode::UNAUTHORIZED).await;
    // The tenant's job is the new key's: listed to it.
    let page = read(&http, &format!("{base}/v1/jobs"), &new).await;
    assert_eq!(page["jobs"][0]["id"], submitted["id"], "{page}");

    // A broken file leaves the keys as they were, and /readyz says so.
    std::fs::write(&file, "{\"keys\": [").unwrap();
    tokio::time::sleep(Duration::from_millis(1500)).await;
    assert_eq!(status(&http, &docs, &new).await, StatusCode::OK);
    let ready = get_json(&http, format!("{base}/readyz")).await;
    assert_eq!(ready["status"], "degraded", "{ready}");
    assert!(
        ready["reasons"][0]
            .as_str()
            .unwrap()
            .contains("is not valid"),
        "{ready}"
    );
    // An admin key revoked; then the file removed: no key is accepted.
    write_keys(&file, &[&new_entry]);
    until(&http, &docs, &ops, StatusCode::UNAUTHORIZED).await;
    assert_eq!(
        get_json(&http, format!("{base}/readyz")).await["status"],
        "ready"
    );
    std::fs::remove_file(&file).unwrap();
    until(&http, &docs, &new, StatusCode::UNAUTHORIZED).await;
    let _ = std::fs::remove_dir_all(&dir);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn tenants_hold_across_a_fleet_on_a_redis_with_a_password() {
    if !redis_server_available() {
        eprintln!("SKIPPED: redis-server is not on PATH (`.ci/run` installs it)");
        return;
    }
    const PASSWORD: &str = "s3cret-of-the-fleet";
    let redis = free_port();
    let _redis = redis_with(
        redis,
        &["--port", &redis.to_string(), "--requirepass", PASSWORD],
    );
    let (a, a_entry) = new_key(&["--name", "lab-a"]);
    let (b, b_entry) = new_key(&["--name", "lab-b"]);
    let (ops, ops_entry) = new_key(&["--name", "ops", "--scopes", "admin"]);
    let keys = json!({"keys": [a_entry, b_entry, ops_entry]}).to_string();
    let http = Client::new();
    let url = format!("redis://:{PASSWORD}@127.0.0.1:{redis}");
    let flags = ["--redis-url", url.as_str(), "--api-keys", keys.as_str()];
    let (one_port, two_port) = (free_port(), free_port());
    let (_one, one_log) = start("serve", redis, Some(one_port), &flags);
    let (_two, two_log) = start("serve", redis, Some(two_port), &flags);
    let one = answering(&http, one_port).await;
    let two = answering(&http, two_port).await;

    // lab-a's sweep, submitted to one process, runs on the fleet and is read from the other.
    let sweep = json!({"kind": "sweep", "input": {"base": {"radius": "30 nm"},
        "vary": {"load": ["1 nN", "2 nN", "3 nN"]}}});
    let response = http
        .post(format!("{one}/v1/jobs"))
        .header("authorization", format!("Bearer {a}"))
        .json(&sweep)
        .send()
        .await
        .unwrap();
    assert_eq!(response.status(), StatusCode::ACCEPTED);
    let id = response.json::<Value>().await.unwrap()["id"]
        .as_str()
        .unwrap()
        .to_string();
    let job = format!("{two}/v1/jobs/{id}");
    let start_at = Instant::now();
    loop {
        let view = read(&http, &job, &a).await;
        if view["status"] == "succeeded" {
            break;
        }
        assert!(start_at.elapsed() < PATIENCE, "{view}\n{}", logs_near(&job));
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    assert_eq!(
        status(&http, &format!("{job}/result"), &a).await,
        StatusCode::OK
    );
    // Not lab-b's, on either process; the admin's on both.
    for base in [&one, &two] {
        let url = format!("{base}/v1/jobs/{id}");
        assert_eq!(status(&http, &url, &b).await, StatusCode::NOT_FOUND);
        assert_eq!(
            status(&http, &format!("{url}/result"), &b).await,
            StatusCode::NOT_FOUND
        );
        assert_eq!(status(&http, &url, &ops).await, StatusCode::OK);
        let listed = read(&http, &format!("{base}/v1/jobs?tenant=lab-a"), &ops).await;
        assert_eq!(listed["jobs"][0]["id"], id.as_str(), "{listed}");
    }
    let deleted = http
        .delete(&job)
        .header("x-api-key", &b)
        .send()
        .await
        .unwrap();
    assert_eq!(deleted.status(), StatusCode::NOT_FOUND);

    // The password is in no log line; a wrong one is told, without it.
    for log in [&one_log, &two_log] {
        assert!(log
            .lock()
            .unwrap()
            .iter()
            .all(|line| !line.contains(PASSWORD)));
    }
    let wrong = format!("redis://:not-{PASSWORD}@127.0.0.1:{redis}");
    let port = free_port();
    let (_three, three_log) = start("serve", redis, Some(port), &["--redis-url", &wrong]);
    let three = answering(&http, port).await;
    let start_at = Instant::now();
    // Each role's link finds the refusal on its own probe: wait for both.
    let ready = loop {
        let ready = get_json(&http, format!("{three}/readyz")).await;
        let denied = ["cache", "jobs"].map(|role| ready["redis"][role] == "denied");
        if denied == [true; 2] || start_at.elapsed() > PATIENCE {
            break ready;
        }
        tokio::time::sleep(Duration::from_millis(100)).await;
    };
    assert_eq!(ready["status"], "degraded", "{ready}");
    assert_eq!(ready["redis"]["cache"], "denied", "{ready}");
    assert_eq!(ready["redis"]["jobs"], "denied", "{ready}");
    let reasons = ready["reasons"].to_string();
    assert!(
        reasons.contains("refuses this process's credentials"),
        "{reasons}"
    );
    assert!(!reasons.contains(PASSWORD), "{reasons}");
    let refused = http
        .post(format!("{three}/v1/jobs"))
        .json(&sweep)
        .send()
        .await
        .unwrap();
    assert_eq!(refused.status(), StatusCode::SERVICE_UNAVAILABLE);
    let problem = refused.text().await.unwrap();
    assert!(
        problem.contains("credentials") && !problem.contains(PASSWORD),
        "{problem}"
    );
    assert!(three_log
        .lock()
        .unwrap()
        .iter()
        .all(|line| !line.contains(PASSWORD)));
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_tenants_points_are_counted_once_for_the_whole_fleet() {
    let Some((redis, _redis)) = crate::fleet::fresh_redis() else {
        return;
    };
    let (key, entry) = new_key(&["--name", "lab-a"]);
    let keys = json!({"keys": [entry]}).to_string();
    let flags = ["--api-keys", keys.as_str(), "--quota-points", "3"];
    let http = Client::new();
    let (_fleet, [one, two]) = two_services(&http, redis, &flags).await;
    // Early in a minute: the count is per minute.
    crate::clock::early_in_a_minute().await;
    let solve = |base: &String, radius: &str| {
        http.post(format!("{base}/v1/rolling"))
            .header("x-api-key", &key)
            .json(&json!({"radius": radius}))
            .send()
    };
    for (base, radius) in [(&one, "20 nm"), (&two, "21 nm"), (&one, "22 nm")] {
        assert_eq!(solve(base, radius).await.unwrap().status(), StatusCode::OK);
    }
    for base in [&one, &two] {
        let refused = solve(base, "23 nm").await.unwrap();
        assert_eq!(refused.status(), StatusCode::TOO_MANY_REQUESTS);
        assert!(refused.headers().contains_key("retry-after"));
    }
    // The count lives as long as its minute and the next.
    let keys = crate::fleet::redis_cli(redis, &["--scan", "--pattern", "thirdbody:quota:*"]);
    let counted = keys.lines().next().expect("a count in Redis");
    assert!(
        counted.starts_with("thirdbody:quota:key:lab-a:"),
        "{counted}"
    );
    assert_eq!(
        crate::fleet::redis_cli(redis, &["GET", counted]).trim(),
        "3"
    );
    let ttl: i64 = crate::fleet::redis_cli(redis, &["TTL", counted])
        .trim()
        .parse()
        .unwrap();
    assert!((1..=120).contains(&ttl), "{ttl}");
}

/// A tenant's answers held are counted from the records in Redis: a job kept by one
/// process counts in the other.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_worker_serves_its_metrics_and_probes_to_whom_the_keys_allow() {
    let Some((redis, _redis)) = fresh_redis() else {
        return;
    };
    let (scraper, scraper_entry) = new_key(&["--name", "prometheus", "--scopes", "metrics"]);
    let (lab, lab_entry) = new_key(&["--name", "lab"]);
    let keys = json!({"keys": [scraper_entry, lab_entry]}).to_string();
    let access = ["--api-keys", keys.as_str(), "--anonymous", "submit,read"];
    let (ops_port, port) = (free_port(), free_port());
    let bind = format!("127.0.0.1:{ops_port}");
    let worker_flags = [&access[..], &["--metrics-bind", bind.as_str()]].concat();
    let (_worker, log) = start("worker", redis, None, &worker_flags);
    let (_service, _) = start("serve", redis, Some(port), &access);
    let http = Client::new();
    let worker = answering(&http, ops_port).await;
    let base = answering(&http, port).await;
    let ready = get_json(&http, format!("{worker}/readyz")).await;
    assert_eq!(ready["status"], "ready", "{ready}");

    let metrics = format!("{worker}/metrics");
    let anonymous = http.get(&metrics).send().await.unwrap();
    assert_eq!(anonymous.status(), StatusCode::UNAUTHORIZED);
    assert_eq!(status(&http, &metrics, &lab).await, StatusCode::FORBIDDEN);
    let id = submit(&http, &base, heavy_sweep()).await;
    taken_by(&log, &id).await;
    assert_eq!(finished(&http, &base, &id).await["status"], "succeeded");
    let text = text_of(http.get(&metrics).header("x-api-key", &scraper)).await;
    let solved = metric_in(&text, "thirdbody_parts_total", "succeeded");
    assert!(solved >= 1.0, "{text}");
    // Nothing else is served there: the API is the replicas'.
    let elsewhere = format!("{worker}/v1/jobs/{id}");
    assert_eq!(status(&http, &elsewhere, &lab).await, StatusCode::NOT_FOUND);
}
