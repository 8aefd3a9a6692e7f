//! The `thirdbody` binary as CI pipelines use it: job files in, JSON or CSV out, errors on
//! standard error with a non-zero status.

use std::io::Write;
use std::process::{Command, Output, Stdio};

use serde_json::Value;

use crate::processes::scratch;

fn thirdbody(args: &[&str], stdin: Option<&str>) -> Output {
    let mut child = crate::processes::thirdbody()
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    if let Some(text) = stdin {
        child
            .stdin
            .take()
            .unwrap()
            .write_all(text.as_bytes())
            .unwrap();
    }
    drop(child.stdin.take());
    child.wait_with_output().unwrap()
}

fn json(output: &Output) -> Value {
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    serde_json::from_slice(&output.stdout).unwrap()
}

#[test]
fn every_example_job_solves() {
    let rolling = json(&thirdbody(&["solve", "examples/rolling.json"], None));
    assert!((rolling["contact_area"].as_f64().unwrap() * 1e18 - 85.234).abs() < 5e-4);
    assert_eq!(rolling["boundary"].as_array().unwrap().len(), 21);

    let sweep = json(&thirdbody(&["solve", "examples/sweep.json"], None));
    assert_eq!(sweep["points"].as_array().unwrap().len(), 15);

    let figure = json(&thirdbody(&["solve", "examples/figure.json"], None));
    assert_eq!(figure["figure"], 6);

    let three_body = json(&thirdbody(&["solve", "examples/three_body.json"], None));
    let load = three_body["loads"]["total"].as_f64().unwrap();
    assert!((load / 1e-3 - 1.0).abs() < 1e-10);
    let mu = &three_body["friction_coefficient"];
    assert!(mu["rolling"].as_f64().unwrap() < mu["static"].as_f64().unwrap());

    // README's worked example: the data were drawn from T_σ = 80 ms, T_ε = 600 ms,
    // E_L = 2.5 GPa, and each 95 % interval holds its true value.
    let fit = json(&thirdbody(&["solve", "examples/fit.json"], None));
    for (name, truth) in [
        ("relaxation_time", 0.08),
        ("retardation_time", 0.6),
        ("elastic_modulus", 2.5e9),
    ] {
        let interval = &fit["parameters"][name]["interval_95"];
        let (lo, hi) = (interval[0].as_f64().unwrap(), interval[1].as_f64().unwrap());
        assert!(lo < truth && truth < hi, "{name}: [{lo}, {hi}]");
    }
    assert_eq!(fit["identifiability"]["identifiable"], true);
}

