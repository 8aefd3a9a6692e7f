//! Hardening: the limits that keep one client from stalling, exhausting or crashing the
//! service, and a shutdown that loses no accepted job.

use std::io::{Read, Write};
use std::net::TcpStream;
use std::time::{Duration, Instant};

use reqwest::Method;
use serde_json::{json, Value};

use crate::helpers::{
    assert_detail_says, long_sweep, problem, problem_type, retry_after, spawn_app,
    spawn_app_adjusted, spawn_app_on_disk, within, Events, TestApp,
};

/// `n` seconds.
fn secs(n: u64) -> Duration {
    Duration::from_secs(n)
}

/// A raw connection to the test server.
fn connect(base: &str) -> TcpStream {
    TcpStream::connect(base.trim_start_matches("http://")).unwrap()
}

/// What `f` makes of the server at `base`, run on a blocking thread: the raw connections
/// these tests hold block.
async fn with_raw_connections<T: Send + 'static>(
    app: &TestApp,
    f: impl FnOnce(&str) -> T + Send + 'static,
) -> T {
    let base = app.base.clone();
    tokio::task::spawn_blocking(move || f(&base)).await.unwrap()
}

/// Whether the server closes the first of `held` within 5 s (read on a blocking thread).
async fn first_closed_within_5s(held: Vec<TcpStream>) -> bool {
    tokio::task::spawn_blocking(move || {
        let first = held.into_iter().next().unwrap();
        read_until_closed(first, Duration::from_secs(5)).0
    })
    .await
    .unwrap()
}

/// Reads until the server closes the connection (or `patience` passes); returns whether it
/// closed and what it sent.
fn read_until_closed(mut stream: TcpStream, patience: Duration) -> (bool, String) {
    stream.set_read_timeout(Some(patience)).unwrap();
    let mut text = Vec::new();
    let closed = stream.read_to_end(&mut text).is_ok();
    (closed, String::from_utf8_lossy(&text).into_owned())
}

#[tokio::test]
async fn a_client_that_sends_its_headers_slowly_or_idles_is_disconnected() {
    let app = spawn_app_adjusted(&[], |c| c.connections.header_timeout = secs(1)).await;
    let (slow, idle) = with_raw_connections(&app, move |base| {
        let mut slow = connect(base);
        slow.write_all(b"GET /healthz HTTP/1.1\r\nHost: x\r\n")
            .unwrap();
        let start = Instant::now();
        let (closed, _) = read_until_closed(slow, Duration::from_secs(20));
        let slow = (closed, start.elapsed());
        // A keep-alive connection that sent one request and then idles.
        let mut idle = connect(base);
        idle.write_all(b"GET /healthz HTTP/1.1\r\nHost: x\r\n\r\n")
            .unwrap();
        let start = Instant::now();
        let (closed, text) = read_until_closed(idle, Duration::from_secs(20));
        assert!(text.starts_with("HTTP/1.1 200"), "{text}");
        (slow, (closed, start.elapsed()))
    })
    .await;
    for (closed, after) in [slow, idle] {
        assert!(
            closed && after < Duration::from_secs(10),
            "{closed} after {after:?}"
        );
    }
}

#[tokio::test]
async fn at_the_connection_cap_a_silent_connection_makes_room_for_a_new_client() {
    let app = spawn_app_adjusted(&["--max-connections", "2"], |c| {
        c.connections.header_timeout = secs(60)
    })
    .await;
    let base = app.base.clone();
    // Two connections that never send a request hold both places...
    let held: Vec<TcpStream> = (0..2).map(|_| connect(&base)).collect();
    std::thread::sleep(Duration::from_millis(100));
    // ...and a real client is served at once, not after the 60 s header timeout: the oldest
    // of them is closed to make room.
    let start = Instant::now();
    let health = within(app.get("/healthz")).await;
    assert_eq!(health.status(), 200);
    assert!(
        start.elapsed() < Duration::from_secs(10),
        "{:?}",
        start.elapsed()
    );
    let base = app.base.clone();
    let closed = first_closed_within_5s(held).await;
    assert!(closed, "the oldest silent connection was closed");
    assert_eq!(within(app.get("/healthz")).await.status(), 200, "{base}");
}

