//! The fleet against a real redis-server that fails as real ones do: full, restarted with
//! and without its data, slow, and its processes rolled during a long job. Each fault must be
//! survived (no job lost, synchronous solves still answered) and told truly (`/readyz`, the
//! problems, the status of a job no store knows).

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::{json, Value};

use super::fleet::{
    answering, finished, free_port, fresh_redis, one_service, post, readyz_until, redis_cli,
    redis_server_available, redis_when_up, redis_with, result, rolling_job_finished, serve, start,
    start_redis, submit, submit_rolling, taken_by, Process,
};
use crate::processes::{logs_near, scratch, spawn_logged, thirdbody, PATIENCE};

fn reasons(ready: &Value) -> String {
    ready["reasons"].to_string()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_full_cache_never_fails_a_job_and_a_full_job_store_is_told_truly() {
    // One server in both roles: the answers may take 200 kB of it at most.
    let Some((port, _redis, http, a)) = one_service(&["--redis-cache-bytes", "200000"]).await
    else {
        return;
    };
    for i in 0..60 {
        let body = json!({"load": format!("{} nN", 1.0 + 0.01 * f64::from(i))});
        let solved = post(&http, format!("{}/v1/rolling", a.base), &body).await;
        assert_eq!(solved.status(), 200);
    }
    let total: u64 = redis_cli(port, &["HGET", "thirdbody:answers:sizes", "total"])
        .trim()
        .parse()
        .unwrap();
    assert!(total <= 200_000, "the answers take {total} bytes");
    let kept = redis_cli(port, &["--scan", "--pattern", "thirdbody:answer:*"])
        .lines()
        .count();
    assert!((1..60).contains(&kept), "{kept} answers kept of 60");
    let id = submit(&http, &a.base, json!({"kind": "rolling", "input": {}})).await;
    assert_eq!(finished(&http, &a.base, &id).await["status"], "succeeded");

    // The server at its memory limit: every write is refused.
    redis_cli(port, &["CONFIG", "SET", "maxmemory", "1"]);
    let started = Instant::now();
    let body = json!({"load": "3.3 nN"});
    let solved = post(&http, format!("{}/v1/rolling", a.base), &body).await;
    assert_eq!(solved.status(), 200, "a synchronous solve is answered here");
    assert!(
        started.elapsed() < Duration::from_secs(2),
        "{:?}",
        started.elapsed()
    );
    let refused = post(
        &http,
        format!("{}/v1/jobs", a.base),
        &json!({"kind": "rolling", "input": {"load": "3.5 nN"}}),
    )
    .await;
    assert_eq!(refused.status(), 503);
    let problem: Value = refused.json().await.unwrap();
    let detail = problem["detail"].as_str().unwrap();
    assert!(
        detail.contains("is full") && detail.contains("maxmemory"),
        "{detail}"
    );
    let ready = readyz_until(&http, &a.base, |r| r["status"] == "degraded").await;
    assert!(reasons(&ready).contains("is full"), "{ready}");
    // The job accepted before is still there, whole.
    let view = finished(&http, &a.base, &id).await;
    assert!(result(&http, &a.base, &view).await["friction_coefficient"].is_number());

    // Room again: ready within a second or two, and jobs are taken.
    redis_cli(port, &["CONFIG", "SET", "maxmemory", "0"]);
    readyz_until(&http, &a.base, |r| r["status"] == "ready").await;
    assert_eq!(
        rolling_job_finished(&http, &a.base, &a.base, "3.5 nN").await["status"],
        "succeeded"
    );
}

/// On a 32 MB server holding both roles, the answers take at most half of it whatever
/// `--redis-cache-bytes` says (64 MiB by default): after 40 MB of distinct answers the jobs
/// are still accepted (before, every submission was 503 "Redis (jobs) is full"), and the
/// bound chosen is logged. So on a server that refuses CONFIG, as managed ones do: its
/// limit is read from INFO.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn answers_leave_half_of_a_small_servers_maxmemory_to_the_jobs() {
    if !redis_server_available() {
        eprintln!("SKIPPED: redis-server is not on PATH (`.ci/run` installs it)");
        return;
    }
    for managed in [false, true] {
        let port = free_port();
        let mut args = vec!["--port".to_string(), port.to_string()];
        args.extend(["--maxmemory", "32mb"].map(String::from));
        if managed {
            args.extend(["--rename-command", "CONFIG", ""].map(String::from));
        }
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let _redis = redis_with(port, &args);
        fill_a_small_server(port, managed).await;
    }
}