#[test]
fn a_job_can_come_on_standard_input_and_a_sweep_can_leave_as_csv() {
    let out = json(&thirdbody(
        &["solve", "-"],
        Some(r#"{"kind": "rolling", "input": {"velocity": 0}}"#),
    ));
    assert_eq!(out["centroid_shift"], 0.0);
    let csv = thirdbody(
        &["solve", "-", "--format", "csv"],
        Some(r#"{"kind": "sweep", "input": {"vary": {"load": ["1 nN", "1.4 nN"]}}}"#),
    );
    assert!(csv.status.success());
    assert_eq!(String::from_utf8_lossy(&csv.stdout).lines().count(), 3);
}

#[test]
fn figures_print_as_json_or_csv() {
    let fig = json(&thirdbody(&["figure", "5"], None));
    assert_eq!(fig["series"].as_array().unwrap().len(), 5);
    let csv = thirdbody(&["figure", "9", "--format", "csv"], None);
    assert!(csv.status.success());
    let text = String::from_utf8_lossy(&csv.stdout);
    assert_eq!(
        text.lines().next(),
        Some("series,label,radius [m],friction_coefficient,load [N],velocity [m/s]")
    );
    assert_eq!(text.lines().count(), 1 + 10 * 14);
}

#[test]
fn a_bad_job_fails_with_status_2_and_says_which_field() {
    let out = thirdbody(
        &["solve", "-"],
        Some(r#"{"kind": "rolling", "input": {"radius": "3 GPa"}}"#),
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(out.stdout.is_empty());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("radius") && err.contains("is a pressure"),
        "{err}"
    );

    let out = thirdbody(&["figure", "12"], None);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("3 to 9"));

    // A file that cannot be read is said so, not taken for malformed JSON.
    let out = thirdbody(&["solve", "no/such/file.json"], None);
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(
        String::from_utf8_lossy(&out.stderr),
        "thirdbody: cannot read no/such/file.json: No such file or directory (os error 2)\n"
    );

    // A valid job the model cannot solve: status 1, its numbers in the units a person reads.
    let out = thirdbody(
        &["solve", "-"],
        Some(r#"{"kind": "three_body", "input": {"operating": {"total_load": 10}}}"#),
    );
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(
        String::from_utf8_lossy(&out.stderr),
        "thirdbody: total_load = 10 N cannot be carried: even at zero separation the system \
         carries only 5.52 N\n"
    );

    // Every bad field in a sentence.
    let out = thirdbody(
        &["solve", "-"],
        Some(r#"{"kind": "three_body", "input": {"velocity": "-4 nm/s"}}"#),
    );
    assert_eq!(out.status.code(), Some(2));
    assert_eq!(
        String::from_utf8_lossy(&out.stderr),
        "thirdbody: operating is required; expected exactly one of separation (m), \
         total_load (N), particle_load (N); velocity = \"-4 nm/s\" is out of range; expected \
         finite and ≥ 0 m/s\n"
    );
}

#[test]
fn every_answer_prints_as_csv_even_a_single_contact() {
    let out = thirdbody(&["solve", "examples/rolling.json", "--format", "csv"], None);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 2, "{text}");
    assert!(lines[0]
        .starts_with("radius [m],load [N],velocity [m/s],penetration [m],contact_area [m²]"));
    let out = thirdbody(
        &["solve", "examples/three_body.json", "--format", "csv"],
        None,
    );
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stdout).starts_with("total_load [N],velocity [m/s]"));
}

#[test]
fn openapi_prints_the_committed_spec() {
    let output = thirdbody(&["openapi"], None);
    assert!(output.status.success());
    let committed = std::fs::read_to_string("openapi/openapi.json").unwrap();
    assert!(
        String::from_utf8(output.stdout).unwrap() == committed,
        "openapi/openapi.json is out of date: run `cargo run -- openapi > openapi/openapi.json`"
    );
}

#[test]
fn serve_refuses_a_bad_setting_at_start_up_with_status_2() {
    let output = thirdbody(&["serve", "--pool-size", "0"], None);
    assert_eq!(output.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("--pool-size 0"), "{stderr}");
    let output = thirdbody(&["serve", "--bind", "nowhere"], None);
    assert_eq!(output.status.code(), Some(2));
    // A history shorter than the time a result stays in memory would contradict it.
    let flags = [
        "serve",
        "--history-retention",
        "1m",
        "--job-retention",
        "15m",
    ];
    let output = thirdbody(&flags, None);
    assert_eq!(output.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("--history-retention 1m must be at least --job-retention 15m"),
        "{stderr}"
    );
}

/// A number out of its flag's range stops `serve` and `worker` (whose flags are `serve`'s)
/// with status 2, naming the flag, the value and the range; so does its variable.
#[test]
fn every_numeric_flag_out_of_range_is_status_2_naming_flag_value_and_range() {
    let fleet = ["worker", "--redis-url", "redis://127.0.0.1:1"];
    for (command, flag, value, expected) in [
        (
            &["serve"][..],
            "--memory-budget",
            "18446744073709551615",
            "thirdbody serve: invalid setting: --memory-budget 18446744073709551615: allowed \
             65536 to 1099511627776 bytes (1 TiB)",
        ),
        (
            &["serve"],
            "--max-queued-jobs",
            "0",
            "thirdbody serve: invalid setting: --max-queued-jobs 0: allowed 1 to 100000000",
        ),
        (
            &fleet,
            "--redis-cache-bytes",
            "0",
            "thirdbody worker: invalid setting: --redis-cache-bytes 0: allowed 65536 to \
             1099511627776 bytes (1 TiB)",
        ),
    ] {
        let args: Vec<&str> = command.iter().copied().chain([flag, value]).collect();
        let output = thirdbody(&args, None);
        assert_eq!(output.status.code(), Some(2), "{args:?}");
        assert_eq!(String::from_utf8_lossy(&output.stderr).trim(), expected);
    }
    let output = crate::processes::thirdbody()
        .args(["serve", "--database", ":memory:"])
        .env("THIRDBODY_QUOTA_POINTS", "18446744073709551615")
        .output()
        .unwrap();
    assert_eq!(output.status.code(), Some(2));
    assert_eq!(
        String::from_utf8_lossy(&output.stderr).trim(),
        "thirdbody serve: invalid setting: --quota-points 18446744073709551615: allowed 0 (no \
         limit) to 100000000"
    );
}

/// `ENV` settings of the Dockerfile's run stage, as (name, value) pairs.
fn dockerfile_env() -> Vec<(String, String)> {
    let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/Dockerfile")).unwrap();
    let run_stage = &text[text.rfind("\nFROM ").unwrap()..];
    let joined = run_stage.replace("\\\n", " ");
    joined
        .lines()
        .filter_map(|l| l.trim().strip_prefix("ENV "))
        .flat_map(|l| l.split_whitespace().map(str::to_string).collect::<Vec<_>>())
        .map(|pair| {
            let (k, v) = pair.split_once('=').unwrap();
            (k.to_string(), v.to_string())
        })
        .collect()
}

fn get(port: u16, path: &str) -> Option<String> {
    use std::io::Read;
    let mut stream = std::net::TcpStream::connect(("127.0.0.1", port)).ok()?;
    write!(
        stream,
        "GET {path} HTTP/1.1\r\nHost: localhost\r\nConnection: close\r\n\r\n"
    )
    .ok()?;
    let mut answer = String::new();
    stream.read_to_string(&mut answer).ok()?;
    Some(answer)
}

#[test]
fn the_container_configuration_starts_a_service_that_drains_on_sigterm() {
    let env = dockerfile_env();
    let names: Vec<&str> = env.iter().map(|(k, _)| k.as_str()).collect();
    assert!(names.contains(&"THIRDBODY_BIND") && names.contains(&"THIRDBODY_LOG_FORMAT"));
    let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/Dockerfile")).unwrap();
    assert!(text.contains("ENTRYPOINT [\"thirdbody\"]") && text.contains("CMD [\"serve\"]"));
    let bind = &env.iter().find(|(k, _)| k == "THIRDBODY_BIND").unwrap().1;
    assert!(text.contains(&format!("EXPOSE {}", bind.rsplit(':').next().unwrap())));
    // The database of saved analyses is in the image's volume, which its user may write.
    let database = &env
        .iter()
        .find(|(k, _)| k == "THIRDBODY_DATABASE")
        .unwrap()
        .1;
    assert!(database.starts_with("/var/lib/thirdbody/"), "{database}");
    assert!(
        text.contains("VOLUME /var/lib/thirdbody")
            && text.contains("chown thirdbody /var/lib/thirdbody")
    );
    // Here, in a directory of the test's (made by the service, as the volume would be).
    let volume = std::env::temp_dir().join(format!("thirdbody-volume-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&volume);

    // The same settings, listening on a free loopback port instead of 0.0.0.0:8080.
    let port = std::net::TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let child = crate::processes::thirdbody()
        .arg("serve")
        .envs(env.iter().map(|(k, v)| (k.as_str(), v.as_str())))
        .env("THIRDBODY_BIND", format!("127.0.0.1:{port}"))
        .env("THIRDBODY_DATABASE", volume.join("thirdbody.db"))
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let started = std::time::Instant::now();
    let health = loop {
        if let Some(health) = get(port, "/healthz") {
            break health;
        }
        assert!(
            started.elapsed() < crate::processes::PATIENCE,
            "the service does not answer /healthz"
        );
        std::thread::sleep(std::time::Duration::from_millis(25));
    };
    assert!(health.starts_with("HTTP/1.1 200"), "{health}");
    assert!(get(port, "/readyz").unwrap().starts_with("HTTP/1.1 200"));
    // The image's HEALTHCHECK command, with the container's bind address.
    assert!(
        text.contains(r#"HEALTHCHECK"#) && text.contains(r#"CMD ["thirdbody", "healthcheck"]"#)
    );
    let healthcheck = |bind: String| {
        crate::processes::thirdbody()
            .arg("healthcheck")
            .env("THIRDBODY_BIND", bind)
            .stderr(Stdio::null())
            .status()
            .unwrap()
            .success()
    };
    assert!(healthcheck(format!("0.0.0.0:{port}")));
    let closed = std::net::TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap();
    assert!(
        !healthcheck(closed.to_string()),
        "nothing listens there once it is dropped"
    );
    let status = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let out = child.wait_with_output().unwrap();
    assert!(out.status.success(), "exit after SIGTERM: {:?}", out.status);
    // JSON log lines, as the container asks.
    let logs = String::from_utf8_lossy(&out.stderr);
    assert!(
        logs.lines()
            .any(|l| l.starts_with('{') && l.contains("listening")),
        "{logs}"
    );
    assert!(
        volume.join("thirdbody.db").is_file(),
        "no database in the volume"
    );
    let _ = std::fs::remove_dir_all(&volume);
}

/// POSTs the JSON `body` to `path`; the answer's status line and body.
fn post(port: u16, path: &str, body: &str) -> (String, String) {
    use std::io::Read;
    let mut stream = std::net::TcpStream::connect(("127.0.0.1", port)).unwrap();
    write!(
        stream,
        "POST {path} HTTP/1.1\r\nHost: localhost\r\nConnection: close\r\n\
         Content-Type: application/json\r\nContent-Length: {}\r\n\r\n{body}",
        body.len()
    )
    .unwrap();
    let mut answer = String::new();
    stream.read_to_string(&mut answer).unwrap();
    let (head, body) = answer.split_once("\r\n\r\n").unwrap();
    (head.lines().next().unwrap().to_string(), body.to_string())
}

/// A free loopback port (free once the listener that found it is dropped).
fn free_port() -> u16 {
    let listener = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    listener.local_addr().unwrap().port()
}

#[test]
fn ctrl_c_says_what_the_drain_waits_for_and_a_second_exits_at_once() {
    use std::io::BufRead;
    use std::time::{Duration, Instant};
    for format in ["json", "text"] {
        let port = free_port();
        let mut child = crate::processes::thirdbody()
            .args(["serve", "--bind", &format!("127.0.0.1:{port}")])
            .args(["--log-format", format, "--shutdown-timeout", "30s"])
            // Without a database file: its results would outlive the process.
            .args(["--database", ":memory:"])
            .env("RUST_LOG", "info")
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        // Log lines as they come, read on another thread.
        let (lines, logged) = std::sync::mpsc::channel();
        let stderr = child.stderr.take().unwrap();
        std::thread::spawn(move || {
            for line in std::io::BufReader::new(stderr).lines() {
                let Ok(line) = line else { break };
                if lines.send(line).is_err() {
                    break;
                }
            }
        });
        let wait_for = |needle: &str| -> String {
            let end = Instant::now() + crate::processes::PATIENCE;
            loop {
                let left = end.saturating_duration_since(Instant::now());
                match logged.recv_timeout(left) {
                    Ok(line) if line.contains(needle) => return line,
                    Ok(_) => {}
                    Err(e) => panic!("no log line with {needle:?} ({format}): {e}"),
                }
            }
        };
        wait_for("listening");
        // A job whose answer is cached finishes as it is accepted; nobody reads it.
        let job = r#"{"kind": "rolling", "input": {"radius": "30 nm"}}"#;
        let (status, _) = post(port, "/v1/rolling", r#"{"radius": "30 nm"}"#);
        assert!(status.starts_with("HTTP/1.1 200"), "{status}");
        let (status, body) = post(port, "/v1/jobs", job);
        assert!(status.starts_with("HTTP/1.1 202"), "{status}");
        assert!(body.contains(r#""status":"succeeded""#), "{body}");

        let pid = child.id().to_string();
        let signal = |name: &str| {
            let sent = Command::new("kill").args([name, &pid]).status().unwrap();
            assert!(sent.success());
        };
        signal("-INT");
        let line = wait_for("shutting down");
        assert!(
            line.contains(
                "shutting down: waiting up to 30 s for 1 finished job whose client has not \
                 read it; press Ctrl-C again to exit now"
            ),
            "{line}"
        );
        // The drain waits for the unread result...
        std::thread::sleep(Duration::from_millis(300));
        assert!(child.try_wait().unwrap().is_none(), "it did not wait");
        // ...until a second Ctrl-C, which exits at once.
        let second = Instant::now();
        signal("-INT");
        let line = wait_for("exiting now");
        assert!(
            line.contains("exiting now: 1 unread result dropped"),
            "{line}"
        );
        let status = loop {
            if let Some(status) = child.try_wait().unwrap() {
                break status;
            }
            assert!(second.elapsed() < Duration::from_secs(5), "still running");
            std::thread::sleep(Duration::from_millis(10));
        };
        assert_eq!(status.code(), Some(130), "{format}");
    }
}

#[test]
fn a_csv_can_say_where_it_comes_from_and_warnings_reach_standard_error() {
    let out = thirdbody(
        &["solve", "-", "--format", "csv", "--provenance"],
        Some(r#"{"kind": "rolling", "input": {"radius": 25}}"#),
    );
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    let first = text.lines().next().unwrap();
    assert!(
        first.starts_with(&format!("# thirdbody {}", env!("CARGO_PKG_VERSION"))),
        "{first}"
    );
    assert!(
        first.contains(&format!("model {}", thirdbody::model::MODEL_VERSION)),
        "{first}"
    );
    assert!(first.contains("input sha256 "), "{first}");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("warning: radius: 25 is 25 m; did you mean \"25 nm\"?"),
        "{stderr}"
    );
}

/// The records of a CSV text (RFC 4180: quoted fields may hold commas, quotes doubled and
/// line breaks).
fn csv_records(text: &str) -> Vec<Vec<String>> {
    let (mut records, mut record, mut field) = (Vec::new(), Vec::new(), String::new());
    let (mut quoted, mut chars) = (false, text.chars().peekable());
    while let Some(c) = chars.next() {
        match (quoted, c) {
            (true, '"') if chars.peek() == Some(&'"') => {
                field.push('"');
                chars.next();
            }
            (true, '"') => quoted = false,
            (true, c) => field.push(c),
            (false, '"') if field.is_empty() => quoted = true,
            (false, ',') => record.push(std::mem::take(&mut field)),
            (false, '\n') => {
                record.push(std::mem::take(&mut field));
                records.push(std::mem::take(&mut record));
            }
            (false, c) => field.push(c),
        }
    }
    assert!(!quoted, "an unterminated quoted field");
    if !field.is_empty() || !record.is_empty() {
        record.push(field);
        records.push(record);
    }
    records
}

#[test]
fn every_output_parses_with_its_provenance() {
    let solve = |job: &str, format: &str| {
        let out = thirdbody(&["solve", job, "--format", format, "--provenance"], None);
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        String::from_utf8(out.stdout).unwrap()
    };
    for job in ["examples/rolling.json", "examples/sweep.json"] {
        // JSON: nothing in front; its meta says where it comes from.
        let json: Value = serde_json::from_str(&solve(job, "json")).unwrap();
        let hash = json["meta"]["input_hash"].as_str().unwrap().to_string();
        let line = format!(
            "thirdbody {} (commit {}), model {}, input sha256 {hash}",
            env!("CARGO_PKG_VERSION"),
            json["meta"]["software"]["commit"].as_str().unwrap(),
            thirdbody::model::MODEL_VERSION
        );

        // CSV: a first `#` line, then a table whose records all have the header's fields.
        let csv = solve(job, "csv");
        let (first, table) = csv.split_once('\n').unwrap();
        assert_eq!(first, format!("# {line}"));
        let records = csv_records(table);
        assert!(records.len() >= 2, "{table}");
        assert!(
            records.iter().all(|r| r.len() == records[0].len()),
            "{table}"
        );

        // SVG: well-formed XML, the provenance in a comment, the root still <svg>.
        let svg = solve(job, "svg");
        let doc = roxmltree::Document::parse(&svg).unwrap_or_else(|e| panic!("{e}: {svg}"));
        assert_eq!(doc.root_element().tag_name().name(), "svg");
        let comments: Vec<&str> = doc
            .root()
            .descendants()
            .filter(|n| n.is_comment())
            .filter_map(|n| n.text())
            .collect();
        assert_eq!(comments, [format!(" {line} ")], "{svg}");
    }
}

#[test]
fn check_exits_0_when_every_check_holds_1_when_one_fails_2_on_bad_input() {
    let out = thirdbody(&["check", "examples/checks.json"], None);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    assert!(String::from_utf8_lossy(&out.stdout).ends_with("6 checks: 6 passed, 0 failed\n"));

    let dir = scratch("check");
    let checks = dir.join("checks.json");
    std::fs::write(
        &checks,
        r#"{"checks": [
            {"name": "low", "job": {"kind": "rolling"}, "expect": {"friction_coefficient": {"max": 0.01}}},
            {"name": "same as before", "job": {"kind": "rolling", "input": {"load": "1.1 nN"}},
             "golden": {"file": "golden/a.json"}}]}"#,
    )
    .unwrap();
    // No golden answer yet: bad input, and the message says how to write it.
    let out = thirdbody(&["check", checks.to_str().unwrap()], None);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--update"));
    // --update writes it; the other check still fails, and the JUnit report says which.
    let junit = dir.join("junit.xml");
    let out = thirdbody(
        &[
            "check",
            checks.to_str().unwrap(),
            "--update",
            "--junit",
            junit.to_str().unwrap(),
        ],
        None,
    );
    assert_eq!(out.status.code(), Some(1));
    let report = String::from_utf8_lossy(&out.stdout);
    assert!(
        report.contains("FAIL  low\n      friction_coefficient = 0.0947"),
        "{report}"
    );
    assert!(report.contains("PASS  same as before"), "{report}");
    let xml = std::fs::read_to_string(&junit).unwrap();
    // Each test case says how long it took, as CI reporters show it (issue 52).
    assert!(
        xml.contains("<testcase name=\"low\" classname=\"thirdbody.rolling\" time=\""),
        "{xml}"
    );
    assert!(
        xml.contains("<failure message=\"friction_coefficient = 0.0947"),
        "{xml}"
    );
    let golden: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("golden/a.json")).unwrap()).unwrap();
    assert!(golden["contact_area"].as_f64().unwrap() > 0.0);
    // A golden answer that moved fails its check.
    let mut moved = golden.clone();
    moved["contact_area"] = serde_json::json!(golden["contact_area"].as_f64().unwrap() * 1.001);
    std::fs::write(dir.join("golden/a.json"), moved.to_string()).unwrap();
    let out = thirdbody(&["check", checks.to_str().unwrap()], None);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stdout).contains("contact_area = "));

    // A malformed bound is said first, though a golden file is missing too: `--update`
    // would only run into it.
    std::fs::write(
        &checks,
        r#"{"checks": [
            {"name": "inverted", "job": {"kind": "rolling"},
             "expect": {"contact_area": {"min": "1 µm^2", "max": "1 nm^2"}}},
            {"name": "new", "job": {"kind": "rolling"}, "golden": {"file": "golden/none.json"}}]}"#,
    )
    .unwrap();
    let out = thirdbody(&["check", checks.to_str().unwrap()], None);
    assert_eq!(out.status.code(), Some(2));
    let said = String::from_utf8_lossy(&out.stderr);
    assert!(
        said.contains("contact_area: min 1e-12 is above max 1e-18"),
        "{said}"
    );
    assert!(!said.contains("--update"), "{said}");

    std::fs::write(
        &checks,
        r#"{"checks": [{"name": "x", "job": {"kind": "nope"}, "expect": {}}]}"#,
    )
    .unwrap();
    let out = thirdbody(&["check", checks.to_str().unwrap()], None);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("unknown kind \"nope\""));
}