#[tokio::test]
async fn at_the_connection_cap_a_fresh_connection_keeps_its_place_over_a_crawling_body() {
    let app = spawn_app_adjusted(&["--max-connections", "2"], |c| {
        c.connections.body.timeout = secs(60)
    })
    .await;
    let (fresh, crawling) = with_raw_connections(&app, move |base| {
        // A body that crawls holds one place...
        let mut crawling = connect(base);
        write!(
            crawling,
            "POST /v1/rolling HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n\
             Content-Length: 1000\r\n\r\n{{"
        )
        .unwrap();
        std::thread::sleep(Duration::from_millis(400));
        // ...a client has just connected to the other and not yet sent its request...
        let mut fresh = connect(base);
        // ...when a third arrives: the crawling body goes, not the client's new connection.
        let mut third = connect(base);
        write!(
            third,
            "GET /healthz HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n"
        )
        .unwrap();
        let (_, third_answer) = read_until_closed(third, Duration::from_secs(10));
        assert!(third_answer.starts_with("HTTP/1.1 200"), "{third_answer}");
        write!(
            fresh,
            "GET /healthz HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n"
        )
        .unwrap();
        (
            read_until_closed(fresh, Duration::from_secs(10)),
            read_until_closed(crawling, Duration::from_secs(1)),
        )
    })
    .await;
    assert!(fresh.1.starts_with("HTTP/1.1 200"), "{fresh:?}");
    assert!(crawling.0, "the crawling body was closed: {crawling:?}");
}

#[tokio::test]
async fn at_the_connection_cap_an_idle_keep_alive_connection_makes_room() {
    let app = spawn_app_adjusted(&["--max-connections", "2"], |c| {
        c.connections.header_timeout = secs(60);
        c.connections.keep_alive_timeout = secs(60);
    })
    .await;
    let base = app.base.clone();
    // Two clients that each had an answer and keep their connection open, idle...
    let held = tokio::task::spawn_blocking(move || {
        (0..2)
            .map(|_| {
                let mut stream = connect(&base);
                stream
                    .write_all(b"GET /healthz HTTP/1.1\r\nHost: x\r\n\r\n")
                    .unwrap();
                let mut answer = [0u8; 12];
                stream.read_exact(&mut answer).unwrap();
                assert_eq!(&answer, b"HTTP/1.1 200");
                stream
            })
            .collect::<Vec<TcpStream>>()
    })
    .await
    .unwrap();
    // ...do not keep a new client waiting: the one idle longest is closed for it.
    let start = Instant::now();
    assert_eq!(within(app.get("/healthz")).await.status(), 200);
    assert!(
        start.elapsed() < Duration::from_secs(5),
        "{:?}",
        start.elapsed()
    );
    let closed = first_closed_within_5s(held).await;
    assert!(closed, "the connection idle longest was closed");
}

#[tokio::test]
async fn an_idle_keep_alive_connection_is_closed_after_the_keep_alive_timeout() {
    let app = spawn_app_adjusted(&[], |c| {
        c.connections.keep_alive_timeout = Duration::from_millis(500)
    })
    .await;
    let after = with_raw_connections(&app, move |base| {
        let mut idle = connect(base);
        idle.write_all(b"GET /healthz HTTP/1.1\r\nHost: x\r\n\r\n")
            .unwrap();
        let start = Instant::now();
        let (closed, text) = read_until_closed(idle, Duration::from_secs(20));
        assert!(closed && text.starts_with("HTTP/1.1 200"), "{text}");
        start.elapsed()
    })
    .await;
    // The header timeout (10 s) would have closed it later.
    assert!(after < Duration::from_secs(4), "{after:?}");
}

/// A sweep of 5,000 loads: its answer (about 3.3 MB) is more than a socket's buffers hold.
fn five_thousand_loads() -> Value {
    json!({"vary": {"load": (0..5000).map(|i| 1e-9 + i as f64 * 1e-13).collect::<Vec<_>>()}})
}

#[tokio::test]
async fn a_client_that_stops_reading_its_answers_is_disconnected_after_the_send_timeout() {
    let app = spawn_app_adjusted(&[], |c| c.connections.send_timeout = secs(1)).await;
    let sweep = five_thousand_loads();
    let body = sweep.to_string();
    assert_eq!(
        app.post("/v1/sweeps", &sweep).await.status(),
        200,
        "solved and cached"
    );
    let (closed, after) = with_raw_connections(&app, move |base| {
        let mut stream = connect(base);
        // Pipelined requests for ~100 MB of answers, more than the kernel's buffers hold,
        // none of which is read: the server's writes wait, then time out.
        let request = format!(
            "POST /v1/sweeps HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n\
             Content-Length: {}\r\n\r\n{body}",
            body.len()
        );
        for _ in 0..30 {
            stream.write_all(request.as_bytes()).unwrap();
        }
        let start = Instant::now();
        std::thread::sleep(Duration::from_secs(6));
        // Reads what the kernel kept, then learns whether the server closed the connection
        // (a reset: it closed with requests unread).
        stream
            .set_read_timeout(Some(Duration::from_secs(20)))
            .unwrap();
        let closed = match std::io::copy(&mut stream, &mut std::io::sink()) {
            Ok(_) => true,
            Err(e) => e.kind() == std::io::ErrorKind::ConnectionReset,
        };
        (closed, start.elapsed())
    })
    .await;
    assert!(closed, "closed after {after:?}");
    assert_eq!(within(app.get("/healthz")).await.status(), 200);
}

