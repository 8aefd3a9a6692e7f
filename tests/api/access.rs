//! Access rules over HTTP: anonymous callers and API keys, scopes, expiry, tenants (another
//! tenant's job is not found), admins, and the cross-origin preflight this service does not
//! allow. Keys are given inline (`--api-keys {...}`); their file, re-read without a restart,
//! is tested on the binary (`tests/service/access.rs`).

use reqwest::{Method, Response, StatusCode};
use serde_json::{json, Value};
use thirdbody::http::access::keys::hash_hex;

use std::time::Duration;

use crate::helpers::{retry_after, spawn_app, spawn_app_adjusted, TestApp};

const LAB_A: &str = "key-of-lab-a-0000000000000001";
const LAB_A_ROTATED: &str = "key-of-lab-a-0000000000000002";
const LAB_B: &str = "key-of-lab-b-0000000000000003";
const READER: &str = "key-of-a-reader-0000000000004";
const ADMIN: &str = "key-of-the-admin-000000000005";
const EXPIRED: &str = "key-that-expired-000000000006";

/// The keys of these tests, as `--api-keys` takes them inline.
fn keys() -> String {
    let entry = |key: &str, name: &str, scopes: &[&str], expires: Option<&str>| {
        let mut entry = json!({"name": name, "sha256": hash_hex(key), "scopes": scopes});
        if let Some(at) = expires {
            entry["expires"] = at.into();
        }
        entry
    };
    json!({"keys": [
        entry(LAB_A, "lab-a", &["submit", "read"], None),
        entry(LAB_A_ROTATED, "lab-a", &["submit", "read"], Some("2999-01-01T00:00:00Z")),
        entry(LAB_B, "lab-b", &["submit", "read"], None),
        entry(READER, "reader", &["read"], None),
        entry(ADMIN, "ops", &["admin"], None),
        entry(EXPIRED, "old", &["submit", "read"], Some("2020-01-01T00:00:00Z")),
    ]})
    .to_string()
}

async fn service(anonymous: &str) -> TestApp {
    spawn_app(&["--api-keys", &keys(), "--anonymous", anonymous]).await
}

fn with_key(key: &str) -> (&'static str, String) {
    ("x-api-key", key.to_string())
}

async fn send(
    app: &TestApp,
    method: Method,
    path: &str,
    key: Option<&str>,
    body: Option<&Value>,
) -> Response {
    let header = key.map(with_key);
    let headers: Vec<(&str, &str)> = header.iter().map(|(n, v)| (*n, v.as_str())).collect();
    app.send(method, path, &headers, body).await
}

/// The problem of a refused request, checked to be a problem of `status` and `kind`.
async fn refused(response: Response, status: StatusCode, kind: &str) -> String {
    assert_eq!(response.status(), status);
    let www = response.headers().get("www-authenticate").cloned();
    assert_eq!(www.is_some(), status == StatusCode::UNAUTHORIZED, "{www:?}");
    let problem: Value = response.json().await.unwrap();
    assert_eq!(
        problem["type"],
        format!("tag:thirdbody,2026:problems/{kind}"),
        "{problem}"
    );
    problem["detail"].as_str().unwrap().to_string()
}

/// The job id in `path` (`/v1/jobs/{id}...`).
fn id_of(path: &str) -> &str {
    &path["/v1/jobs/".len().."/v1/jobs/".len() + 36]
}

/// `path` with its job id replaced by one no run issued.
fn uuid_like(path: &str) -> String {
    path.replace(id_of(path), "01a21b77-0000-7000-8000-000000000000")
}

/// POSTs `body` as JSON to `path` with the API key `key`.
async fn post_as(app: &TestApp, path: &str, key: &str, body: &Value) -> Response {
    send(app, Method::POST, path, Some(key), Some(body)).await
}

/// The default rolling contact, solved now with `key`.
async fn solve_with(app: &TestApp, key: &str) -> Response {
    send(
        app,
        Method::POST,
        "/v1/rolling",
        Some(key),
        Some(&json!({})),
    )
    .await
}

fn rolling_job(radius: &str) -> Value {
    json!({"kind": "rolling", "input": {"radius": radius}})
}

