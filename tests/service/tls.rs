//! A fleet on a Redis that speaks only TLS (`rediss://`), as a managed Redis does: the
//! service checks the server's certificate against the certificates the machine trusts
//! (`SSL_CERT_FILE` names a CA here, as an operator would for a private one) and refuses one
//! it cannot check.

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use reqwest::Client;
use serde_json::json;

use crate::fleet::{
    answering, finished, free_port, get_json, redis_server_available, redis_with, submit, Process,
};
use crate::processes::{thirdbody, PATIENCE};

const PASSWORD: &str = "s3cret-over-tls";

/// Runs `openssl` with `args` in `dir`.
fn openssl(dir: &Path, args: &[&str]) {
    let out = Command::new("openssl")
        .current_dir(dir)
        .args(args)
        .output()
        .expect("openssl runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A CA (`ca.crt`) and a certificate it signed for localhost (`redis.crt`, `redis.key`).
fn certificates(dir: &Path) {
    let days = ["-days", "2"];
    openssl(
        dir,
        &[
            &[
                "req", "-x509", "-newkey", "rsa:2048", "-nodes", "-keyout", "ca.key",
            ][..],
            &["-out", "ca.crt", "-subj", "/CN=thirdbody test CA"],
            &days,
        ]
        .concat(),
    );
    openssl(
        dir,
        &[
            "req",
            "-newkey",
            "rsa:2048",
            "-nodes",
            "-keyout",
            "redis.key",
            "-out",
            "redis.csr",
            "-subj",
            "/CN=localhost",
        ],
    );
    std::fs::write(
        dir.join("san"),
        "subjectAltName=DNS:localhost,IP:127.0.0.1\n",
    )
    .unwrap();
    openssl(
        dir,
        &[
            &[
                "x509",
                "-req",
                "-in",
                "redis.csr",
                "-CA",
                "ca.crt",
                "-CAkey",
                "ca.key",
            ][..],
            &["-CAcreateserial", "-out", "redis.crt", "-extfile", "san"],
            &days,
        ]
        .concat(),
    );
}

/// `thirdbody serve` on `port` with its Redis at `url`, trusting the CA file `trusted`; its
/// log in `log`.
fn serve(port: u16, url: &str, trusted: &Path, log: &Path) -> Process {
    Process(
        thirdbody()
            .args(["serve", "--bind", &format!("127.0.0.1:{port}")])
            .args(["--redis-url", url, "--log-format", "text"])
            .env("SSL_CERT_FILE", trusted)
            .stdout(Stdio::null())
            .stderr(std::fs::File::create(log).unwrap())
            .spawn()
            .unwrap(),
    )
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_fleet_works_on_a_redis_over_tls_whose_certificate_it_checks() {
    let openssl_runs = Command::new("openssl").arg("version").output().is_ok();
    if !redis_server_available() || !openssl_runs {
        eprintln!("SKIPPED: redis-server or openssl is not on PATH (`.ci/run` installs them)");
        return;
    }
    let dir = std::env::temp_dir().join(format!("thirdbody-tls-{}", free_port()));
    std::fs::create_dir_all(&dir).unwrap();
    certificates(&dir);
    let redis = free_port();
    let file = |name: &str| dir.join(name).to_str().unwrap().to_string();
    let (port, cert, key, ca) = (
        redis.to_string(),
        file("redis.crt"),
        file("redis.key"),
        file("ca.crt"),
    );
    let _redis = redis_with(
        redis,
        &[
            "--port",
            "0",
            "--tls-port",
            &port,
            "--tls-cert-file",
            &cert,
            "--tls-key-file",
            &key,
            "--tls-ca-cert-file",
            &ca,
            "--tls-auth-clients",
            "no",
            "--requirepass",
            PASSWORD,
        ],
    );
    let url = format!("rediss://:{PASSWORD}@localhost:{redis}");
    let http = Client::new();

    // Trusting the CA: ready, and a job goes through the Redis stream and back.
    let port = free_port();
    let _trusting = serve(port, &url, &dir.join("ca.crt"), &dir.join("trusting.log"));
    let base = answering(&http, port).await;
    let ready = get_json(&http, format!("{base}/readyz")).await;
    assert_eq!(ready["status"], "ready", "{ready}");
    let id = submit(&http, &base, json!({"kind": "rolling", "input": {}})).await;
    assert_eq!(finished(&http, &base, &id).await["status"], "succeeded");

    // Trusting another CA (the server's own certificate is no authority): Redis is
    // unreachable, a job is refused (none is lost), /readyz says so, and the log says why,
    // the password hidden.
    let port = free_port();
    let log = dir.join("doubting.log");
    let _doubting = serve(port, &url, &dir.join("redis.crt"), &log);
    let base = answering(&http, port).await;
    let start = Instant::now();
    loop {
        let ready = get_json(&http, format!("{base}/readyz")).await;
        if ready["redis"]["jobs"] == "down" {
            assert_eq!(ready["status"], "degraded", "{ready}");
            break;
        }
        assert!(
            start.elapsed() < PATIENCE,
            "{ready}\n{}",
            std::fs::read_to_string(&log).unwrap_or_default()
        );
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    let job = json!({"kind": "rolling", "input": {}});
    let refused = http.post(format!("{base}/v1/jobs")).json(&job).send();
    assert_eq!(refused.await.unwrap().status(), 503);
    let logged = std::fs::read_to_string(&log).unwrap();
    assert!(
        logged.contains("Redis unreachable") && logged.contains("certificate"),
        "{logged}"
    );
    assert!(!logged.contains(PASSWORD), "{logged}");
    let _ = std::fs::remove_dir_all(&dir);
}