#[tokio::test]
async fn a_reader_cut_by_the_send_timeout_is_reset_so_its_answer_leaves_the_kernel() {
    let app = spawn_app_adjusted(&[], |c| c.connections.send_timeout = secs(1)).await;
    let sweep = five_thousand_loads();
    let body = sweep.to_string();
    assert_eq!(app.post("/v1/sweeps", &sweep).await.status(), 200, "cached");
    // A client with a small receive buffer, as a reader that wants the server to queue its
    // answer would have.
    let socket = tokio::net::TcpSocket::new_v4().unwrap();
    socket.set_recv_buffer_size(4096).unwrap();
    let address = app.base.trim_start_matches("http://").parse().unwrap();
    let stream = socket.connect(address).await.unwrap().into_std().unwrap();
    let ended = tokio::task::spawn_blocking(move || {
        let mut stream = stream;
        stream.set_nonblocking(false).unwrap();
        // One request for a 3.3 MB answer, not read until well past the send timeout.
        write!(
            stream,
            "POST /v1/sweeps HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n\
             Content-Length: {}\r\n\r\n{body}",
            body.len()
        )
        .unwrap();
        std::thread::sleep(Duration::from_secs(3));
        stream
            .set_read_timeout(Some(Duration::from_secs(20)))
            .unwrap();
        // Closed gracefully, the server's kernel would go on sending the megabytes it had
        // queued, then the end; reset, the client gets what reached it, then the reset.
        std::io::copy(&mut stream, &mut std::io::sink()).map_err(|e| e.kind())
    })
    .await
    .unwrap();
    assert_eq!(ended.map(|_| ()), Err(std::io::ErrorKind::ConnectionReset));
    assert_eq!(within(app.get("/healthz")).await.status(), 200);
}

#[tokio::test]
async fn a_body_that_crawls_is_answered_408_naming_the_knobs() {
    let app = spawn_app_adjusted(&[], |c| c.connections.body.timeout = secs(1)).await;
    let (text, after) = with_raw_connections(&app, move |base| {
        let mut stream = connect(base);
        let head = "POST /v1/rolling HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n\
                    Content-Length: 100\r\n\r\n{";
        stream.write_all(head.as_bytes()).unwrap();
        let start = Instant::now();
        // A byte every 300 ms: each within the body timeout, far below 240 bytes/s.
        stream
            .set_read_timeout(Some(Duration::from_millis(300)))
            .unwrap();
        let mut text = Vec::new();
        for _ in 0..40 {
            if stream.write_all(b" ").is_err() {
                break;
            }
            let mut chunk = [0u8; 4096];
            match stream.read(&mut chunk) {
                Ok(0) => break,
                Ok(n) => text.extend_from_slice(&chunk[..n]),
                Err(_) => {}
            }
            if text.windows(4).any(|w| w == b"\r\n\r\n") && text.ends_with(b"}") {
                break;
            }
        }
        (String::from_utf8_lossy(&text).into_owned(), start.elapsed())
    })
    .await;
    assert!(text.starts_with("HTTP/1.1 408"), "{text}");
    assert!(
        text.contains("for each piece of a body") && text.contains("bytes/s on average"),
        "{text}"
    );
    assert!(after < Duration::from_secs(6), "{after:?}");
}

#[tokio::test]
async fn event_streams_beyond_their_allowance_are_refused_and_polling_still_works() {
    let app = spawn_app_adjusted(&[], |c| c.max_event_streams = 1).await;
    let running = app.submit(&long_sweep(40)).await;
    let events = format!("{running}/events");
    let first = app.get(&events).await;
    assert_eq!(first.status(), 200);
    let second = app.get(&events).await;
    assert!(second.headers().contains_key("retry-after"));
    let refused = problem(second, 429).await;
    assert_eq!(refused["type"], problem_type("too-many-streams"));
    assert!(refused["detail"]
        .as_str()
        .unwrap()
        .contains("--max-connections"));
    assert_eq!(app.get(&running).await.status(), 200, "polling works");
    // A stream that ends gives its place back.
    drop(first);
    app.cancel(&running).await;
    let again = within(async {
        loop {
            let response = app.get(&events).await;
            if response.status() == 200 {
                return response;
            }
            tokio::time::sleep(Duration::from_millis(50)).await;
        }
    })
    .await;
    Events::new(again);
}

