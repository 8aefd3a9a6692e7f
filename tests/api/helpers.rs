//! Starting a server the way the binary does, and reading what it answers.

use std::future::Future;
use std::time::Duration;

use clap::Parser;
use reqwest::{Client, Method, Response, StatusCode};
use serde_json::Value;
use thirdbody::http::{self, AppState, Config, ServeArgs};
use tokio::net::TcpListener;
use tokio::sync::oneshot;
use tokio::task::JoinHandle;

/// Generous bound on any wait in a test: reached only when something hangs.
pub const PATIENCE: Duration = Duration::from_secs(120);

/// A running server.
pub struct TestApp {
    pub base: String,
    pub client: Client,
    shutdown: Option<oneshot::Sender<()>>,
    pub server: JoinHandle<std::io::Result<()>>,
    /// The database file of [`spawn_app_on_disk`], removed with the app.
    database: Option<DatabaseFile>,
}

/// A database file of one test's, removed (with its log) when the test's app goes.
struct DatabaseFile(std::path::PathBuf);

impl DatabaseFile {
    fn new() -> DatabaseFile {
        let name = format!("thirdbody-test-{}.db", uuid::Uuid::new_v4().simple());
        DatabaseFile(std::env::temp_dir().join(name))
    }
}

impl Drop for DatabaseFile {
    fn drop(&mut self) {
        for end in ["", "-wal", "-shm"] {
            let _ = std::fs::remove_file(format!("{}{end}", self.0.display()));
        }
    }
}

/// The validated settings of `thirdbody serve` with these flags; the database of saved
/// analyses in memory unless the flags name one (tests run side by side, and a file is
/// one process's).
pub fn config(flags: &[&str]) -> Config {
    let memory = ["--database", ":memory:"];
    let database = if flags.contains(&"--database") {
        &[][..]
    } else {
        &memory[..]
    };
    let args = std::iter::once("serve")
        .chain(database.iter().copied())
        .chain(flags.iter().copied());
    ServeArgs::try_parse_from(args)
        .expect("valid flags")
        .validate()
        .expect("valid settings")
}

/// The service `thirdbody serve` would be with these flags.
pub fn state(flags: &[&str]) -> AppState {
    AppState::new(config(flags)).expect("the service starts")
}

/// Serves on 127.0.0.1, port 0, with `flags`.
pub async fn spawn_app(flags: &[&str]) -> TestApp {
    serve(state(flags)).await
}

/// Serves on 127.0.0.1, port 0, with `flags` and a database file of its own: results beyond
/// the memory budget are kept there (a database in memory keeps none), as a test of a job
/// whose answer may be large needs.
pub async fn spawn_app_on_disk(flags: &[&str]) -> TestApp {
    let database = DatabaseFile::new();
    let path = database
        .0
        .to_str()
        .expect("a UTF-8 temporary directory")
        .to_string();
    let flags: Vec<&str> = ["--database", path.as_str()]
        .into_iter()
        .chain(flags.iter().copied())
        .collect();
    let mut app = spawn_app(&flags).await;
    app.database = Some(database);
    app
}

/// Serves on 127.0.0.1, port 0, with `flags` and then `adjust` applied to the settings:
/// for a bound that the binary holds constant (a connection's timeouts, the drain's delay,
/// the cache's time to live), shortened or lengthened so that a test sees it act.
pub async fn spawn_app_adjusted(flags: &[&str], adjust: impl FnOnce(&mut Config)) -> TestApp {
    let mut config = config(flags);
    adjust(&mut config);
    serve(AppState::new(config).expect("the service starts")).await
}

/// Serves `state` on 127.0.0.1, port 0.
pub async fn serve(state: AppState) -> TestApp {
    let listener = TcpListener::bind("127.0.0.1:0").await.unwrap();
    let base = format!("http://{}", listener.local_addr().unwrap());
    let (tx, rx) = oneshot::channel::<()>();
    let shutdown = async {
        let _ = rx.await;
    };
    let server = tokio::spawn(http::run(listener, state, shutdown));
    TestApp {
        base,
        client: Client::new(),
        shutdown: Some(tx),
        server,
        database: None,
    }
}

impl TestApp {
    pub fn url(&self, path: &str) -> String {
        format!("{}{path}", self.base)
    }

    /// Sends `method path` with `headers`, and `body` as JSON if any.
    pub async fn send(
        &self,
        method: Method,
        path: &str,
        headers: &[(&str, &str)],
        body: Option<&Value>,
    ) -> Response {
        let mut request = self.client.request(method, self.url(path));
        for (name, value) in headers {
            request = request.header(*name, *value);
        }
        if let Some(body) = body {
            request = request.json(body);
        }
        request.send().await.unwrap()
    }

