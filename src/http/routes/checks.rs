//! `POST /v1/checks`: the checks `thirdbody check` runs, for a pipeline without the binary.

use std::time::Instant;

use axum::extract::State;
use axum::http::{header, HeaderMap};
use axum::response::{IntoResponse, Response};

use crate::check::{CheckReport, CheckSpec, ChecksInput, Report, Suite};
use crate::engine::{CacheUse, EngineError};
use crate::http::accept::Accept;
use crate::http::access::{self, Caller};
use crate::http::body::{offload, JsonBody};
use crate::http::error::ApiError;
use crate::http::responses::{BadBody, Busy, ChecksFailed, NotAcceptable};
use crate::http::AppState;
use crate::job::{Job, JobError, Keyed};

/// The forms of a report: JSON, or JUnit XML for CI systems.
const FORMS: [&str; 2] = ["application/json", "application/xml"];

/// Run checks.
///
/// The body is a checks document, as `thirdbody check` takes (golden answers inline, as
/// `golden.answer`): each check a job and expectations on its answer. Every job is solved
/// through the cache like a synchronous request, all of them within one solve deadline
/// (checks not reached by then fail, saying so). The answer is the report, as JSON or, with
/// `Accept: application/xml`, as JUnit XML: 200 when every check passed, 422 when one
/// failed (as JSON, the problem `checks-failed` with the report's fields as members), so
/// that `curl --fail-with-body` fails a pipeline and still prints the report.
#[utoipa::path(
    post,
    path = "/v1/checks",
    operation_id = "run_checks",
    tag = "solve",
    request_body(content = ChecksInput, content_type = "application/json"),
    responses(
        (status = 200, description = "The report: every check passed", content(
            (Report = "application/json"), (String = "application/xml"))),
        BadBody, ChecksFailed, NotAcceptable, Busy,
    )
)]
pub async fn run(
    State(state): State<AppState>,
    caller: Caller,
    headers: HeaderMap,
    body: JsonBody,
) -> Result<Response, ApiError> {
    let accept = Accept::from_headers(&headers);
    let xml = accept.choose_media(&FORMS)? == FORMS[1];
    let limits = state.config().limits;
    let suite = body
        .read(&state, move |checks| {
            Ok(Suite::from_value(checks, &limits)?)
        })
        .await?;
    refuse_golden_files(&suite)?;
    // Its points are the caller's, charged at once: the suite runs whole or not at all.
    let jobs: Vec<Keyed> = suite
        .checks
        .iter()
        .map(|c| c.job.clone().keyed().scoped(caller.tenant()))
        .collect();
    let charged = access::charge_all(&state, &caller, &jobs).await?;
    // One deadline for the whole suite, so that its cost is that of one solve at most,
    // however many checks it holds; each answer is judged and let go before the next, so
    // that the suite holds its verdicts and one answer at a time.
    let started = Instant::now();
    let deadline = started + state.config().engine.solve_deadline;
    let mut reports = Vec::with_capacity(suite.checks.len());
    for (spec, keyed) in suite.checks.into_iter().zip(jobs) {
        if Instant::now() >= deadline {
            reports.push(not_run(&spec, &state));
            continue;
        }
        let began = Instant::now();
        let cache = cache_use(&spec.job, state.config().engine.memory_budget);
        let answer = match state.engine().solve_by(keyed, deadline, cache).await {
            Ok((solved, _)) => Ok(solved),
            Err(EngineError::Job(e)) => Err(e),
            Err(refusal) => return Err(refusal.into()),
        };
        // A large answer (a sweep's is megabytes) is read as a large body is: off the async
        // threads.
        let size = answer.as_ref().map_or(0, |solved| solved.json().len());
        let judge = move || {
            let json = answer.as_ref().map(|solved| solved.json().as_ref());
            Ok(spec.judge(json).timed(began))
        };
        reports.push(offload(&state, size, judge).await?);
    }
    if let Some(charge) = charged {
        state
            .engine()
            .points
            .true_up(&charge, started.elapsed())
            .await;
    }
    Ok(respond(Report::new(reports), xml))
}

/// A golden answer kept in a file is read by the command line, not by the service: a suite
/// that names one is refused whole.
fn refuse_golden_files(suite: &Suite) -> Result<(), ApiError> {
    let Some(spec) = suite
        .checks
        .iter()
        .find(|c| c.golden.as_ref().is_some_and(|g| g.answer.is_none()))
    else {
        return Ok(());
    };
    Err(JobError::Schema {
        field: "golden".to_string(),
        message: format!(
            "check \"{}\": a golden file is for `thirdbody check`; send the answer inline \
             as golden.answer",
            spec.name
        ),
    }
    .into())
}

/// The report of a check the suite's deadline came before.
fn not_run(spec: &CheckSpec, state: &AppState) -> CheckReport {
    let mut report = CheckReport::new(&spec.name, spec.job.kind().name());
    report.fail_with(format!(
        "not run: the suite ran past its deadline of {} (--solve-deadline, one for \
         the whole suite); split the suite, or run it with `thirdbody check`",
        humantime::format_duration(state.config().engine.solve_deadline)
    ));
    report.settle();
    report
}

/// The suite's report, as JSON or JUnit XML: 200 if every check passed, else the problem.
fn respond(report: Report, xml: bool) -> Response {
    let failed = (!report.passed).then(|| ApiError::checks_failed(&report));
    match (failed, xml) {
        (None, false) => axum::Json(report).into_response(),
        (None, true) => ([(header::CONTENT_TYPE, FORMS[1])], report.to_junit()).into_response(),
        (Some(failed), false) => failed.into_response(),
        (Some(failed), true) => failed.respond_as(FORMS[1], report.to_junit()),
    }
}

/// Whether a check keeps the answer it solves in the cache: when the answer takes at most a
/// thousandth of the memory budget (256 KiB of the default 256 MiB), as a rolling contact's
/// few kB do, so that the suite run again is answered from the cache and costs its caller no
/// points. A larger answer (a sweep of more than about 150 points, up to megabytes) is judged
/// and let go: nobody but the same check asks for it, and a suite of them kept would push out
/// every client's answers and stay resident (332 10,000-point sweeps left the cache holding
/// ~100 MiB after the suite), while the suite run again would not find them anyway, each
/// having pushed out the ones before.
fn cache_use(job: &Job, memory_budget: u64) -> CacheUse {
    if job.result_bytes() <= memory_budget / 1024 {
        CacheUse::Keep
    } else {
        CacheUse::ReadOnly
    }
}