#[tokio::test]
async fn a_body_declared_too_large_is_refused_before_it_is_read() {
    let app = spawn_app(&[]).await;
    let (text, after) = with_raw_connections(&app, move |base| {
        let mut stream = connect(base);
        let head = "POST /v1/rolling HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\n\
                    Content-Length: 67108864\r\n\r\n";
        stream.write_all(head.as_bytes()).unwrap();
        stream.write_all(&[b' '; 1 << 20]).ok();
        let start = Instant::now();
        let (_, text) = read_until_closed(stream, Duration::from_secs(30));
        (text, start.elapsed())
    })
    .await;
    assert!(text.starts_with("HTTP/1.1 413"), "{text}");
    assert!(text.contains("payload-too-large"), "{text}");
    assert!(after < Duration::from_secs(5), "{after:?}");
}

#[tokio::test]
async fn made_up_methods_do_not_make_up_metric_series_and_request_ids_are_clean() {
    let app = spawn_app(&[]).await;
    for i in 0..20 {
        let method = Method::from_bytes(format!("INVENTED{i}").as_bytes()).unwrap();
        app.send(method, "/healthz", &[], None).await;
    }
    let metrics = app.get("/metrics").await.text().await.unwrap();
    assert!(!metrics.contains("INVENTED"), "{metrics}");
    assert!(
        app.metric("http_requests_total", &[("method", "other")])
            .await
            >= 20.0
    );

    let forged = "abc\" level=ERROR msg=\"forged";
    let id = app.request_id_for(forged).await;
    assert_ne!(id, forged);
    assert!(
        id.chars().all(|c| c.is_ascii_alphanumeric() || c == '-'),
        "{id}"
    );
    let kept = app.request_id_for("trace-42.a:b_c").await;
    assert_eq!(kept, "trace-42.a:b_c");
}

#[tokio::test]
async fn asynchronous_jobs_leave_a_solver_thread_to_synchronous_requests() {
    let app = spawn_app_on_disk(&["--pool-size", "2", "--max-sweep-points", "1000000"]).await;
    let first = app.submit(&long_sweep(60)).await;
    let second = app.submit(&long_sweep(60)).await;
    app.wait_for_job(&first, |j| j["status"] == "running").await;
    // The second job waits for a solver thread the first does not hold...
    let queued: serde_json::Value = app.get(&second).await.json().await.unwrap();
    assert_eq!(queued["status"], "queued");
    // ...which synchronous requests get.
    let response = app.post("/v1/rolling", &json!({"load": "1.05 nN"})).await;
    assert_eq!(response.status(), 200);
    app.delete(&first).await;
    app.delete(&second).await;
}

#[tokio::test]
async fn a_shutdown_finishes_the_accepted_jobs_and_keeps_answering_their_clients() {
    let mut app = spawn_app(&[
        "--pool-size=1",
        "--max-sweep-points=1000000",
        "--shutdown-timeout=1m",
    ])
    .await;
    // A job finished before the shutdown that its client has not read yet...
    let unread = app
        .submit(&json!({"kind": "rolling", "input": {"load": "1.02 nN"}}))
        .await;
    tokio::time::sleep(Duration::from_millis(200)).await;
    // ...a job running and one queued behind it when the shutdown starts: both finish.
    let running = app.submit_running(&long_sweep(20)).await;
    let queued = app
        .submit(&json!({"kind": "rolling", "input": {"load": "1.01 nN"}}))
        .await;
    let mut running_events = Events::new(app.get(&format!("{running}/events")).await);
    let mut queued_events = Events::new(app.get(&format!("{queued}/events")).await);
    app.shut_down();
    // New work is refused while the accepted jobs are still answered.
    tokio::time::sleep(Duration::from_millis(50)).await;
    let refused = app.post("/v1/rolling", &json!({})).await;
    assert_eq!(
        problem(refused, 503).await["type"],
        problem_type("draining")
    );
    let polled: serde_json::Value = app.get(&queued).await.json().await.unwrap();
    assert!(polled["status"].is_string());
    for events in [&mut running_events, &mut queued_events] {
        let (_, completion) = events.until_completion().await;
        assert_eq!(completion["status"], "succeeded");
    }
    // The server waits for the unread job's client too.
    tokio::time::sleep(Duration::from_millis(300)).await;
    assert!(!app.server.is_finished());
    let read: serde_json::Value = app.get(&unread).await.json().await.unwrap();
    assert_eq!(read["status"], "succeeded");
    within(&mut app.server).await.unwrap().unwrap();
}

