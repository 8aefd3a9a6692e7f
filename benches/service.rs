//! Speed of the service around the physics core (whose own benchmarks are the model crate's
//! `solver` bench): a rolling sweep job, the data of all of the paper's Figures 3–9 (target:
//! < 50 ms), the work the HTTP service adds to a solve, and a fit of three parameters to 30
//! points (target: ≤ 50 ms). Results and method: BENCHMARKS.md. Run with
//! `cargo bench --bench service`.

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use serde_json::json;
use thirdbody::engine::{self, cache::Solved};
use thirdbody::job::{Control, Job, Kind, Limits, RollingJob, Work};
use thirdbody::render::Format;

/// A rolling sweep job on one thread, whole (validation aside): its marginal cost per point
/// is the difference of the two sizes over the difference of their points.
fn sweep(c: &mut Criterion) {
    let mut group = c.benchmark_group("sweep");
    group.sample_size(20);
    for (loads, speeds) in [(10, 100), (100, 100)] {
        let job = Job::from_value(
            json!({"kind": "sweep", "input": {"vary": {
                "load": (0..loads).map(|i| format!("{} nN", 0.5 + 0.01 * f64::from(i))).collect::<Vec<_>>(),
                "velocity": (0..speeds).map(|i| format!("{} nm/s", 0.1 * f64::from(i))).collect::<Vec<_>>()}}}),
            &Limits::default(),
        )
        .unwrap();
        group.bench_function(format!("rolling_{}_points", loads * speeds), |b| {
            b.iter(|| black_box(engine::run(&job, &Control::new(None, 1)).unwrap()))
        });
    }
    group.finish();
}

/// A 10,000-point rolling sweep's answer rendered as CSV (its per-point cost is the median
/// over 10,000), and as JSON beside it.
fn render(c: &mut Criterion) {
    let mut group = c.benchmark_group("render");
    group.sample_size(20);
    let job = Job::from_value(
        json!({"kind": "sweep", "input": {"vary": {
            "load": (0..100).map(|i| format!("{} nN", 0.5 + 0.01 * f64::from(i))).collect::<Vec<_>>(),
            "velocity": (0..100).map(|i| format!("{} nm/s", 0.1 * f64::from(i))).collect::<Vec<_>>()}}}),
        &Limits::default(),
    )
    .unwrap();
    let answer = engine::run(&job, &Control::new(None, 2)).unwrap();
    for (name, format) in [("csv", Format::Csv), ("json", Format::Json)] {
        group.bench_function(format!("sweep_10000_points_{name}"), |b| {
            b.iter(|| black_box(answer.render(format).unwrap()))
        });
    }
    group.finish();
}

fn figures(c: &mut Criterion) {
    let jobs: Vec<Job> = (3..=9)
        .map(|n| {
            Job::from_value(
                json!({"kind": "figure", "input": {"number": n}}),
                &Limits::default(),
            )
            .unwrap()
        })
        .collect();
    let solves: usize = jobs
        .iter()
        .map(|job| match job.work() {
            Work::Known(n) => n,
            Work::Unknown => 0,
        })
        .sum();
    println!("figures 3-9: {solves} rolling solves");
    let mut group = c.benchmark_group("figures_3_to_9");
    group
        .sample_size(20)
        .measurement_time(Duration::from_secs(8));
    for threads in [1, 2] {
        group.bench_function(format!("threads_{threads}"), |b| {
            b.iter(|| {
                for job in &jobs {
                    black_box(engine::run(job, &Control::new(None, threads)).unwrap());
                }
            })
        });
    }
    group.finish();
}

