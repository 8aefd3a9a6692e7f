//! The job-kind seam: a kind is one type behind `Kind`; the engine runs any kind, known or
//! not to the registry; every kind's canonical input reads back as the same job; every
//! answer renders as JSON and as CSV from one declaration of its columns.

use std::sync::Arc;
use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};
use serde_json::{json, Value};
use thirdbody::engine::metrics::Metrics;
use thirdbody::engine::store::{JobRecord, JobState, JobStatus};
use thirdbody::engine::{self, Engine, EngineConfig};
use thirdbody::job::{
    Control, Job, JobError, Kind, Limits, Meta, References, Validated, Work, ROLLING_REFERENCES,
};
use thirdbody::render::svg::{Axis, Chart, Layer};
use thirdbody::render::Picture;
use thirdbody::render::{Column, Format, Output, RenderError, Table, UnitTable};
use thirdbody::unit_table;
use utoipa::ToSchema;

/// A scratch kind that cannot tell its work in advance (as an iterative fit), or with
/// `known` can (as a sweep's points): it counts `steps` units of work, a millisecond each,
/// checking its control between them, and says how many threads it was let use.
#[derive(Debug, PartialEq)]
struct Countdown {
    steps: usize,
    known: bool,
}

thirdbody::described! {
    #[derive(Debug, PartialEq, Serialize, ToSchema)]
    struct CountdownOutput {
        steps: usize => [unit ""],
        threads: usize => [unit ""],
        meta: Meta => [],
    }
}

impl Output for CountdownOutput {
    const UNITS: &'static UnitTable = unit_table!(CountdownOutput);
    type Picture = CountdownPicture;

    fn table(&self) -> Table {
        Table::new(
            &[Column::count("steps", |o: &CountdownOutput| o.steps)],
            [self],
        )
    }
}

/// What the picture of a countdown shows: its steps.
#[derive(Deserialize)]
struct CountdownPicture {
    steps: f64,
}

impl Picture for CountdownPicture {
    /// The steps as one bar.
    fn chart(self) -> Result<Chart, RenderError> {
        let steps = self.steps;
        Ok(Chart {
            title: "countdown".to_string(),
            x: Axis::new("step", ""),
            y: Axis::new("steps", ""),
            layers: vec![Layer::Line {
                name: "steps".to_string(),
                group: "steps".to_string(),
                points: vec![(0.0, 0.0), (steps, steps)],
                dashed: false,
            }],
            equal_aspect: false,
            notes: Vec::new(),
        })
    }
}

/// The input of a countdown.
#[derive(ToSchema)]
#[allow(dead_code)]
struct CountdownInput {
    steps: Option<u64>,
}

impl Kind for Countdown {
    const NAME: &'static str = "countdown";
    type Input = CountdownInput;
    type Output = CountdownOutput;

    fn validate(input: Value, _limits: &Limits) -> Result<Validated<Self>, JobError> {
        let steps = input["steps"].as_u64().unwrap_or(1);
        let steps = usize::try_from(steps).unwrap_or(usize::MAX);
        let known = input["known"].as_bool().unwrap_or(false);
        Ok(Countdown { steps, known }.into())
    }

    fn canonical(&self) -> Value {
        match self.known {
            true => json!({ "steps": self.steps, "known": true }),
            false => json!({ "steps": self.steps }),
        }
    }

    fn references(&self) -> &'static References {
        &ROLLING_REFERENCES
    }

    fn work(&self) -> Work {
        match self.known {
            true => Work::Known(self.steps),
            false => Work::Unknown,
        }
    }

    fn run(&self, meta: Meta, control: &Control) -> Result<CountdownOutput, JobError> {
        for _ in 0..self.steps {
            control.check()?;
            std::thread::sleep(Duration::from_millis(1));
            control.advance(1);
        }
        Ok(CountdownOutput {
            steps: self.steps,
            threads: control.threads(),
            meta,
        })
    }
}

fn engine() -> Arc<Engine> {
    engine_of(1)
}

fn engine_of(pool_size: usize) -> Arc<Engine> {
    let config = EngineConfig {
        pool_size,
        solve_deadline: Duration::from_secs(30),
        job_deadline: Duration::from_secs(60),
        max_queued_jobs: 4,
        memory_budget: 1 << 20,
        max_jobs: 100,
        cache_ttl: Duration::from_secs(60),
        job_retention: Duration::from_secs(60),
        database: thirdbody::engine::archive::IN_MEMORY.to_string(),
        history_retention: Duration::from_secs(3600),
    };
    Engine::new(config, Metrics::noop()).expect("an engine on a database in memory starts")
}