#[test]
fn a_check_s_misspelt_path_names_the_nearest_fields_of_the_answer() {
    let checks = scratch("misspelt").join("checks.json");
    std::fs::write(
        &checks,
        r#"{"checks": [{"name": "mu stays low", "job": {"kind": "rolling"},
            "expect": {"friction_coeficient": {"max": 0.1}}}]}"#,
    )
    .unwrap();
    let out = thirdbody(&["check", checks.to_str().unwrap()], None);
    assert_eq!(out.status.code(), Some(1));
    let report = String::from_utf8_lossy(&out.stdout);
    assert!(
        report.contains(
            "FAIL  mu stays low\n      friction_coeficient: the answer has no field at this \
             path; nearest: friction_coefficient, static.friction_coefficient\n"
        ),
        "{report}"
    );
}

/// The kinds are listed once, in the registry: the help of `solve` and README's job line
/// name each of them, and no other.
#[test]
fn the_help_and_the_readme_name_every_kind_of_the_registry() {
    let out = thirdbody(&["solve", "--help"], None);
    assert!(out.status.success());
    let help = String::from_utf8(out.stdout).unwrap();
    let readme =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/README.md")).unwrap();
    let job_line = readme
        .lines()
        .find(|l| l.starts_with("A job is `{\"kind\": "))
        .expect("README says what a job is");
    let listed = |text: &str| -> Vec<String> {
        let kinds = text.split("{\"kind\": ").nth(1).unwrap();
        let kinds = kinds.split(", \"input\"").next().unwrap();
        kinds
            .split(" | ")
            .map(|k| k.trim_matches('"').to_string())
            .collect()
    };
    let registry: Vec<String> = thirdbody::job::registry::NAMES
        .iter()
        .map(|n| n.to_string())
        .collect();
    assert_eq!(listed(&help), registry, "{help}");
    assert_eq!(listed(job_line), registry, "{job_line}");
}

/// A fit's CSV carries what was fitted: each parameter and its standard error beside every
/// residual (issue 52: the CSV had the residuals alone).
#[test]
fn a_fit_s_csv_says_what_was_fitted() {
    let answer = json(&thirdbody(&["solve", "examples/fit.json"], None));
    let out = thirdbody(&["solve", "examples/fit.json", "--format", "csv"], None);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let row: Vec<&str> = text.lines().nth(1).unwrap().split(',').collect();
    for name in answer["parameter_names"].as_array().unwrap() {
        let name = name.as_str().unwrap();
        let column = header
            .iter()
            .position(|h| h.starts_with(&format!("fitted_{name} [")))
            .unwrap_or_else(|| panic!("no column for {name}: {header:?}"));
        let value: f64 = row[column].parse().unwrap();
        assert_eq!(value, answer["parameters"][name]["value"].as_f64().unwrap());
        assert!(header[column + 1].starts_with(&format!("fitted_{name}_standard_error [")));
    }
}