/// What the HTTP service does for one uncached rolling request besides HTTP itself:
/// validation and cache key, the engine's run (solve and answer), the JSON rendered once.
fn service(c: &mut Criterion) {
    let mut group = c.benchmark_group("service");
    let input = json!({"load": "1 nN"});
    let limits = Limits::default();
    group.bench_function("validate_and_key", |b| {
        b.iter(|| {
            let job = Job::from_input(RollingJob::NAME, black_box(input.clone()), &limits);
            black_box(job.unwrap().cache_key())
        })
    });
    let job = Job::from_input(RollingJob::NAME, input.clone(), &limits).unwrap();
    let control = Control::new(None, 1);
    group.bench_function("engine_run_default_job", |b| {
        b.iter(|| black_box(engine::run(black_box(&job), &control).unwrap()))
    });
    group.bench_function("render_json", |b| {
        b.iter_batched(
            || engine::run(&job, &control).unwrap(),
            |answer| black_box(Solved::new(job.cache_key(), job.kind(), answer).unwrap()),
            criterion::BatchSize::SmallInput,
        )
    });
    group.finish();
}

/// A fit of three parameters (T_σ, T_ε, E_L) to the 30 noisy points of `examples/fit.json`,
/// on one thread (target: ≤ 50 ms).
fn fit(c: &mut Criterion) {
    let text = std::fs::read(concat!(env!("CARGO_MANIFEST_DIR"), "/examples/fit.json")).unwrap();
    let job = Job::from_json(&text, &Limits::default()).unwrap();
    let control = Control::new(None, 1);
    let mut group = c.benchmark_group("fit");
    group.sample_size(20);
    group.bench_function("three_parameters_30_points", |b| {
        b.iter(|| black_box(engine::run(black_box(&job), &control).unwrap()))
    });
    group.finish();
}

/// One rolling request through the whole router (as `thirdbody serve` builds it, no socket):
/// the same input every time (a cache hit after the first), and a new load every time
/// (solved). Their difference is what a solve adds to a request in the process; the
/// throughput ratio of the two over HTTP is `loadtest/ratio.sh`'s. The cache hit again on
/// a service that requires an API key: what the access rules add to a request.
fn http(c: &mut Criterion) {
    use axum::body::Body;
    use axum::http::Request;
    use axum::Router;
    use clap::Parser;
    use thirdbody::http::access::keys::hash_hex;
    use thirdbody::http::{app, AppState, ServeArgs};
    use tower::ServiceExt;

    const KEY: &str = "tb_key-of-the-benchmark-0000000000000001";
    let runtime = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()
        .unwrap();
    let router = |flags: &[&str]| -> Router {
        let config =
            ServeArgs::try_parse_from([&["serve", "--database", ":memory:"][..], flags].concat())
                .unwrap()
                .validate()
                .unwrap();
        runtime.block_on(async { app(AppState::new(config).unwrap()) })
    };
    let (open, keys) = (
        router(&[]),
        serde_json::json!({"keys": [{"name": "lab", "sha256": hash_hex(KEY), "scopes": ["submit"]}]})
            .to_string(),
    );
    let keyed = router(&["--api-keys", &keys, "--anonymous", "none"]);
    let post = |router: &Router, key: Option<&str>, body: String| {
        let mut request = Request::post("/v1/rolling").header("content-type", "application/json");
        if let Some(key) = key {
            request = request.header("x-api-key", key);
        }
        let request = request.body(Body::from(body)).unwrap();
        let response = runtime.block_on(router.clone().oneshot(request)).unwrap();
        assert!(response.status().is_success());
        response
    };
    // Cached from here on.
    post(&open, None, "{}".to_string());
    post(&keyed, Some(KEY), "{}".to_string());
    let mut group = c.benchmark_group("http");
    group.bench_function("rolling_cached", |b| {
        b.iter(|| post(&open, None, "{}".to_string()))
    });
    group.bench_function("rolling_cached_keyed", |b| {
        b.iter(|| post(&keyed, Some(KEY), "{}".to_string()))
    });
    let mut load = 1e-9;
    group.bench_function("rolling_uncached", |b| {
        b.iter(|| {
            load *= 1.0 + 1e-9;
            post(&open, None, format!("{{\"load\": {load:e}}}"))
        })
    });
    group.finish();
}

criterion_group!(benches, sweep, render, figures, service, fit, http);
criterion_main!(benches);