/// Submits `job` with `key`; returns the job's path.
async fn submit(app: &TestApp, key: Option<&str>, job: &Value) -> String {
    let response = send(app, Method::POST, "/v1/jobs", key, Some(job)).await;
    assert_eq!(response.status(), StatusCode::ACCEPTED);
    response.headers()["location"].to_str().unwrap().to_string()
}

#[tokio::test]
async fn without_keys_configured_everyone_is_anonymous_and_a_key_is_refused() {
    let app = spawn_app(&[]).await;
    assert_eq!(
        app.post("/v1/rolling", &json!({})).await.status(),
        StatusCode::OK
    );
    assert_eq!(app.get("/metrics").await.status(), StatusCode::OK);
    let sent = solve_with(&app, LAB_A).await;
    let detail = refused(sent, StatusCode::UNAUTHORIZED, "unauthorized").await;
    assert!(detail.contains("started without --api-keys"), "{detail}");
}

#[tokio::test]
async fn scopes_decide_what_a_caller_may_do() {
    let app = service("read").await;
    // Anonymous: may read (docs, figures), not submit nor read metrics.
    assert_eq!(app.get("/openapi.json").await.status(), StatusCode::OK);
    let detail = refused(
        app.post("/v1/rolling", &json!({})).await,
        StatusCode::UNAUTHORIZED,
        "unauthorized",
    )
    .await;
    assert!(
        detail.contains("submit scope") && detail.contains("anonymous: read"),
        "{detail}"
    );
    refused(
        app.get("/metrics").await,
        StatusCode::UNAUTHORIZED,
        "unauthorized",
    )
    .await;
    // The probes and the dashboard need nothing.
    for path in ["/healthz", "/readyz", "/"] {
        assert_eq!(app.get(path).await.status(), StatusCode::OK, "{path}");
    }
    // A key with submit: as x-api-key or as a bearer token.
    assert_eq!(solve_with(&app, LAB_A).await.status(), StatusCode::OK);
    let bearer = app
        .post_with(
            "/v1/rolling",
            &[("authorization", &format!("Bearer {LAB_B}"))],
            &json!({}),
        )
        .await;
    assert_eq!(bearer.status(), StatusCode::OK);
    // A reader's key may not submit: 403 naming its scopes.
    let sent = solve_with(&app, READER).await;
    let detail = refused(sent, StatusCode::FORBIDDEN, "forbidden").await;
    assert!(
        detail.contains("\"reader\" has the scopes read, not submit"),
        "{detail}"
    );
    // Only metrics (or admin) reads /metrics.
    let metrics = send(&app, Method::GET, "/metrics", Some(LAB_A), None).await;
    refused(metrics, StatusCode::FORBIDDEN, "forbidden").await;
    assert_eq!(
        send(&app, Method::GET, "/metrics", Some(ADMIN), None)
            .await
            .status(),
        StatusCode::OK
    );
    // Keys not accepted: unknown, expired, two different, not a bearer.
    let unknown = send(
        &app,
        Method::GET,
        "/openapi.json",
        Some("nobody-s-key-000000"),
        None,
    )
    .await;
    assert!(refused(unknown, StatusCode::UNAUTHORIZED, "unauthorized")
        .await
        .contains("not known"));
    let expired = send(&app, Method::GET, "/openapi.json", Some(EXPIRED), None).await;
    let detail = refused(expired, StatusCode::UNAUTHORIZED, "unauthorized").await;
    assert!(
        detail.contains("\"old\" expired at 2020-01-01T00:00:00Z"),
        "{detail}"
    );
    let two = app
        .get_with(
            "/openapi.json",
            &[
                ("x-api-key", LAB_A),
                ("authorization", &format!("Bearer {LAB_B}")),
            ],
        )
        .await;
    assert!(refused(two, StatusCode::UNAUTHORIZED, "unauthorized")
        .await
        .contains("two different keys"));
    // Another scheme (a proxy's Basic credentials) is not a key: the caller is anonymous.
    let basic = [("authorization", "Basic YTpi")];
    let read = app.get_with("/openapi.json", &basic).await;
    assert_eq!(read.status(), StatusCode::OK);
    let body = json!({});
    let submitted = app.post_with("/v1/rolling", &basic, &body).await;
    let detail = refused(submitted, StatusCode::UNAUTHORIZED, "unauthorized").await;
    assert!(detail.contains("callers without an API key"), "{detail}");
}

