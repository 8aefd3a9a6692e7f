//! Several processes on one real Redis (`redis-server` from the machine's packages: `.ci/run`
//! installs it; without it these tests say they were skipped): two `thirdbody serve` and one
//! `thirdbody worker`, as `deploy/compose.yaml` runs them.

use std::net::TcpListener;
use std::process::{Command, Stdio};
use std::sync::Arc;
use std::time::{Duration, Instant};

use serde_json::{json, Value};

pub(crate) use crate::processes::Process;
use crate::processes::{exited, logs_near, spawn_logged, tail, thirdbody, Log, PATIENCE, STALL};

pub(crate) fn free_port() -> u16 {
    TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port()
}

pub(crate) fn redis_server_available() -> bool {
    Command::new("redis-server")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success())
}

/// A Redis server on `port`, without persistence.
pub(crate) fn start_redis(port: u16) -> Process {
    redis_with(port, &["--port", &port.to_string()])
}

/// A redis-server on loopback without persistence, with `args` (its ports among them), once
/// it accepts connections on `port`.
pub(crate) fn redis_with(port: u16, args: &[&str]) -> Process {
    let child = Command::new("redis-server")
        .args(["--bind", "127.0.0.1", "--save", "", "--appendonly", "no"])
        .args(args)
        .stdout(Stdio::null())
        .spawn()
        .expect("redis-server starts");
    redis_when_up(Process(child), port, || {
        std::net::TcpStream::connect(("127.0.0.1", port)).is_ok()
    })
}