    pub async fn get(&self, path: &str) -> Response {
        self.send(Method::GET, path, &[], None).await
    }

    pub async fn post(&self, path: &str, body: &Value) -> Response {
        self.send(Method::POST, path, &[], Some(body)).await
    }

    /// POSTs `body` as JSON to `path`, checks that it is answered (200), and reads the
    /// answer.
    pub async fn answer(&self, path: &str, body: &Value) -> Value {
        let response = self.post(path, body).await;
        assert_eq!(response.status(), StatusCode::OK);
        response.json().await.unwrap()
    }

    /// POSTs `body` as JSON to `path` and reads the answer as JSON, whatever its status.
    pub async fn post_json(&self, path: &str, body: &Value) -> Value {
        self.post(path, body).await.json().await.unwrap()
    }

    /// GETs `path` with `headers` (an `accept`, an `origin`, a request id).
    pub async fn get_with(&self, path: &str, headers: &[(&str, &str)]) -> Response {
        self.send(Method::GET, path, headers, None).await
    }

    /// POSTs `body` as JSON to `path` with `headers`.
    pub async fn post_with(&self, path: &str, headers: &[(&str, &str)], body: &Value) -> Response {
        self.send(Method::POST, path, headers, Some(body)).await
    }

    /// The request id a probe's answer carries when asked with `id` as its `x-request-id`.
    pub async fn request_id_for(&self, id: &str) -> String {
        let response = self.get_with("/healthz", &[("x-request-id", id)]).await;
        response.headers()["x-request-id"]
            .to_str()
            .unwrap()
            .to_string()
    }

    pub async fn delete(&self, path: &str) -> Response {
        self.send(Method::DELETE, path, &[], None).await
    }

    /// Cancels the job at `location`.
    pub async fn cancel(&self, location: &str) -> Response {
        let path = format!("{location}/cancel");
        self.send(Method::POST, &path, &[], None).await
    }

    /// POSTs `text` as it is, as `application/json` (its spelling is what is tested).
    pub async fn post_json_text(&self, path: &str, text: &str) -> Response {
        self.post_raw(path, "application/json", text.to_string())
            .await
    }

    /// POSTs `body` as it is, with `content_type`.
    pub async fn post_raw(&self, path: &str, content_type: &str, body: String) -> Response {
        self.client
            .post(self.url(path))
            .header("content-type", content_type)
            .body(body)
            .send()
            .await
            .unwrap()
    }

    /// Sends the shutdown signal (SIGTERM for the binary).
    pub fn shut_down(&mut self) {
        if let Some(tx) = self.shutdown.take() {
            let _ = tx.send(());
        }
    }

    /// The value of the metric line `name{labels...}` (labels in any order), 0 if absent.
    pub async fn metric(&self, name: &str, labels: &[(&str, &str)]) -> f64 {
        let text = self.get("/metrics").await.text().await.unwrap();
        text.lines()
            .filter(|line| !line.starts_with('#'))
            .filter_map(|line| line.rsplit_once(' '))
            .find(|(series, _)| {
                let (metric, rest) = series.split_once('{').unwrap_or((series, ""));
                metric == name
                    && labels
                        .iter()
                        .all(|(k, v)| rest.contains(&format!("{k}=\"{v}\"")))
            })
            .map_or(0.0, |(_, value)| value.parse().unwrap())
    }

    /// Solves done so far with these labels (`kind`, `outcome`).
    pub async fn solves(&self, labels: &[(&str, &str)]) -> f64 {
        self.metric("thirdbody_solve_duration_seconds_count", labels)
            .await
    }

    /// The answer of a job (as its view gives it), fetched from its `result_url`: a job's
    /// view never carries its answer.
    pub async fn result(&self, job: &Value) -> Value {
        assert!(job.get("result").is_none(), "{job}");
        let url = job["result_url"].as_str().expect("the job has a result");
        let response = self.get(url).await;
        assert_eq!(response.status(), StatusCode::OK);
        response.json().await.unwrap()
    }

    /// Submits an asynchronous job; returns its URL.
    pub async fn submit(&self, job: &Value) -> String {
        let response = self.post("/v1/jobs", job).await;
        assert_eq!(response.status(), StatusCode::ACCEPTED);
        let location = response.headers()["location"].to_str().unwrap().to_string();
        assert!(location.starts_with("/v1/jobs/"), "{location}");
        location
    }