#[tokio::test]
async fn anonymous_access_can_be_turned_off() {
    let app = service("none").await;
    for path in ["/openapi.json", "/v1/figures/3", "/metrics"] {
        refused(
            app.get(path).await,
            StatusCode::UNAUTHORIZED,
            "unauthorized",
        )
        .await;
    }
    assert_eq!(app.get("/healthz").await.status(), StatusCode::OK);
    let figure = send(&app, Method::GET, "/v1/figures/3", Some(READER), None).await;
    assert_eq!(figure.status(), StatusCode::OK);
}

#[tokio::test]
async fn a_tenants_jobs_are_its_keys_and_the_admins_alone() {
    let app = service("submit,read").await;
    let ours = submit(&app, Some(LAB_A), &rolling_job("30 nm")).await;
    let theirs = submit(&app, Some(LAB_B), &rolling_job("31 nm")).await;
    let anonymous = submit(&app, None, &rolling_job("32 nm")).await;
    app.wait_for_job(&anonymous, |j| j["status"] == "succeeded")
        .await;

    // Another tenant, and anonymous callers, do not find lab-a's job; a rotated key of
    // the same name, and the admin, do.
    for path in [
        ours.clone(),
        format!("{ours}/result"),
        format!("{ours}/events"),
    ] {
        for key in [Some(LAB_B), None] {
            let response = send(&app, Method::GET, &path, key, None).await;
            let detail = refused(response, StatusCode::NOT_FOUND, "not-found").await;
            // As for an id never issued: nothing says the job exists.
            let never = uuid_like(&path);
            let unknown = send(&app, Method::GET, &never, key, None).await;
            let told = refused(unknown, StatusCode::NOT_FOUND, "not-found").await;
            assert_eq!(
                detail.replace(id_of(&path), "ID"),
                told.replace(id_of(&never), "ID")
            );
        }
    }
    for key in [LAB_A, LAB_A_ROTATED, ADMIN] {
        let response = send(&app, Method::GET, &ours, Some(key), None).await;
        assert_eq!(response.status(), StatusCode::OK, "{key}");
    }
    // Nor cancel or delete it.
    let delete = send(&app, Method::DELETE, &ours, Some(LAB_B), None).await;
    assert_eq!(delete.status(), StatusCode::NOT_FOUND);
    // An anonymous job is read by anyone holding its id, as before keys.
    assert_eq!(
        send(&app, Method::GET, &anonymous, Some(LAB_B), None)
            .await
            .status(),
        StatusCode::OK
    );

    let done = within_done(&app, &ours, LAB_A).await;
    let hash = done["input_hash"].as_str().unwrap();

    // Listing: each key its tenant's jobs; the admin any tenant's.
    let listed = |key: &'static str, query: &'static str| {
        let app = &app;
        async move {
            let response = send(
                app,
                Method::GET,
                &format!("/v1/jobs{query}"),
                Some(key),
                None,
            )
            .await;
            let status = response.status();
            (status, response.json::<Value>().await.unwrap())
        }
    };
    let ids = |page: &Value| -> Vec<String> {
        page["jobs"]
            .as_array()
            .unwrap()
            .iter()
            .map(|j| format!("/v1/jobs/{}", j["id"].as_str().unwrap()))
            .collect()
    };
    let (_, page) = listed(LAB_A_ROTATED, "").await;
    assert_eq!(ids(&page), [ours.as_str()]);
    let (_, page) = listed(LAB_B, "").await;
    assert_eq!(ids(&page), [theirs.as_str()]);
    let (_, page) = listed(ADMIN, "?tenant=lab-a").await;
    assert_eq!(ids(&page), [ours.as_str()]);
    let (status, problem) = listed(LAB_B, "?tenant=lab-a").await;
    assert_eq!(status, StatusCode::FORBIDDEN, "{problem}");
    assert!(
        problem["detail"]
            .as_str()
            .unwrap()
            .contains("only an admin"),
        "{problem}"
    );

    // The admin cancels and deletes another tenant's job.
    let deleted = send(&app, Method::DELETE, &theirs, Some(ADMIN), None).await;
    assert_eq!(deleted.status(), StatusCode::OK);
    let gone = send(&app, Method::GET, &theirs, Some(LAB_B), None).await;
    assert_eq!(gone.status(), StatusCode::NOT_FOUND);
    // The input's link: lab-a's answer to lab-a's keys and, by name, to the admin; not to
    // another tenant, even while it is cached (that would tell what lab-a asked).
    let link = format!("/v1/results/{hash}");
    let status_of = |path: String, key: &'static str| {
        let app = &app;
        async move {
            send(app, Method::GET, &path, Some(key), None)
                .await
                .status()
        }
    };
    assert_eq!(status_of(link.clone(), LAB_A).await, StatusCode::OK);
    assert_eq!(status_of(link.clone(), LAB_B).await, StatusCode::NOT_FOUND);
    let named = format!("{link}?tenant=lab-a");
    assert_eq!(status_of(named.clone(), ADMIN).await, StatusCode::OK);
    assert_eq!(status_of(named, LAB_B).await, StatusCode::FORBIDDEN);
}