/// The redis-server `redis` on `port`, once `up` says it answers; fails if it exits first
/// or is not up within [`PATIENCE`].
pub(crate) fn redis_when_up(mut redis: Process, port: u16, up: impl Fn() -> bool) -> Process {
    let start = Instant::now();
    while !up() {
        if let Some(status) = redis.0.try_wait().unwrap() {
            panic!("redis-server on port {port} exited: {status}");
        }
        assert!(
            start.elapsed() < PATIENCE,
            "redis-server did not start on port {port} in {PATIENCE:?}"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    redis
}

/// A Redis server of its own on a free port; `None` (the test saying it is skipped) when
/// redis-server is not installed.
pub(crate) fn fresh_redis() -> Option<(u16, Process)> {
    if !redis_server_available() {
        eprintln!("SKIPPED: redis-server is not on PATH (`.ci/run` installs it)");
        return None;
    }
    let port = free_port();
    Some((port, start_redis(port)))
}

pub(crate) fn redis_cli(port: u16, args: &[&str]) -> String {
    let out = Command::new("redis-cli")
        .args(["-p", &port.to_string()])
        .args(args)
        .output()
        .expect("redis-cli runs");
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// Starts `thirdbody <command>` on the fleet of Redis `redis` (its database of saved
/// analyses in memory unless `flags` name one); its log lines are collected.
pub(crate) fn start(
    command: &str,
    redis: u16,
    port: Option<u16>,
    flags: &[&str],
) -> (Process, Log) {
    let mut cmd = thirdbody();
    let url = format!("redis://127.0.0.1:{redis}");
    let default_url = ["--redis-url", url.as_str()];
    cmd.arg(command)
        // Unless the test names it (with a password, say).
        .args(if flags.contains(&"--redis-url") {
            &[][..]
        } else {
            &default_url[..]
        })
        .args(["--log-format", "text"])
        .args(["--pool-size", "2"])
        .env("RUST_LOG", "info")
        .args(flags);
    if let Some(port) = port {
        cmd.args(["--bind", &format!("127.0.0.1:{port}")]);
    }
    let name = match port {
        Some(port) => format!("{command} on port {port}"),
        None => command.to_string(),
    };
    spawn_logged(&mut cmd, &name, port, Some(redis))
}

pub(crate) struct Service {
    pub base: String,
    _process: Process,
}

/// Waits until a service answers on `port` (failing at once if its process exits, or after
/// [`PATIENCE`]); returns its base URL.
pub(crate) async fn answering(http: &reqwest::Client, port: u16) -> String {
    let base = format!("http://127.0.0.1:{port}");
    let start = Instant::now();
    while http.get(format!("{base}/healthz")).send().await.is_err() {
        let gone = exited(port);
        assert!(
            !gone && start.elapsed() < PATIENCE,
            "the service on port {port} {}\n{}",
            if gone {
                "exited before it answered"
            } else {
                "did not answer /healthz"
            },
            logs_near(&base)
        );
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    base
}

pub(crate) async fn serve(redis: u16, http: &reqwest::Client, flags: &[&str]) -> Service {
    let port = free_port();
    let (process, _) = start("serve", redis, Some(port), flags);
    let base = answering(http, port).await;
    Service {
        base,
        _process: process,
    }
}

/// A fresh Redis and one `serve` with `flags` on it, with a client; `None` (the test
/// saying it is skipped) when redis-server is not installed.
pub(crate) async fn one_service(
    flags: &[&str],
) -> Option<(u16, Process, reqwest::Client, Service)> {
    let (port, redis) = fresh_redis()?;
    let http = reqwest::Client::new();
    let service = serve(port, &http, flags).await;
    Some((port, redis, http, service))
}

/// The value of the metric `name` (summed over its label sets matching `filter`).
pub(crate) async fn metric(http: &reqwest::Client, base: &str, name: &str, filter: &str) -> f64 {
    let text = text_of(http.get(format!("{base}/metrics"))).await;
    metric_in(&text, name, filter)
}

/// The body of the answer to `request`, as text.
pub(crate) async fn text_of(request: reqwest::RequestBuilder) -> String {
    request.send().await.unwrap().text().await.unwrap()
}

/// The sum of the samples of `name` whose line holds `filter`, in the exposition `text`.
pub(crate) fn metric_in(text: &str, name: &str, filter: &str) -> f64 {
    text.lines()
        .filter(|l| l.starts_with(name) && l.contains(filter))
        .filter_map(|l| l.rsplit(' ').next()?.parse::<f64>().ok())
        .sum()
}

pub(crate) async fn post(http: &reqwest::Client, url: String, body: &Value) -> reqwest::Response {
    http.post(url).json(body).send().await.unwrap()
}

pub(crate) async fn get_json(http: &reqwest::Client, url: String) -> Value {
    http.get(url).send().await.unwrap().json().await.unwrap()
}

/// The answer of a finished job (its view links to it), read from `base`.
pub(crate) async fn result(http: &reqwest::Client, base: &str, view: &Value) -> Value {
    assert!(
        view.get("result").is_none(),
        "a job's view carries no answer: {view}"
    );
    let url = view["result_url"].as_str().expect("the job has a result");
    get_json(http, format!("{base}{url}")).await
}

/// Polls job `id` on `base` until it finished; returns its view. Waits as long as the job
/// moves (its status or its count of points done changes at least every [`STALL`]), and
/// otherwise fails saying where it stood and what the fleet's processes logged.
pub(crate) async fn finished(http: &reqwest::Client, base: &str, id: &str) -> Value {
    let start = Instant::now();
    let (mut seen, mut moved) = (Value::Null, Instant::now());
    loop {
        let view = get_json(http, format!("{base}/v1/jobs/{id}")).await;
        if !matches!(view["status"].as_str(), Some("queued" | "running")) {
            return view;
        }
        let now = json!([view["status"], view["progress"]]);
        if now != seen {
            (seen, moved) = (now, Instant::now());
        }
        assert!(
            moved.elapsed() < STALL,
            "job {id} made no progress in {STALL:?} ({:.0?} since it was polled first): \
             status {}, progress {} (done/total); its view: {view}\n{}",
            start.elapsed(),
            view["status"],
            view["progress"],
            logs_near(base)
        );
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
}

/// Waits (up to [`PATIENCE`]: the links are checked every half second) until `/readyz` on
/// `base` satisfies `ok`; returns its answer.
pub(crate) async fn readyz_until(
    http: &reqwest::Client,
    base: &str,
    ok: impl Fn(&Value) -> bool,
) -> Value {
    let start = Instant::now();
    loop {
        let ready = get_json(http, format!("{base}/readyz")).await;
        if ok(&ready) {
            return ready;
        }
        assert!(
            start.elapsed() < PATIENCE,
            "readyz stayed {ready} for {PATIENCE:?}\n{}",
            logs_near(base)
        );
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
}

/// Waits until the process whose log is `log` is solving a part of job `id`.
pub(crate) async fn taken_by(log: &Log, id: &str) {
    let start = Instant::now();
    let taken = |l: &String| l.contains("solving a part") && l.contains(id);
    while !log.lock().unwrap().iter().any(taken) {
        assert!(
            start.elapsed() < PATIENCE,
            "the worker took no part of job {id} in {PATIENCE:?}; its log ends:\n{}",
            tail(log)
        );
        tokio::time::sleep(Duration::from_millis(5)).await;
    }
}

/// A sweep of 2,000 points with a fine rule, parts long enough to kill a worker in one.
pub(crate) fn heavy_sweep() -> Value {
    let loads: Vec<String> = (0..40)
        .map(|i| format!("{} nN", 1.0 + 0.05 * f64::from(i)))
        .collect();
    let speeds: Vec<String> = (0..50).map(|i| format!("{} nm/s", f64::from(i))).collect();
    json!({"kind": "sweep", "input": {
        "base": {"options": {"strips": 1024}},
        "vary": {"load": loads, "velocity": speeds}}})
}

/// Submits a rolling job at `load` to `submit_to` and polls it on `read_from` (the same
/// service or another of the fleet) until it finished; returns its view.
pub(crate) async fn rolling_job_finished(
    http: &reqwest::Client,
    submit_to: &str,
    read_from: &str,
    load: &str,
) -> Value {
    let id = submit_rolling(http, submit_to, load).await;
    finished(http, read_from, &id).await
}

/// Submits a rolling job at `load` to `base`; returns its id.
pub(crate) async fn submit_rolling(http: &reqwest::Client, base: &str, load: &str) -> String {
    let job = json!({"kind": "rolling", "input": {"load": load}});
    submit(http, base, job).await
}

pub(crate) async fn submit(http: &reqwest::Client, base: &str, job: Value) -> String {
    let response = post(http, format!("{base}/v1/jobs"), &job).await;
    let status = response.status();
    let view: Value = response.json().await.unwrap();
    assert_eq!(status, 202, "{view}");
    view["id"].as_str().unwrap().to_string()
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn two_services_and_a_worker_share_answers_jobs_and_sweeps_through_redis() {
    let Some((redis_port, redis)) = fresh_redis() else {
        return;
    };
    let http = reqwest::Client::new();
    let a = serve(redis_port, &http, &[]).await;
    let b = serve(redis_port, &http, &[]).await;
    let (worker, worker_log) = start("worker", redis_port, None, &[]);

    // A job submitted to A is polled and followed on B.
    let id = submit_rolling(&http, &a.base, "1.5 nN").await;
    let view = finished(&http, &b.base, &id).await;
    assert_eq!(view["status"], "succeeded", "{view}");
    let answer = result(&http, &b.base, &view).await;
    assert!(answer["friction_coefficient"].as_f64().unwrap() > 0.0);
    let events = http
        .get(format!("{}/v1/jobs/{id}/events", b.base))
        .header("accept", "text/event-stream")
        .send()
        .await
        .unwrap()
        .text()
        .await
        .unwrap();
    assert!(events.contains("event: completion"), "{events}");

    // An answer solved on A is a hit on B.
    let body = json!({"load": "1.7 nN"});
    let on_a = post(&http, format!("{}/v1/rolling", a.base), &body).await;
    assert_eq!(on_a.headers()["x-cache"], "miss");
    let solved_a: Value = on_a.json().await.unwrap();
    let on_b = post(&http, format!("{}/v1/rolling", b.base), &body).await;
    assert_eq!(on_b.headers()["x-cache"], "hit");
    assert_eq!(on_b.json::<Value>().await.unwrap(), solved_a);

    // A burst of 50 identical requests across A and B solves once in the fleet.
    let misses = |http: reqwest::Client, a: String, b: String| async move {
        metric(&http, &a, "thirdbody_cache_misses_total", "").await
            + metric(&http, &b, "thirdbody_cache_misses_total", "").await
    };
    let before = misses(http.clone(), a.base.clone(), b.base.clone()).await;
    let body = json!({"load": "1.9 nN", "radius": "30 nm"});
    let burst: Vec<_> = (0..50)
        .map(|i| {
            let url = format!("{}/v1/rolling", if i % 2 == 0 { &a.base } else { &b.base });
            let (http, body) = (http.clone(), body.clone());
            tokio::spawn(async move { post(&http, url, &body).await.status() })
        })
        .collect();
    for request in burst {
        assert_eq!(request.await.unwrap(), 200);
    }
    let after = misses(http.clone(), a.base.clone(), b.base.clone()).await;
    assert_eq!(
        after - before,
        1.0,
        "50 identical requests solved {} times",
        after - before
    );

    // A 2,000-point sweep is worked by all three, and SIGKILL of the worker mid-run loses no
    // point: its part is delivered again.
    let sweep = heavy_sweep();
    let id = submit(&http, &a.base, sweep.clone()).await;
    taken_by(&worker_log, &id).await;
    drop(worker); // SIGKILL
    let view = finished(&http, &b.base, &id).await;
    assert_eq!(view["status"], "succeeded", "{view}");
    let answer = result(&http, &b.base, &view).await;
    let points = answer["points"].as_array().unwrap();
    assert_eq!(points.len(), 2000);
    let whole: Value = post(&http, format!("{}/v1/sweeps", b.base), &sweep["input"])
        .await
        .json()
        .await
        .unwrap();
    assert_eq!(answer, whole, "the sweep assembled from parts is the sweep");
    // Drawn from its JSON, though no process holds it typed.
    let picture = http
        .get(format!("{}/v1/jobs/{id}/result?format=svg", a.base))
        .send()
        .await
        .unwrap();
    assert_eq!(picture.headers()["content-type"], "image/svg+xml");
    assert!(picture
        .text()
        .await
        .unwrap()
        .contains("Sweep: friction coefficient"));
    let deliveries = redis_cli(
        redis_port,
        &["HVALS", &format!("thirdbody:job:{id}:deliveries")],
    );
    assert!(
        deliveries.lines().any(|n| n.trim() == "2"),
        "deliveries: {deliveries}"
    );
    // A sweep on the layer as a continuum (a hundred times a local point's cost) is spread
    // in parts too, and its assembled answer is the whole sweep's.
    let speeds: Vec<String> = (0..60)
        .map(|i| format!("{} nm/s", 0.1 * f64::from(i)))
        .collect();
    let continuum = json!({"kind": "sweep", "input": {
        "base": {"layer": {"model": "continuum"}},
        "vary": {"load": ["1 nN", "1.5 nN"], "velocity": speeds}}});
    let id = submit(&http, &b.base, continuum.clone()).await;
    let view = finished(&http, &a.base, &id).await;
    assert_eq!(view["status"], "succeeded", "{view}");
    let answer = result(&http, &a.base, &view).await;
    assert_eq!(answer["points"].as_array().unwrap().len(), 120);
    assert_eq!(answer["meta"]["verification"]["method"], "grid");
    let whole: Value = post(&http, format!("{}/v1/sweeps", a.base), &continuum["input"])
        .await
        .json()
        .await
        .unwrap();
    assert_eq!(
        answer, whole,
        "the continuum sweep assembled from parts is the sweep"
    );

    for service in [&a, &b] {
        let parts = metric(&http, &service.base, "thirdbody_parts_total", "succeeded").await;
        assert!(parts >= 1.0, "{} solved no part", service.base);
    }

    // A cancel sent to B stops the parts running on A: the job ends cancelled everywhere.
    let mut long = sweep.clone();
    long["input"]["vary"]["velocity"] = json!((0..50)
        .map(|i| format!("{} nm/s", 100 + i))
        .collect::<Vec<_>>());
    let id = submit(&http, &a.base, long).await;
    let start = Instant::now();
    while metric(&http, &a.base, "thirdbody_jobs_running", "").await < 1.0 {
        assert!(
            start.elapsed() < PATIENCE,
            "job {id} never ran on {}\n{}",
            a.base,
            logs_near(&a.base)
        );
        tokio::time::sleep(Duration::from_millis(5)).await;
    }
    let cancelled = http
        .post(format!("{}/v1/jobs/{id}/cancel", b.base))
        .send()
        .await
        .unwrap();
    assert_eq!(cancelled.status(), 200);
    assert_eq!(finished(&http, &a.base, &id).await["status"], "cancelled");
    let start = Instant::now();
    while metric(&http, &a.base, "thirdbody_jobs_running", "").await
        + metric(&http, &b.base, "thirdbody_jobs_running", "").await
        > 0.0
    {
        // A running part looks for a cancel every 200 ms, and stops within a point.
        assert!(
            start.elapsed() < Duration::from_secs(5),
            "the cancelled parts still run after {:?}\n{}",
            start.elapsed(),
            logs_near(&a.base)
        );
        tokio::time::sleep(Duration::from_millis(20)).await;
    }

    // Redis stopped: synchronous solves still answer, submissions are refused with 503.
    drop(redis);
    let body = json!({"load": "2.1 nN"});
    let solved = post(&http, format!("{}/v1/rolling", a.base), &body).await;
    assert_eq!(solved.status(), 200);
    let refused = post(
        &http,
        format!("{}/v1/jobs", a.base),
        &json!({"kind": "rolling"}),
    )
    .await;
    assert_eq!(refused.status(), 503);
    let problem: Value = refused.json().await.unwrap();
    assert_eq!(problem["type"], "tag:thirdbody,2026:problems/unavailable");
    let ready = get_json(&http, format!("{}/readyz", a.base)).await;
    assert_eq!(ready["status"], "degraded", "{ready}");

    // Redis back: sharing resumes without a restart.
    let _redis = start_redis(redis_port);
    for base in [&a.base, &b.base] {
        readyz_until(&http, base, |r| r["status"] == "ready").await;
    }
    let body = json!({"load": "2.3 nN"});
    let on_a = post(&http, format!("{}/v1/rolling", a.base), &body).await;
    assert_eq!(on_a.headers()["x-cache"], "miss");
    let on_b = post(&http, format!("{}/v1/rolling", b.base), &body).await;
    assert_eq!(on_b.headers()["x-cache"], "hit");
    assert_eq!(
        rolling_job_finished(&http, &b.base, &a.base, "2.5 nN").await["status"],
        "succeeded"
    );
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_part_whose_worker_keeps_dying_fails_its_job_saying_so() {
    // One delivery allowed: the part of a killed worker is not tried again.
    let Some((redis_port, _redis, http, a)) = one_service(&["--max-deliveries", "1"]).await else {
        return;
    };
    let (worker, log) = start("worker", redis_port, None, &[]);
    let id = submit(&http, &a.base, heavy_sweep()).await;
    taken_by(&log, &id).await;
    drop(worker); // SIGKILL
    let view = finished(&http, &a.base, &id).await;
    assert_eq!(view["status"], "failed", "{view}");
    let detail = view["problem"]["detail"].as_str().unwrap();
    assert!(
        detail.contains("was delivered once and every worker that took it stopped"),
        "{detail}"
    );
}

/// A worker on its own, built from its handles (a solve path, the fleet, the drain's
/// token), with no engine and no HTTP: it takes a job from the stream of a real Redis, stores
/// its answer, and stops once the drain begins.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_worker_on_its_own_takes_a_job_from_the_stream_and_stores_its_answer() {
    use thirdbody::engine::cache::MemoryCache;
    use thirdbody::engine::fleet::{
        Fleet, FleetConfig, RedisJobStore, Shared, TieredCache, Worker,
    };
    use thirdbody::engine::metrics::Metrics;
    use thirdbody::engine::store::{JobRecord, JobStatus};
    use thirdbody::engine::{EngineConfig, Solver};
    use thirdbody::job::{Control, Job, Limits};
    use tokio_util::sync::CancellationToken;

    let Some((redis_port, _redis)) = fresh_redis() else {
        return;
    };
    let url = format!("redis://127.0.0.1:{redis_port}");
    let minute = Duration::from_secs(60);
    let config = EngineConfig {
        pool_size: 1,
        solve_deadline: minute,
        job_deadline: minute,
        max_queued_jobs: 1,
        memory_budget: 1 << 24,
        max_jobs: 1,
        cache_ttl: minute,
        job_retention: minute,
        database: thirdbody::engine::archive::IN_MEMORY.to_string(),
        history_retention: Duration::from_secs(3600),
    };
    let fleet = Arc::new(
        Fleet::open(FleetConfig {
            cache_url: url.clone(),
            jobs_url: url,
            claim_idle: Duration::from_secs(30),
            max_deliveries: 3,
            part_points: 250,
            shared_cache_bytes: 64 << 20,
        })
        .unwrap(),
    );
    let store = Arc::new(RedisJobStore::new(fleet.clone(), minute, minute));
    let cache = TieredCache::new(MemoryCache::new(1 << 24, minute), fleet.clone(), minute);
    let solver = Arc::new(Solver::new(&config, Metrics::noop(), Arc::new(cache)));

    let keyed = Job::from_value(
        json!({"kind": "rolling", "input": {"load": "1.2 nN"}}),
        &Limits::default(),
    )
    .unwrap()
    .keyed();
    let job = keyed.job();
    let record = JobRecord::queued(uuid::Uuid::new_v4(), job.kind(), job.work(), keyed.key());
    let deadline = std::time::SystemTime::now() + minute;
    store
        .enqueue(&record, &job.to_wire(), keyed.key(), deadline, &[])
        .await
        .unwrap();

    let draining = CancellationToken::new();
    let shared = Arc::new(Shared::new(fleet, store.clone()));
    let worker = Worker {
        solver,
        shared,
        slots: None,
        draining: draining.clone(),
    };
    let worker = tokio::spawn(worker.run());
    let start = Instant::now();
    let answered = loop {
        let now = store
            .record(record.id)
            .await
            .unwrap()
            .expect("the record is kept");
        if now.state.status().is_finished() {
            break now;
        }
        assert!(start.elapsed() < PATIENCE, "not answered: {now:?}");
        tokio::time::sleep(Duration::from_millis(20)).await;
    };
    assert_eq!(answered.state.status(), JobStatus::Succeeded);
    let (json, _) = answered.state.result().unwrap().bodies().await.unwrap();
    let stored: Value = serde_json::from_slice(&json).unwrap();
    let direct = thirdbody::engine::run(job, &Control::default()).unwrap();
    let direct: Value = serde_json::from_str(&direct.to_pretty_json().unwrap()).unwrap();
    assert_eq!(stored["meta"]["input_hash"], json!(keyed.key()));
    // Through the layer's table or exactly, whichever this process has built by then: the
    // two agree to the table's error, 1e-9 (tests/service/jobs.rs).
    for quantity in ["contact_area", "friction_coefficient", "penetration"] {
        let (a, b) = (
            stored[quantity].as_f64().unwrap(),
            direct[quantity].as_f64().unwrap(),
        );
        assert!((a / b - 1.0).abs() < 1e-9, "{quantity}: {a:e} vs {b:e}");
    }

    draining.cancel();
    tokio::time::timeout(Duration::from_secs(5), worker)
        .await
        .expect("the worker stops when the drain begins")
        .unwrap();
}
