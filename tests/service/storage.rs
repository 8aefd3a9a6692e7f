//! The database of saved analyses when it cannot be written: on a full filesystem (a small
//! tmpfs mounted by the test, which needs root: without it the test says it was skipped),
//! removed while the service runs, or damaged before it starts. Accepted means kept: a job
//! that cannot be recorded is refused, `/readyz` says why, and every job accepted is
//! readable, finished, after a restart.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use reqwest::{Client, StatusCode};
use serde_json::{json, Value};

use crate::fleet::{answering, free_port};
use crate::processes::{scratch, thirdbody, Process};

/// A tmpfs of `size` mounted at a directory of the test's own; unmounted when dropped.
struct SmallDisk(PathBuf);

impl SmallDisk {
    /// The mount, or why it cannot be made here.
    fn mount(name: &str, size: &str) -> Result<SmallDisk, String> {
        let dir = std::env::temp_dir().join(format!("thirdbody-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
        let out = Command::new("mount")
            .args(["-t", "tmpfs", "-o", &format!("size={size}"), "tmpfs"])
            .arg(&dir)
            .output()
            .map_err(|e| format!("mount: {e}"))?;
        if !out.status.success() {
            let _ = std::fs::remove_dir(&dir);
            return Err(String::from_utf8_lossy(&out.stderr).trim().to_string());
        }
        Ok(SmallDisk(dir))
    }

    /// Fills the filesystem to its last byte with a file; returns it.
    fn fill(&self) -> PathBuf {
        use std::io::Write;
        let filler = self.0.join("filler");
        let mut file = std::fs::File::create(&filler).unwrap();
        let block = vec![0u8; 4096];
        while file.write_all(&block).is_ok() {}
        while file.write_all(&block[..1]).is_ok() {}
        filler
    }
}

impl Drop for SmallDisk {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg(&self.0).status();
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// `thirdbody serve` alone on the database `database`; its base URL.
async fn serve(http: &Client, database: &Path) -> (Process, String) {
    let port = free_port();
    let child = thirdbody()
        .args(["serve", "--bind", &format!("127.0.0.1:{port}")])
        .arg("--database")
        .arg(database)
        .args(["--log-format", "text"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("thirdbody starts");
    let process = Process(child);
    (process, answering(http, port).await)
}

/// A rolling job of its own input (`i` sets its radius).
fn job(i: usize) -> Value {
    json!({"kind": "rolling", "input": {"radius": format!("{} nm", 20 + i)}})
}

async fn submit(http: &Client, base: &str, job: &Value) -> (StatusCode, Value) {
    let response = http
        .post(format!("{base}/v1/jobs"))
        .json(job)
        .send()
        .await
        .unwrap();
    (response.status(), response.json().await.unwrap())
}

async fn get(http: &Client, url: String) -> (StatusCode, Value) {
    let response = http.get(url).send().await.unwrap();
    (response.status(), response.json().await.unwrap())
}

/// The job `id` once it has finished (a rolling job takes microseconds: a bound of a
/// minute is for a machine under any load), failing with its last view.
async fn finished(http: &Client, base: &str, id: &str) -> Value {
    let start = Instant::now();
    loop {
        let (_, view) = get(http, format!("{base}/v1/jobs/{id}")).await;
        if !matches!(view["status"].as_str(), Some("queued" | "running")) {
            return view;
        }
        assert!(start.elapsed() < Duration::from_secs(60), "{view}");
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
}

/// Stops `process` by SIGTERM, waiting for its drain.
fn terminate(process: &mut Process) {
    process.sigterm();
    let status = process.0.wait().unwrap();
    assert!(status.success(), "{status}");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_full_disk_refuses_jobs_rather_than_lose_them() {
    let disk = match SmallDisk::mount("full-disk", "2m") {
        Ok(disk) => disk,
        Err(why) => {
            println!("skipped: a tmpfs cannot be mounted here ({why})");
            return;
        }
    };
    let database = disk.0.join("analyses.db");
    let http = Client::new();
    let (mut server, base) = serve(&http, &database).await;
    let mut accepted = Vec::new();
    for i in 0..5 {
        let (status, view) = submit(&http, &base, &job(i)).await;
        assert_eq!(status, StatusCode::ACCEPTED, "{view}");
        accepted.push(view["id"].as_str().unwrap().to_string());
    }
    for id in &accepted {
        assert_eq!(finished(&http, &base, id).await["status"], "succeeded");
    }
    let filler = disk.fill();
    // The log may have room left in its pages: submissions go on until it has none.
    let mut refused = None;
    for i in 5..2000 {
        let (status, view) = submit(&http, &base, &job(i)).await;
        match status {
            StatusCode::ACCEPTED => accepted.push(view["id"].as_str().unwrap().to_string()),
            StatusCode::SERVICE_UNAVAILABLE => {
                refused = Some(view);
                break;
            }
            other => panic!("{other}: {view}"),
        }
    }
    let refused = refused.expect("a full disk refuses a job at last");
    assert_eq!(refused["type"], "tag:thirdbody,2026:problems/unavailable");
    let detail = refused["detail"].as_str().unwrap();
    assert!(detail.contains("cannot be written"), "{detail}");
    let (status, ready) = get(&http, format!("{base}/readyz")).await;
    assert_eq!(status, StatusCode::OK);
    assert_eq!(ready["status"], "degraded", "{ready}");
    assert!(ready["reasons"][0]
        .as_str()
        .is_some_and(|r| r.contains("database of saved analyses")));
    // Room again: the ends that could not be saved are saved before the process ends,
    // though nothing was written since.
    std::fs::remove_file(filler).unwrap();
    for id in &accepted {
        assert_eq!(finished(&http, &base, id).await["status"], "succeeded");
    }
    terminate(&mut server);
    // After a restart every job accepted is there, finished, its answer whole; and the
    // service takes jobs again.
    let (_server, base) = serve(&http, &database).await;
    for id in &accepted {
        let (status, view) = get(&http, format!("{base}/v1/jobs/{id}")).await;
        assert_eq!(status, StatusCode::OK, "{id}: {view}");
        assert_eq!(view["status"], "succeeded", "{view}");
        let (status, answer) = get(&http, format!("{base}/v1/jobs/{id}/result")).await;
        assert_eq!(status, StatusCode::OK, "{answer}");
        assert!(answer["contact_area"].as_f64().is_some_and(|a| a > 0.0));
    }
    let (status, view) = submit(&http, &base, &job(9999)).await;
    assert_eq!(status, StatusCode::ACCEPTED, "{view}");
    let (_, ready) = get(&http, format!("{base}/readyz")).await;
    assert_eq!(ready["status"], "ready", "{ready}");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_database_removed_while_running_degrades_readiness_and_refuses_jobs() {
    let dir = scratch("removed");
    let database = dir.join("analyses.db");
    let http = Client::new();
    let (_server, base) = serve(&http, &database).await;
    let (status, _) = submit(&http, &base, &job(0)).await;
    assert_eq!(status, StatusCode::ACCEPTED);
    std::fs::remove_file(&database).unwrap();
    let (_, ready) = get(&http, format!("{base}/readyz")).await;
    assert_eq!(ready["status"], "degraded", "{ready}");
    let reason = ready["reasons"][0].as_str().unwrap();
    assert!(
        reason.contains("was removed while the service runs"),
        "{reason}"
    );
    let (status, refused) = submit(&http, &base, &job(1)).await;
    assert_eq!(status, StatusCode::SERVICE_UNAVAILABLE, "{refused}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_damaged_database_is_refused_at_start_saying_how_to_go_on() {
    let dir = scratch("damaged");
    let database = dir.join("analyses.db");
    // 4 KiB of bytes that are no database.
    let noise: Vec<u8> = (0..4096u32)
        .map(|i| (i.wrapping_mul(2654435761) >> 13) as u8)
        .collect();
    std::fs::write(&database, noise).unwrap();
    let out = thirdbody()
        .args(["serve", "--bind", &format!("127.0.0.1:{}", free_port())])
        .arg("--database")
        .arg(&database)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1), "{out:?}");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains(&database.display().to_string()), "{stderr}");
    assert!(stderr.contains("move the file aside"), "{stderr}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A job finished before the shutdown, or during it, and never read is in the database, for
/// the next process to give: the drain does not wait out its timeout for its client (it did
/// for the first, and, issue 52, for the second: one Ctrl-C waited 30 s).
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn the_drain_does_not_wait_for_unread_jobs_the_database_keeps() {
    // A continuum sweep runs for a good part of a second: still running at the SIGTERM.
    let running = json!({"kind": "sweep", "input": {"base": {"layer": {"model": "continuum"}},
        "vary": {"load": ["0.5 nN", "0.6 nN", "0.7 nN", "0.8 nN", "0.9 nN", "1 nN"]}}});
    for (name, job, before) in [("unread", job(0), 200), ("running", running, 0)] {
        let dir = scratch(name);
        let database = dir.join("analyses.db");
        let http = Client::new();
        let port = free_port();
        let child = thirdbody()
            .args(["serve", "--bind", &format!("127.0.0.1:{port}")])
            .arg("--database")
            .arg(&database)
            .args(["--shutdown-timeout", "10m"])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap();
        let mut server = Process(child);
        let base = answering(&http, port).await;
        let (status, view) = submit(&http, &base, &job).await;
        assert_eq!(status, StatusCode::ACCEPTED, "{view}");
        let id = view["id"].as_str().unwrap().to_string();
        if name == "running" {
            assert_eq!(view["status"], "queued", "{view}");
        }
        // Not read by its client here.
        let start = Instant::now();
        tokio::time::sleep(Duration::from_millis(before)).await;
        server.sigterm();
        let exited = loop {
            if let Some(status) = server.0.try_wait().unwrap() {
                break status;
            }
            // Far below the drain's bound of ten minutes, far above what exiting takes.
            assert!(
                start.elapsed() < Duration::from_secs(60),
                "the drain waited for the {name} job"
            );
            tokio::time::sleep(Duration::from_millis(20)).await;
        };
        assert!(exited.success(), "{exited}");
        let (_server, base) = serve(&http, &database).await;
        let read = finished(&http, &base, &id).await;
        assert_eq!(read["status"], "succeeded", "{name}: {read}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