/// What one tenant asked for is not told to another: its solve of the same input is a miss
/// (and costs it), and the input's link does not find the other's answer.
#[tokio::test]
async fn a_tenant_learns_nothing_of_what_another_asked() {
    let app = service("submit,read").await;
    let cache = |response: &Response| response.headers()["x-cache"].to_str().unwrap().to_string();
    let first = solve_with(&app, LAB_A).await;
    assert_eq!(cache(&first), "miss");
    let answer: Value = first.json().await.unwrap();
    let link = format!(
        "/v1/results/{}",
        answer["meta"]["input_hash"].as_str().unwrap()
    );
    assert_eq!(cache(&solve_with(&app, LAB_A).await), "hit");
    let read = |key: Option<&'static str>| {
        let (app, link) = (&app, &link);
        async move { send(app, Method::GET, link, key, None).await.status() }
    };
    assert_eq!(read(Some(LAB_A)).await, StatusCode::OK);
    assert_eq!(read(Some(LAB_B)).await, StatusCode::NOT_FOUND);
    assert_eq!(read(None).await, StatusCode::NOT_FOUND);
    // Nor by naming the tenant in the link: a link is an input's hash, nothing else.
    for forged in [format!("{link}@lab-a"), format!("{link}%40lab-a")] {
        let response = send(&app, Method::GET, &forged, None, None).await;
        assert_eq!(response.status(), StatusCode::NOT_FOUND, "{forged}");
    }
    assert_eq!(cache(&solve_with(&app, LAB_B).await), "miss");
    assert_eq!(cache(&solve_with(&app, LAB_B).await), "hit");
    assert_eq!(read(Some(LAB_B)).await, StatusCode::OK);
    let anonymous = send(&app, Method::POST, "/v1/rolling", None, Some(&json!({}))).await;
    assert_eq!(cache(&anonymous), "miss");
}

/// Both tenants ran one input, lab-b the later: out of the cache each tenant's link finds
/// its own job's answer (it found the newest job's, lab-b's, and so none for lab-a).
#[tokio::test]
async fn each_tenants_link_finds_its_own_job_out_of_the_cache() {
    let app = spawn_app_adjusted(&["--api-keys", &keys()], |c| {
        c.engine.cache_ttl = Duration::from_millis(1)
    })
    .await;
    let job = rolling_job("34 nm");
    let ours = submit(&app, Some(LAB_A), &job).await;
    let ours = within_done(&app, &ours, LAB_A).await;
    let theirs = submit(&app, Some(LAB_B), &job).await;
    let theirs = within_done(&app, &theirs, LAB_B).await;
    let hash = ours["input_hash"].as_str().unwrap();
    assert_eq!(theirs["input_hash"], hash);
    tokio::time::sleep(std::time::Duration::from_millis(20)).await;
    for key in [LAB_A, LAB_B] {
        let link = format!("/v1/results/{hash}");
        let response = send(&app, Method::GET, &link, Some(key), None).await;
        assert_eq!(response.status(), StatusCode::OK, "{key}");
        assert_eq!(response.headers()["x-input-hash"], hash);
    }
}