    /// Submits `job` and waits until a solver thread runs it; returns its URL.
    pub async fn submit_running(&self, job: &Value) -> String {
        let location = self.submit(job).await;
        self.wait_for_job(&location, |j| j["status"] == "running")
            .await;
        location
    }

    /// Polls the job at `location` until `done` holds for it; returns it then.
    pub async fn wait_for_job(&self, location: &str, done: impl Fn(&Value) -> bool) -> Value {
        within(async {
            loop {
                let job: Value = self.get(location).await.json().await.unwrap();
                if done(&job) {
                    return job;
                }
                tokio::time::sleep(Duration::from_millis(10)).await;
            }
        })
        .await
    }
}

/// `future`, or a panic if it hangs.
pub async fn within<T>(future: impl Future<Output = T>) -> T {
    tokio::time::timeout(PATIENCE, future)
        .await
        .expect("the test hung")
}

/// A sweep long enough to hold a solver thread for the length of a test, as long as `n`³
/// points of ≈ 0.05 ms would be: (`n`/2)³ points of the finest rule (1024 Gauss nodes,
/// ≈ 0.4 ms each, exact strip solves rather than table look-ups), so that what a stopped
/// sweep keeps (a row per point) stays small. Each `n` is another job.
pub fn long_sweep(n: usize) -> Value {
    let m = n.div_ceil(2);
    let radii: Vec<String> = (0..m).map(|i| format!("{} nm", 25 + i)).collect();
    let loads: Vec<String> = (0..m).map(|i| format!("{} pN", 1000 + n + i)).collect();
    let speeds: Vec<String> = (0..m).map(|i| format!("{} nm/s", 1 + i)).collect();
    serde_json::json!({"kind": "sweep", "input": {
        "base": {"options": {"strips": 1024}},
        "vary": {"radius": radii, "load": loads, "velocity": speeds}}})
}

/// Reads a `text/event-stream` body event by event.
pub struct Events {
    response: Response,
    /// Bytes read and not yet parsed (a chunk may end inside a character).
    buffer: Vec<u8>,
}

impl Events {
    pub fn new(response: Response) -> Self {
        assert_eq!(response.status(), StatusCode::OK);
        assert_eq!(response.headers()["content-type"], "text/event-stream");
        Events {
            response,
            buffer: Vec::new(),
        }
    }

    /// The `progress` events up to the `completion` event, and that event.
    pub async fn until_completion(&mut self) -> (Vec<Value>, Value) {
        let mut progress = Vec::new();
        loop {
            match self.next().await.expect("a completion event") {
                (name, job) if name == "progress" => progress.push(job),
                (name, job) if name == "completion" => return (progress, job),
                (name, _) => panic!("unexpected event {name}"),
            }
        }
    }

    /// The next event's name and data (keep-alive comments skipped); `None` at the end.
    pub async fn next(&mut self) -> Option<(String, Value)> {
        within(async {
            loop {
                if let Some(end) = self.buffer.windows(2).position(|w| w == b"\n\n") {
                    let bytes: Vec<u8> = self.buffer.drain(..end + 2).collect();
                    let block = String::from_utf8(bytes).unwrap();
                    let field = |name: &str| {
                        block
                            .lines()
                            .find_map(|l| l.strip_prefix(name))
                            .map(|v| v.trim_start().to_string())
                    };
                    if let (Some(event), Some(data)) = (field("event:"), field("data:")) {
                        return Some((event, serde_json::from_str(&data).unwrap()));
                    }
                    continue;
                }
                match self.response.chunk().await {
                    Ok(Some(bytes)) => self.buffer.extend_from_slice(&bytes),
                    _ => return None,
                }
            }
        })
        .await
    }
}

/// The seconds a response's `Retry-After` header asks a client to wait.
pub fn retry_after(response: &Response) -> u64 {
    response.headers()["retry-after"]
        .to_str()
        .unwrap()
        .parse()
        .unwrap()
}

/// The problem document of an error response, checked for its status and content type.
pub async fn problem(response: Response, status: u16) -> Value {
    assert_eq!(response.status().as_u16(), status);
    assert_eq!(
        response.headers()["content-type"],
        "application/problem+json"
    );
    let problem: Value = response.json().await.unwrap();
    assert_eq!(problem["status"], status);
    assert!(problem["title"].is_string() && problem["detail"].is_string());
    problem
}

/// Asserts that a problem's `detail` says `part`.
pub fn assert_detail_says(problem: &Value, part: &str) {
    let detail = problem["detail"].as_str().unwrap();
    assert!(detail.contains(part), "{detail}");
}

/// The type URI of the problem named `name`.
pub fn problem_type(name: &str) -> String {
    format!("tag:thirdbody,2026:problems/{name}")
}