#[test]
fn a_kind_of_unknown_size_runs_and_stops_on_cancel_and_deadline() {
    let job = countdown(5, false);
    assert_eq!(job.kind(), "countdown");
    assert_eq!(job.work(), Work::Unknown);
    let answer = engine::run(&job, &Control::new(None, 1)).unwrap();
    let out: CountdownOutput = answer.downcast().unwrap();
    assert_eq!(out.steps, 5);
    assert_eq!(out.meta.input.get(), json!({"steps": 5}).to_string());

    let long = countdown(1_000_000, false);
    let late = Control::new(Some(Instant::now() + Duration::from_millis(20)), 1);
    assert_eq!(engine::run(&long, &late), Err(JobError::DeadlineExceeded));
    assert!(late.done() > 0 && late.done() < 1_000);
    let cancelled = Control::new(None, 1);
    cancelled.cancel();
    assert_eq!(engine::run(&long, &cancelled), Err(JobError::Cancelled));
    assert_eq!(cancelled.done(), 0);
}

#[tokio::test]
async fn the_engine_runs_an_unregistered_kind_reports_its_progress_and_cancels_it() {
    let engine = engine();
    let record = engine
        .submit(countdown(1_000_000, false).keyed(), None, None)
        .await
        .unwrap();
    assert_eq!(
        (record.kind.name(), record.work),
        ("countdown", Work::Unknown)
    );
    let started = Instant::now();
    loop {
        let now = engine.jobs.job(record.id).await.unwrap();
        if now.done >= 20 {
            assert_eq!(now.state.status(), JobStatus::Running);
            break;
        }
        assert!(started.elapsed() < Duration::from_secs(60), "no progress");
        tokio::time::sleep(Duration::from_millis(5)).await;
    }
    let cancel = Instant::now();
    let stopped = engine.jobs.cancel(record.id).await.unwrap();
    assert_eq!(stopped.state.status(), JobStatus::Cancelled);
    // The job checks its control every millisecond; the whole run would take 17 minutes.
    assert!(
        cancel.elapsed() < Duration::from_secs(1),
        "{:?}",
        cancel.elapsed()
    );

    let done = finished(&engine, countdown(30, false)).await;
    assert_eq!((done.state.status(), done.done), (JobStatus::Succeeded, 30));
}

/// A countdown of `steps`, its work known in advance or not.
fn countdown(steps: usize, known: bool) -> Job {
    Job::new(Countdown { steps, known })
}

/// Submits `job` to `engine` and waits for its end: its record then.
async fn finished(engine: &Engine, job: Job) -> JobRecord {
    let record = engine.submit(job.keyed(), None, None).await.unwrap();
    let mut status = engine.jobs.watch(record.id).unwrap();
    status.wait_for(|s| s.is_finished()).await.unwrap();
    engine.jobs.job(record.id).await.unwrap()
}

/// Issue 47: a job whose units can be spread (a sweep's points) is lent the pool's idle
/// threads while it runs, all but one, which stays the requests'; one that cannot (a fit)
/// keeps its one; pools of one and two lend none.
#[tokio::test]
async fn a_job_of_many_units_is_lent_the_pools_idle_threads_but_one() {
    let cases = [
        (4, true, 3),
        (3, true, 2),
        (4, false, 1),
        (2, true, 1),
        (1, true, 1),
    ];
    for (pool, known, threads) in cases {
        let done = finished(&engine_of(pool), countdown(5, known)).await;
        let JobState::Succeeded(result) = done.state else {
            panic!("{:?}", done.state);
        };
        let (json, _) = result.bodies().await.unwrap();
        let answer: Value = serde_json::from_slice(&json).unwrap();
        assert_eq!(
            answer["threads"], threads,
            "a pool of {pool}, known: {known}"
        );
    }
}

fn job(value: Value) -> Job {
    Job::from_value(value, &Limits::default()).unwrap()
}

/// One job of every registered kind, with its defaults and without.
fn jobs() -> Vec<Job> {
    [
        json!({"kind": "rolling"}),
        json!({"kind": "rolling", "input": {"radius": "50 nm", "layer": {"thickness": "80 nm"},
            "options": {"quadrature": "midpoint", "pressure_grid": 5}}}),
        json!({"kind": "three_body", "input": {"operating": {"total_load": "1 mN"}}}),
        json!({"kind": "three_body", "input": {"operating": {"separation": "55 nm"},
            "particle": {"elastic_modulus": "100 GPa"}, "layer_contact": "hertz",
            "asperities": {"density": "1e14 m^-2", "tip_radius": "1 um",
                           "height_std": "2 nm", "hardness": "2 GPa"}}}),
        json!({"kind": "sweep", "input": {"vary": {"load": ["1 nN", "1.2 nN"]}}}),
        json!({"kind": "sweep", "input": {"kind": "three_body",
            "vary": {"particle_load": ["1 nN", "2 nN"], "mean_diameter": ["40 nm", "50 nm"]}}}),
        json!({"kind": "sweep", "input": {"kind": "three_body",
            "base": {"operating": {"separation": "50 nm"},
                     "distribution": {"min_diameter": "30 nm"}},
            "vary": {"velocity": [0, "4 nm/s"]}}}),
        json!({"kind": "figure", "input": {"number": 3}}),
    ]
    .into_iter()
    .map(job)
    .collect()
}