#[tokio::test]
async fn a_tenants_answer_by_its_input_needs_its_key_once_out_of_the_cache() {
    // A cache too small to keep the answer: the link reads the job's saved answer.
    let app = spawn_app_adjusted(&["--api-keys", &keys()], |c| {
        c.engine.cache_ttl = Duration::from_millis(1)
    })
    .await;
    let ours = submit(&app, Some(LAB_A), &rolling_job("33 nm")).await;
    let job = within_done(&app, &ours, LAB_A).await;
    let link = format!("/v1/results/{}", job["input_hash"].as_str().unwrap());
    tokio::time::sleep(std::time::Duration::from_millis(20)).await;
    assert_eq!(
        send(&app, Method::GET, &link, Some(LAB_A), None)
            .await
            .status(),
        StatusCode::OK
    );
    assert_eq!(
        send(&app, Method::GET, &link, Some(LAB_B), None)
            .await
            .status(),
        StatusCode::NOT_FOUND
    );
}

async fn within_done(app: &TestApp, path: &str, key: &str) -> Value {
    crate::helpers::within(async {
        loop {
            let job: Value = send(app, Method::GET, path, Some(key), None)
                .await
                .json()
                .await
                .unwrap();
            if job["status"] == "succeeded" {
                return job;
            }
            tokio::time::sleep(std::time::Duration::from_millis(10)).await;
        }
    })
    .await
}

#[tokio::test]
async fn a_cross_origin_preflight_not_allowed_names_the_flag() {
    let preflight = |app: &TestApp, origin: &'static str| {
        app.client
            .request(Method::OPTIONS, app.url("/v1/rolling"))
            .header("origin", origin)
            .header("access-control-request-method", "POST")
            .header("access-control-request-headers", "content-type, x-api-key")
            .send()
    };
    let closed = spawn_app(&[]).await;
    let response = preflight(&closed, "https://lab.example").await.unwrap();
    let detail = refused(response, StatusCode::FORBIDDEN, "forbidden").await;
    assert!(
        detail.contains("--cors-origin https://lab.example"),
        "{detail}"
    );

    let open = spawn_app(&["--cors-origin", "https://lab.example"]).await;
    let allowed = preflight(&open, "https://lab.example").await.unwrap();
    assert_eq!(allowed.status(), StatusCode::OK);
    let headers = allowed.headers()["access-control-allow-headers"]
        .to_str()
        .unwrap()
        .to_lowercase();
    assert!(
        headers.contains("x-api-key") && headers.contains("thirdbody-owner"),
        "{headers}"
    );
    let other = preflight(&open, "https://elsewhere.example").await.unwrap();
    let detail = refused(other, StatusCode::FORBIDDEN, "forbidden").await;
    assert!(
        detail.contains("allows https://lab.example. Add https://elsewhere.example"),
        "{detail}"
    );
}

/// A refusal for a quota: 429 with `Retry-After` (within the minute) and its detail.
async fn over_quota(response: Response) -> String {
    let retry_after = retry_after(&response);
    assert!((1..=60).contains(&retry_after), "{retry_after}");
    refused(response, StatusCode::TOO_MANY_REQUESTS, "quota-exceeded").await
}