/// 41 MB of distinct answers on the 32 MB server on `port`, a job submitted after each
/// 0.7 MB: see [`answers_leave_half_of_a_small_servers_maxmemory_to_the_jobs`].
async fn fill_a_small_server(port: u16, managed: bool) {
    let http = reqwest::Client::new();
    let web = free_port();
    let (_serve, logs) = start("serve", port, Some(web), &[]);
    let base = answering(&http, web).await;
    let chosen = "cached answers take at most half of Redis's maxmemory";
    let started = Instant::now();
    while !logs
        .lock()
        .unwrap()
        .iter()
        .any(|line| line.contains(chosen))
    {
        assert!(
            started.elapsed() < Duration::from_secs(20),
            "no bound logged"
        );
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    let logged = logs.lock().unwrap().join("\n");
    assert!(
        logged.contains("maxmemory=33554432") && logged.contains("cache_bytes=16777216"),
        "{logged}"
    );
    // 60 distinct sweeps of 1,000 points: 0.68 MB of JSON each (0.92 MB in Redis, with
    // their CSV), 41 MB in all; a job submitted after each.
    let (mut shared, mut jobs) = (0, Vec::new());
    for k in 0..60 {
        let loads: Vec<String> = (0..50)
            .map(|j| format!("{} nN", 1.0 + 0.01 * f64::from(j) + 0.7 * f64::from(k)))
            .collect();
        let radii: Vec<String> = (0..20).map(|i| format!("{} nm", 20 + i)).collect();
        let body = json!({"vary": {"radius": radii, "load": loads}});
        let solved = post(&http, format!("{base}/v1/sweeps"), &body).await;
        assert_eq!(solved.status(), 200);
        shared += solved.bytes().await.unwrap().len();
        let load = format!("{} nN", 2.0 + 0.01 * f64::from(k));
        let job = json!({"kind": "rolling", "input": {"load": load}});
        jobs.push(submit(&http, &base, job).await);
    }
    assert!(shared > 32 << 20, "{shared} bytes of answers");
    let total: u64 = redis_cli(port, &["HGET", "thirdbody:answers:sizes", "total"])
        .trim()
        .parse()
        .unwrap();
    assert!(total <= 16 << 20, "the answers take {total} bytes");
    // Room to spare: no write was refused (before: 31 MB of 32 used, the server full).
    let memory = redis_cli(port, &["INFO", "memory"]);
    let used: u64 = memory
        .lines()
        .find_map(|line| line.strip_prefix("used_memory:"))
        .and_then(|bytes| bytes.trim().parse().ok())
        .unwrap();
    assert!(
        used < 24 << 20,
        "Redis uses {used} bytes of 32 MB (CONFIG refused: {managed})"
    );
    let logged = logs.lock().unwrap().join("\n");
    assert!(!logged.contains("Redis is full"), "{logged}");
    for id in jobs {
        assert_eq!(finished(&http, &base, &id).await["status"], "succeeded");
    }
}

/// A Redis server on `port` keeping its data in an append-only file in `dir`.
fn start_persisted_redis(port: u16, dir: &std::path::Path) -> Process {
    let child = Command::new("redis-server")
        .args(["--port", &port.to_string(), "--bind", "127.0.0.1"])
        .args([
            "--appendonly",
            "yes",
            "--appendfsync",
            "always",
            "--save",
            "",
        ])
        .arg("--dir")
        .arg(dir)
        .stdout(Stdio::null())
        .spawn()
        .expect("redis-server starts");
    redis_when_up(Process(child), port, || {
        redis_cli(port, &["PING"]).trim() == "PONG"
    })
}

/// Polls `url` (for up to [`PATIENCE`]: the links are checked every half second) until it
/// answers `status`; returns that answer's body.
async fn answered_with(http: &reqwest::Client, url: &str, status: u16) -> Value {
    let start = Instant::now();
    loop {
        let response = http.get(url).send().await.unwrap();
        if response.status() == status {
            return response.json().await.unwrap();
        }
        assert!(
            start.elapsed() < PATIENCE,
            "{url}: still {} after {PATIENCE:?}\n{}",
            response.status(),
            logs_near(url.split("/v1/").next().unwrap())
        );
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
}

/// Stops the Redis server on `port` (saving nothing more) and waits for its process.
fn shut_down_redis(port: u16, mut redis: Process) {
    redis_cli(port, &["SHUTDOWN", "NOSAVE"]);
    let _ = redis.0.wait();
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn jobs_outlive_a_restart_of_a_persisted_store_and_are_told_lost_with_one_that_was_not() {
    if !redis_server_available() {
        eprintln!("SKIPPED: redis-server is not on PATH (`.ci/run` installs it)");
        return;
    }
    let dir = scratch("aof");
    let port = free_port();
    let redis = start_persisted_redis(port, &dir);
    let http = reqwest::Client::new();
    let a = serve(port, &http, &[]).await;
    let id = submit_rolling(&http, &a.base, "1.1 nN").await;
    let view = finished(&http, &a.base, &id).await;
    let before = result(&http, &a.base, &view).await;

    // Restarted with its data: the job and its answer are there.
    shut_down_redis(port, redis);
    let redis = start_persisted_redis(port, &dir);
    let view = answered_with(&http, &format!("{}/v1/jobs/{id}", a.base), 200).await;
    assert_eq!(view["status"], "succeeded");
    assert_eq!(result(&http, &a.base, &view).await, before);

    // Restarted without it: the job is told lost with the store, not "expired".
    shut_down_redis(port, redis);
    std::fs::remove_dir_all(&dir).unwrap();
    let _redis = start_redis(port);
    let problem = answered_with(&http, &format!("{}/v1/jobs/{id}", a.base), 410).await;
    let detail = problem["detail"].as_str().unwrap();
    assert!(detail.contains("restarted without its data"), "{detail}");
    // An id no run of the service issued is told so.
    let never = http
        .get(format!("{}/v1/jobs/{}", a.base, uuid::Uuid::new_v4()))
        .send()
        .await
        .unwrap();
    assert_eq!(never.status(), 404);
    let detail = never.json::<Value>().await.unwrap()["detail"].to_string();
    assert!(detail.contains("no run of this service issued"), "{detail}");
}

/// A TCP proxy to 127.0.0.1:`upstream` that holds every chunk for `delay`, each way (a
/// thread per direction of each connection); returns its port.
fn latency_proxy(upstream: u16, delay: Duration) -> u16 {
    use std::io::{Read, Write};
    let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let port = listener.local_addr().unwrap().port();
    std::thread::spawn(move || {
        for client in listener.incoming().map_while(Result::ok) {
            let Ok(server) = std::net::TcpStream::connect(("127.0.0.1", upstream)) else {
                continue;
            };
            let pairs = [
                (client.try_clone().unwrap(), server.try_clone().unwrap()),
                (server, client),
            ];
            for (mut from, mut to) in pairs {
                std::thread::spawn(move || {
                    let mut buffer = vec![0; 64 << 10];
                    while let Ok(n @ 1..) = from.read(&mut buffer) {
                        std::thread::sleep(delay);
                        if to.write_all(&buffer[..n]).is_err() {
                            break;
                        }
                    }
                    let _ = to.shutdown(std::net::Shutdown::Both);
                });
            }
        }
    });
    port
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_slow_redis_sends_synchronous_solves_to_the_process_and_readyz_says_why() {
    let Some((port, _redis)) = fresh_redis() else {
        return;
    };
    // 100 ms each way: 200 ms a round trip.
    let proxy = latency_proxy(port, Duration::from_millis(100));
    let http = reqwest::Client::new();
    let a = serve(proxy, &http, &[]).await;
    let ready = readyz_until(&http, &a.base, |r| r["redis"]["cache"] == "slow").await;
    assert_eq!(ready["status"], "degraded");
    assert!(reasons(&ready).contains("answers slowly"), "{ready}");
    // A solve that waited on Redis would take a round trip through the proxy, at least
    // 200 ms of its sleeps however idle or busy the machine; one solved in the process takes
    // well under a millisecond of work.
    let round_trip = Duration::from_millis(200);
    for i in 0..5 {
        let body = json!({"load": format!("{} nN", 2.0 + 0.1 * f64::from(i))});
        let started = Instant::now();
        let solved = post(&http, format!("{}/v1/rolling", a.base), &body).await;
        assert_eq!(solved.status(), 200);
        let took = started.elapsed();
        assert!(
            took < round_trip,
            "an uncached solve took {took:?}, as long as a round trip to Redis"
        );
    }
    // Jobs still go through the slow store, and end.
    assert_eq!(
        rolling_job_finished(&http, &a.base, &a.base, "2.9 nN").await["status"],
        "succeeded"
    );
}

/// A sweep on the layer as a continuum: 240 points of ~25 ms, in parts of 20 points.
pub(crate) fn long_sweep() -> Value {
    let speeds: Vec<String> = (0..60)
        .map(|i| format!("{} nm/s", 0.1 + 0.1 * f64::from(i)))
        .collect();
    json!({"kind": "sweep", "input": {
        "base": {"layer": {"model": "continuum"}},
        "vary": {"load": ["1 nN", "1.2 nN", "1.4 nN", "1.6 nN"], "velocity": speeds}}})
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn three_rolling_restarts_during_a_long_job_hand_its_parts_back_and_it_finishes() {
    let Some((port, _redis)) = fresh_redis() else {
        return;
    };
    let http = reqwest::Client::new();
    // One delivery per part: a hand-back charged as a delivery would fail the job.
    let strict = ["--max-deliveries", "1"];
    let a = serve(port, &http, &strict).await;
    let id = submit(&http, &a.base, long_sweep()).await;
    let rolled = ["--shutdown-timeout", "10ms"];
    let mut handed_back = 0;
    let mut logs = Vec::new();
    for _ in 0..3 {
        let (mut worker, log) = start("worker", port, None, &[&strict[..], &rolled[..]].concat());
        taken_by(&log, &id).await;
        let pid = worker.0.id().to_string();
        Command::new("kill").args(["-TERM", &pid]).status().unwrap();
        let status = worker.0.wait().unwrap();
        assert!(status.success(), "the worker drained and exited: {status}");
        handed_back += log
            .lock()
            .unwrap()
            .iter()
            .filter(|l| l.contains("handed a part back"))
            .count();
        logs.push(crate::processes::tail(&log));
    }
    assert!(handed_back >= 1, "no drain interrupted a part");
    let view = finished(&http, &a.base, &id).await;
    assert_eq!(
        view["status"],
        "succeeded",
        "{view}\nworkers' logs:\n{}\n{}",
        logs.join("\n---\n"),
        logs_near(&a.base)
    );
    let answer = result(&http, &a.base, &view).await;
    assert_eq!(answer["points"].as_array().unwrap().len(), 240);
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn no_key_is_left_without_a_time_to_live_after_deletes_and_cancels() {
    let Some((port, _redis, http, a)) = one_service(&[]).await else {
        return;
    };
    let mut ids = Vec::new();
    for _ in 0..6 {
        ids.push(submit(&http, &a.base, long_sweep()).await);
    }
    for (i, id) in ids.iter().enumerate() {
        let url = format!("{}/v1/jobs/{id}", a.base);
        let response = if i % 2 == 0 {
            http.post(format!("{url}/cancel")).send().await.unwrap()
        } else {
            http.delete(url).send().await.unwrap()
        };
        assert_eq!(response.status(), 200);
    }
    // The stream empties as workers find its entries' jobs finished or gone.
    let start = Instant::now();
    while redis_cli(port, &["XLEN", "thirdbody:work"]).trim() != "0" {
        assert!(
            start.elapsed() < PATIENCE,
            "the stream kept its entries for {PATIENCE:?}\n{}",
            logs_near(&a.base)
        );
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    // Owned: the stream (its entries deleted when done) and the store's epoch. Every other
    // key has a time to live once the parts that were running have stopped.
    let owned = ["thirdbody:work", "thirdbody:epoch"];
    let start = Instant::now();
    loop {
        let keys = redis_cli(port, &["--scan", "--pattern", "*"]);
        assert!(keys.lines().any(|k| k.contains(":job:")), "{keys}");
        let forever: Vec<String> = keys
            .lines()
            .filter(|k| !owned.contains(k))
            .filter_map(|key| {
                let ttl: i64 = redis_cli(port, &["PTTL", key]).trim().parse().unwrap();
                (ttl <= 0 && ttl != -2).then(|| format!("{key} ({ttl})"))
            })
            .collect();
        if forever.is_empty() {
            break;
        }
        assert!(
            start.elapsed() < PATIENCE,
            "keys without a time to live for {PATIENCE:?}: {forever:?}\n{}",
            logs_near(&a.base)
        );
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
}

/// Starts `thirdbody serve` alone (no Redis, its database in memory) on a free port; returns
/// its base URL.
async fn serve_alone(http: &reqwest::Client) -> (String, Process) {
    let port = free_port();
    let mut cmd = thirdbody();
    cmd.args(["serve", "--pool-size", "2", "--log-format", "text"])
        .args(["--bind", &format!("127.0.0.1:{port}")]);
    let (process, _) = spawn_logged(
        &mut cmd,
        &format!("serve alone on port {port}"),
        Some(port),
        None,
    );
    (answering(http, port).await, process)
}

/// The JSON and CSV of job `job` run on `base`, as bytes, with the JSON's `ETag`.
async fn job_bytes(http: &reqwest::Client, base: &str, job: &Value) -> (String, Vec<u8>, Vec<u8>) {
    let id = submit(http, base, job.clone()).await;
    let view = finished(http, base, &id).await;
    assert_eq!(view["status"], "succeeded", "{view}");
    let url = format!("{base}{}", view["result_url"].as_str().unwrap());
    let mut etag = String::new();
    let mut forms = Vec::new();
    for accept in ["application/json", "text/csv"] {
        let response = http
            .get(&url)
            .header("accept", accept)
            .send()
            .await
            .unwrap();
        assert_eq!(response.status(), 200);
        if etag.is_empty() {
            etag = response.headers()["etag"].to_str().unwrap().to_string();
        }
        forms.push(response.bytes().await.unwrap().to_vec());
    }
    let csv = forms.pop().unwrap();
    (etag, forms.pop().unwrap(), csv)
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_fleet_answers_every_kind_byte_for_byte_as_one_process_does() {
    let Some((port, _redis, http, fleet)) = one_service(&[]).await else {
        return;
    };
    let _worker = start("worker", port, None, &[]);
    let (alone, _alone) = serve_alone(&http).await;
    let fit: Value = serde_json::from_str(include_str!("../../examples/fit.json")).unwrap();
    let loads: Vec<String> = (0..30)
        .map(|i| format!("{} nN", 1.0 + 0.1 * f64::from(i)))
        .collect();
    let jobs = [
        json!({"kind": "rolling", "input": {"load": "1.3 nN", "velocity": "4 nm/s"}}),
        json!({"kind": "three_body", "input": {"operating": {"total_load": "1 mN"}}}),
        json!({"kind": "sweep", "input": {"vary": {"load": loads, "velocity": ["0 nm/s", "4 nm/s"]}}}),
        json!({"kind": "sweep", "input": {"kind": "three_body",
            "vary": {"total_load": ["0.5 mN", "1 mN", "2 mN"], "velocity": ["1 nm/s", "4 nm/s"]}}}),
        json!({"kind": "figure", "input": {"number": 6}}),
        fit,
    ];
    for job in &jobs {
        // Solved in the fleet (in parts where it splits), then alone; then in the fleet
        // again, answered from the cache at submission.
        let alone = job_bytes(&http, &alone, job).await;
        for round in ["solved", "cached"] {
            let (etag, json, csv) = job_bytes(&http, &fleet.base, job).await;
            let kind = &job["kind"];
            assert_eq!(etag, alone.0, "the ETag of {kind} ({round})");
            assert!(json == alone.1, "the JSON of {kind} differs ({round})");
            assert!(csv == alone.2, "the CSV of {kind} differs ({round})");
        }
    }
}

/// A fleet upgraded over a persisted store reads the jobs the version before finished:
/// their records did not name their result's form, their results are where they were.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_job_finished_by_the_version_before_is_read_with_its_result() {
    let Some((port, _redis, http, a)) = one_service(&[]).await else {
        return;
    };
    let id = uuid::Uuid::new_v4();
    let record = format!("thirdbody:job:{id}");
    let fields = [
        "kind",
        "rolling",
        "work",
        "1",
        "status",
        "succeeded",
        "done",
        "1",
        "key",
        "k",
    ];
    redis_cli(port, &[&["HSET", &record][..], &fields[..]].concat());
    let stored = format!("{record}:result");
    redis_cli(
        port,
        &["HSET", &stored, "json", r#"{"x":1}"#, "csv", "x\n1\n"],
    );
    let view: Value = http
        .get(format!("{}/v1/jobs/{id}", a.base))
        .send()
        .await
        .unwrap()
        .json()
        .await
        .unwrap();
    assert_eq!(view["status"], "succeeded", "{view}");
    assert_eq!(result(&http, &a.base, &view).await, json!({"x": 1}));
}