#[test]
fn every_canonical_input_reads_back_as_the_same_job() {
    for job in jobs() {
        let again = Job::from_input(job.kind().name(), job.canonical(), &Limits::default())
            .unwrap_or_else(|e| panic!("{}: {e}: {}", job.kind(), job.canonical()));
        assert_eq!(again, job, "{}", job.canonical());
        assert_eq!(again.canonical(), job.canonical());
        assert_eq!(again.cache_key(), job.cache_key());
    }
}

#[test]
fn a_three_body_sweep_whose_bounds_follow_the_mean_has_another_key_than_fixed_bounds() {
    let vary = json!({"mean_diameter": ["50 nm", "80 nm"]});
    let following = job(json!({"kind": "sweep", "input": {"kind": "three_body",
        "base": {"operating": {"separation": "60 nm"}}, "vary": vary}}));
    // The bounds the base would have at its default mean, given explicitly: fixed.
    let fixed = job(json!({"kind": "sweep", "input": {"kind": "three_body",
        "base": {"operating": {"separation": "60 nm"},
                 "distribution": {"min_diameter": "35 nm", "max_diameter": "65 nm"}},
        "vary": vary}}));
    assert_ne!(following.cache_key(), fixed.cache_key());
}

#[test]
fn every_answer_renders_as_json_and_as_a_rectangular_csv() {
    for job in jobs() {
        let answer = engine::run(&job, &Control::default()).unwrap();
        let json: Value = serde_json::from_slice(&answer.render(Format::Json).unwrap()).unwrap();
        assert_eq!(json["meta"]["input_hash"], json!(job.cache_key()));
        let csv = String::from_utf8(answer.render(Format::Csv).unwrap()).unwrap();
        let table = answer.table();
        assert!(!table.rows.is_empty(), "{}", job.kind());
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines.len(), 1 + table.rows.len(), "{csv}");
        let header = lines[0].split(',').count();
        assert_eq!(header, table.headings.len());
        for row in &table.rows {
            assert_eq!(row.len(), header, "{}", job.kind());
        }
    }
}

/// A memo that counts what it is asked.
#[derive(Debug, Default)]
struct CountingMemo {
    kept: std::sync::Mutex<std::collections::HashMap<String, thirdbody::job::Kept>>,
    recalled: std::sync::atomic::AtomicUsize,
}

impl thirdbody::job::Memo for CountingMemo {
    fn recall(&self, key: &str) -> Option<thirdbody::job::Kept> {
        let found = self.kept.lock().unwrap().get(key).cloned();
        if found.is_some() {
            self.recalled
                .fetch_add(1, std::sync::atomic::Ordering::SeqCst);
        }
        found
    }

    fn keep(&self, key: String, value: thirdbody::job::Kept, _bytes: usize) {
        self.kept.lock().unwrap().insert(key, value);
    }
}

#[test]
fn a_sweep_cut_by_its_deadline_leaves_its_solved_points_to_its_retry() {
    // Points solved exactly (its own rule) are kept; table points cost less than keeping.
    let sweep = job(
        json!({"kind": "sweep", "input": {"base": {"options": {"strips": 128}}, "vary": {
        "radius": (1..=20).map(|i| format!("{} nm", 20 + i)).collect::<Vec<_>>(),
        "load": (0..10).map(|i| format!("{} pN", 1000 + 40 * i)).collect::<Vec<_>>(),
        "velocity": (1..=10).map(|i| format!("{i} nm/s")).collect::<Vec<_>>()}}}),
    );
    let memo = Arc::new(CountingMemo::default());
    let cut =
        Control::new(Some(Instant::now() + Duration::from_millis(20)), 1).with_memo(memo.clone());
    assert_eq!(engine::run(&sweep, &cut), Err(JobError::DeadlineExceeded));
    let solved_before = memo.kept.lock().unwrap().len();
    assert!(solved_before > 0 && solved_before < 2000, "{solved_before}");
    let retry = Control::new(None, 1).with_memo(memo.clone());
    let answer = engine::run(&sweep, &retry).unwrap();
    let recalled = memo.recalled.load(std::sync::atomic::Ordering::SeqCst);
    assert_eq!(recalled, solved_before);
    assert_eq!(answer, engine::run(&sweep, &Control::new(None, 1)).unwrap());
}

#[test]
fn only_jobs_certain_to_be_quick_run_on_the_callers_thread() {
    assert!(job(json!({"kind": "rolling"})).is_small());
    for heavy in [
        json!({"kind": "rolling", "input": {"options": {"pressure_grid": 501}}}),
        json!({"kind": "rolling", "input": {"options": {"boundary_points": 10001}}}),
        json!({"kind": "rolling", "input": {"options": {"strips": 1024}}}),
        json!({"kind": "sweep", "input": {"vary": {"load": ["1 nN", "2 nN"]}}}),
        json!({"kind": "three_body", "input": {"operating": {"total_load": "1 mN"}}}),
        json!({"kind": "figure", "input": {"number": 3}}),
    ] {
        assert!(!job(heavy.clone()).is_small(), "{heavy}");
    }
}