/// A server shutting down within `shutdown_timeout`, and the URL of a job it runs that is
/// longer than that.
async fn running_past_the_bound(shutdown_timeout: &str) -> (TestApp, String) {
    let app = spawn_app_on_disk(&[
        "--max-sweep-points=1000000",
        "--shutdown-timeout",
        shutdown_timeout,
    ])
    .await;
    let long = app.submit_running(&long_sweep(100)).await;
    (app, long)
}

#[tokio::test]
async fn a_job_the_shutdown_bound_cannot_fit_ends_interrupted() {
    let (mut app, long) = running_past_the_bound("2s").await;
    let mut events = Events::new(app.get(&format!("{long}/events")).await);
    app.shut_down();
    let (_, completion) = events.until_completion().await;
    assert_eq!(completion["status"], "interrupted");
    within(&mut app.server).await.unwrap().unwrap();
}

#[tokio::test]
async fn pollers_of_a_job_the_shutdown_interrupts_learn_it_before_the_port_closes() {
    let (mut app, long) = running_past_the_bound("6s").await;
    let started = Instant::now();
    app.shut_down();
    // Five clients poll once a second (the pace the job's Retry-After asks), each from its
    // own moment; each must read the job's end from this process.
    let pollers = (0..5u64).map(|k| {
        let (client, url) = (app.client.clone(), format!("{}{long}", app.base));
        tokio::spawn(async move {
            tokio::time::sleep(Duration::from_millis(200 * k)).await;
            loop {
                match client.get(&url).send().await {
                    Ok(answer) => {
                        let job: serde_json::Value = answer.json().await.unwrap();
                        if job["status"] != "running" {
                            return Ok(job["status"].clone());
                        }
                    }
                    Err(e) => return Err(format!("after {:?}: {e}", started.elapsed())),
                }
                tokio::time::sleep(Duration::from_secs(1)).await;
            }
        })
    });
    for poller in pollers.collect::<Vec<_>>() {
        assert_eq!(poller.await.unwrap(), Ok(json!("interrupted")));
    }
    within(&mut app.server).await.unwrap().unwrap();
    assert!(
        started.elapsed() < Duration::from_millis(6500),
        "{:?}",
        started.elapsed()
    );
}

#[tokio::test]
async fn a_job_that_could_not_end_within_its_deadline_behind_the_queue_is_refused() {
    // The deadline leaves the first job 15 times the time it takes on a quiet machine (a
    // 3 s deadline failed it on a busy one), and the big job takes twice the deadline and
    // more on the fastest.
    let app = spawn_app_on_disk(&[
        "--pool-size=2",
        "--job-deadline=6s",
        "--max-sweep-points=100000",
    ])
    .await;
    // A job of 1,000 points (~0.3 s) teaches the service what such points cost.
    let first = app.submit(&long_sweep(20)).await;
    let learned = app
        .wait_for_job(&first, |j| {
            j["status"] != "running" && j["status"] != "queued"
        })
        .await;
    assert_eq!(learned["status"], "succeeded", "{learned}");
    // 64,000 points (~17 s on the one job thread) are accepted: nothing is ahead of them.
    let big = app.submit(&long_sweep(80)).await;
    // 125 more would wait for them past their own deadline: refused now, not failed later.
    // (Few enough that they alone fit in the deadline however slow the machine: on one
    // running beside `stress --cpu 2` the first job took fifteen times as long, and 1,331
    // points alone were then estimated past it, a refusal of another kind.)
    let answer = app.post("/v1/jobs", &long_sweep(10)).await;
    let wait = retry_after(&answer);
    assert!(wait >= 3, "Retry-After {wait}");
    let refusal = problem(answer, 429).await;
    assert_eq!(refusal["type"], problem_type("overloaded"));
    assert_detail_says(&refusal, "past its deadline of 6 s (--job-deadline)");
    // A synchronous solve is not held up; once the big job ends, the next is accepted.
    assert_eq!(app.post("/v1/rolling", &json!({})).await.status(), 200);
    let cancel = app.post(&format!("{big}/cancel"), &json!({})).await;
    assert!(cancel.status().is_success(), "{}", cancel.status());
    app.wait_for_job(&big, |j| {
        j["status"] != "running" && j["status"] != "queued"
    })
    .await;
    assert_eq!(app.post("/v1/jobs", &long_sweep(22)).await.status(), 202);
}