#[tokio::test]
async fn points_a_minute_are_each_tenants_and_anonymous_callers_share_theirs() {
    // The callers without a key are one tenant under the quota: two points here, five
    // for the tenants below.
    let keys = keys();
    let app = spawn_app(&["--api-keys", &keys, "--quota-points", "2"]).await;
    crate::clock::early_in_a_minute().await;
    let rolling = |radius: &str| json!({"radius": radius});
    // Callers without a key: two points a minute between them.
    for radius in ["20 nm", "21 nm"] {
        let solved = app.post("/v1/rolling", &rolling(radius)).await;
        assert_eq!(solved.status(), StatusCode::OK);
    }
    let detail = over_quota(app.post("/v1/rolling", &rolling("22 nm")).await).await;
    assert!(
        detail.contains("a caller without an API key asked for 2 points this minute, of the 2"),
        "{detail}"
    );
    // An answer already cached costs nothing.
    assert_eq!(
        app.post("/v1/rolling", &rolling("20 nm")).await.status(),
        StatusCode::OK
    );

    // A tenant's five are its own: a sweep of three points and two contacts, then no more,
    // whichever of its keys asks; another tenant is not held back.
    let app = spawn_app(&["--api-keys", &keys, "--quota-points", "5"]).await;
    let sweep = json!({"base": {"radius": "30 nm"}, "vary": {"load": ["1 nN", "2 nN", "3 nN"]}});
    let swept = post_as(&app, "/v1/sweeps", LAB_A, &sweep).await;
    assert_eq!(swept.status(), StatusCode::OK);
    let job = rolling_job("23 nm");
    submit(&app, Some(LAB_A_ROTATED), &job).await;
    let solved = post_as(&app, "/v1/rolling", LAB_A, &rolling("24 nm")).await;
    assert_eq!(solved.status(), StatusCode::OK);
    let past = post_as(&app, "/v1/rolling", LAB_A, &rolling("25 nm")).await;
    let detail = over_quota(past).await;
    assert!(
        detail.contains("\"lab-a\" asked for 5 points this minute, of the 5"),
        "{detail}"
    );
    let job = post_as(&app, "/v1/jobs", LAB_A, &rolling_job("26 nm")).await;
    over_quota(job).await;
    let theirs = post_as(&app, "/v1/rolling", LAB_B, &rolling("25 nm")).await;
    assert_eq!(theirs.status(), StatusCode::OK);
    // More than a minute's points at once: no wait would help.
    let big =
        json!({"base": {}, "vary": {"load": ["1 nN", "2 nN", "3 nN", "4 nN", "5 nN", "6 nN"]}});
    let response = post_as(&app, "/v1/sweeps", LAB_B, &big).await;
    assert!(response.headers().get("retry-after").is_none());
    let detail = refused(response, StatusCode::TOO_MANY_REQUESTS, "quota-exceeded").await;
    assert!(
        detail.contains("asks for 6 points, more than the 5"),
        "{detail}"
    );
}

#[tokio::test]
async fn a_tenant_has_at_most_its_quota_of_unfinished_jobs() {
    let app = spawn_app(&[
        "--api-keys",
        &keys(),
        "--quota-jobs",
        "1",
        "--pool-size",
        "2",
    ])
    .await;
    let first = submit(&app, Some(LAB_A), &crate::helpers::long_sweep(40)).await;
    let second = post_as(&app, "/v1/jobs", LAB_A_ROTATED, &rolling_job("27 nm")).await;
    let detail = over_quota(second).await;
    assert!(detail.contains("has 1 unfinished jobs"), "{detail}");
    // Another tenant's jobs, and anonymous ones, are not counted.
    submit(&app, Some(LAB_B), &rolling_job("27 nm")).await;
    submit(&app, None, &rolling_job("28 nm")).await;
    // Once the first ends (cancelled), another is taken.
    let cancelled = send(
        &app,
        Method::POST,
        &format!("{first}/cancel"),
        Some(LAB_A),
        None,
    )
    .await;
    assert_eq!(cancelled.status(), StatusCode::OK);
    crate::helpers::within(async {
        loop {
            let job: Value = send(&app, Method::GET, &first, Some(LAB_A), None)
                .await
                .json()
                .await
                .unwrap();
            if job["status"] == "cancelled" {
                break;
            }
            tokio::time::sleep(std::time::Duration::from_millis(10)).await;
        }
    })
    .await;
    submit(&app, Some(LAB_A), &rolling_job("29 nm")).await;
}

/// Concurrent submissions take the last places one at a time: 20 at once under a quota of
/// 2 unfinished jobs let exactly 2 in (each was counted before the others were stored, and
/// 5 got in); anonymous callers have their one share too.
#[tokio::test]
async fn concurrent_submissions_pass_a_quota_of_jobs_no_more_than_it_allows() {
    for (key, quota) in [(Some(LAB_A), 2), (None, 3)] {
        // The callers without a key are one tenant under the same quota: 3 for them here.
        let app = spawn_app(&[
            "--api-keys",
            &keys(),
            "--quota-jobs",
            &quota.to_string(),
            "--anonymous",
            "submit,read",
        ])
        .await;
        let statuses = futures_util::future::join_all((0..20).map(|i| {
            let job = crate::helpers::long_sweep(20 + i);
            let app = &app;
            async move {
                send(app, Method::POST, "/v1/jobs", key, Some(&job))
                    .await
                    .status()
            }
        }))
        .await;
        let accepted = statuses
            .iter()
            .filter(|s| **s == StatusCode::ACCEPTED)
            .count();
        assert_eq!(accepted, quota, "{key:?}: {statuses:?}");
        assert!(
            statuses
                .iter()
                .all(|s| [StatusCode::ACCEPTED, StatusCode::TOO_MANY_REQUESTS].contains(s)),
            "{statuses:?}"
        );
    }
}

/// A point is about ten microseconds of a solver thread: a local answer is one, a continuum
/// answer what its grid costs (7,000 points on the default grid), a continuum fit its
/// expected evaluations (each counted one before). What a solve really took is charged after
/// it (`engine::quota`'s tests: it depends on the machine's speed).
#[tokio::test]
async fn quotas_charge_what_work_costs() {
    let app = spawn_app(&["--api-keys", &keys(), "--quota-points", "5000"]).await;
    let asks = |detail: &str| -> u64 {
        detail["this asks for ".len()..]
            .split(' ')
            .next()
            .and_then(|n| n.parse().ok())
            .unwrap_or_else(|| panic!("{detail}"))
    };
    let fit = json!({"kind": "fit", "input": {
        "layer": {"model": "continuum"},
        "series": [{"radius": "25 nm", "load": "1 nN", "quantity": "friction_coefficient",
            "points": [{"velocity": "1 nm/s", "value": 0.01}, {"velocity": "2 nm/s", "value": 0.009},
                       {"velocity": "4 nm/s", "value": 0.008}]}],
        "parameters": {"relaxation_time": {}, "retardation_time": {}}}});
    let refused_fit = post_as(&app, "/v1/jobs", LAB_A, &fit).await;
    let detail = refused(refused_fit, StatusCode::TOO_MANY_REQUESTS, "quota-exceeded").await;
    assert!(detail.contains("more than the 5000 a minute"), "{detail}");
    assert!(
        asks(&detail) > 1_000_000,
        "a continuum fit of 3 points: {detail}"
    );
    let continuum = json!({"layer": {"model": "continuum"}});
    let refused_solve = post_as(&app, "/v1/rolling", LAB_A, &continuum).await;
    let detail = refused(
        refused_solve,
        StatusCode::TOO_MANY_REQUESTS,
        "quota-exceeded",
    )
    .await;
    assert!((6000..9000).contains(&asks(&detail)), "{detail}");
    // A local answer is a point.
    for radius in ["25 nm", "26 nm", "27 nm"] {
        let local = json!({"radius": radius});
        let response = post_as(&app, "/v1/rolling", LAB_A, &local).await;
        assert_eq!(response.status(), StatusCode::OK);
    }
}

#[tokio::test]
async fn a_checks_suite_is_charged_its_points_whole_before_it_runs() {
    let app = spawn_app(&["--api-keys", &keys(), "--quota-points", "3"]).await;
    crate::clock::early_in_a_minute().await;
    let suite = |radii: &[&str]| {
        let checks: Vec<Value> = radii
            .iter()
            .map(|radius| {
                json!({"name": radius, "job": rolling_job(radius),
                    "expect": {"friction_coefficient": {"max": 1}}})
            })
            .collect();
        json!({ "checks": checks })
    };
    let run = |radii: &'static [&'static str]| {
        let body = suite(radii);
        let app = &app;
        async move { post_as(app, "/v1/checks", LAB_A, &body).await }
    };
    // Four checks are more points than a minute's: refused whole, no wait would help.
    let response = run(&["20 nm", "21 nm", "22 nm", "23 nm"]).await;
    assert!(response.headers().get("retry-after").is_none());
    let detail = refused(response, StatusCode::TOO_MANY_REQUESTS, "quota-exceeded").await;
    assert!(
        detail.contains("asks for 4 points, more than the 3"),
        "{detail}"
    );
    // Three run; the same three again are cached and cost nothing; one more is over.
    for _ in 0..2 {
        assert_eq!(
            run(&["20 nm", "21 nm", "22 nm"]).await.status(),
            StatusCode::OK
        );
    }
    let detail = over_quota(run(&["23 nm"]).await).await;
    assert!(
        detail.contains("\"lab-a\" asked for 3 points this minute, of the 3"),
        "{detail}"
    );
}
