//! `/v1/jobs`: asynchronous jobs. Submit, poll or follow the progress as server-sent events,
//! cancel; a finished job is kept for the retention time, then forgotten (404).

use std::sync::Arc;
use std::time::Duration;

use axum::extract::{FromRequestParts, Path, State};
use axum::http::request::Parts;
use axum::http::{header, StatusCode};
use axum::response::sse::{Event, KeepAlive, Sse};
use axum::response::{IntoResponse, Response};
use axum::Json;
use futures_util::stream::{self, Stream};
use serde::Deserialize;
use tokio::sync::watch;
use utoipa::{IntoParams, ToSchema};
use uuid::Uuid;

use super::shared::{JobView, OwnerHeader, OWNER_HEADER};
use super::{Answering, FormatQuery};
use crate::engine::store::{JobRecord, JobState, JobStatus};
use crate::engine::{Engine, Unknown};
use crate::http::accept::{Accept, AcceptsJson};
use crate::http::access::{self, Caller};
use crate::http::body::JsonBody;
use crate::http::error::ApiError;
use crate::http::responses::{
    BadBody, Busy, Gone, InvalidParameters, JobFailure, NotAcceptable, NotFound, NotModified,
    NotTheOwner, ReadBack, TooManyStreams, Unfinished,
};
use crate::http::AppState;
use crate::job::registry::Envelope;
use crate::job::{Job, JobError};

/// How often a progress stream looks at a running job's count of solves.
const PROGRESS_INTERVAL: Duration = Duration::from_millis(100);

/// The job named in the path; 404 when the id is unknown, expired or not a UUID.
#[derive(Deserialize, IntoParams)]
#[into_params(parameter_in = Path)]
pub struct JobId {
    /// The job's id, as in its `Location`.
    id: Uuid,
}

/// Extracts the job of the path.
pub struct FoundJob(JobRecord);

impl FromRequestParts<AppState> for FoundJob {
    type Rejection = ApiError;

    async fn from_request_parts(parts: &mut Parts, state: &AppState) -> Result<Self, ApiError> {
        let Path(JobId { id }) = Path::from_request_parts(parts, state)
            .await
            .map_err(|_| ApiError::not_found("no such job: its id is a UUID"))?;
        let engine = state.engine();
        if let Some(record) = engine.jobs.job(id).await {
            let caller = Caller::of(&parts.extensions);
            if !caller.may_read(record.owner.as_ref()) {
                return Err(never_issued(id, state));
            }
            return Ok(FoundJob(record));
        }
        // Unknown here may be unknown only while the fleet's store is away.
        engine.jobs.store_reachable()?;
        Err(match engine.jobs.unknown(id).await {
            Unknown::NeverIssued => never_issued(id, state),
            Unknown::Gone => ApiError::not_found(format!(
                "no job {id}: it was deleted, or it expired (it finished more than the \
                 retention time ago)"
            )),
            Unknown::EarlierRun => ApiError::interrupted(format!(
                "job {id} was accepted by an earlier run of the service, which stopped before \
                 this one started: unless it had finished and been collected, it was \
                 interrupted. Submit it again"
            )),
            Unknown::LostWithStore { since } => ApiError::interrupted(format!(
                "job {id} was accepted before the job store (Redis) restarted without its \
                 data ({} s ago): unless it had expired or been deleted before, it was lost \
                 then. Submit it again",
                seconds_since(since)
            )),
        })
    }
}

/// An id no run issued, or, with API keys, a job another tenant's: told alike, so that a
/// tenant's jobs are not another's to know of.
fn never_issued(id: Uuid, state: &AppState) -> ApiError {
    let whose = if state.config().access.keys.configured() {
        " to a caller whose jobs this one may read"
    } else {
        ""
    };
    ApiError::not_found(format!(
        "no job {id}: no run of this service issued this id{whose} (check it against the \
         Location of the job's submission)"
    ))
}

/// Whole seconds from the Unix time `unix_ms` to now.
fn seconds_since(unix_ms: u64) -> u64 {
    let now = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_millis() as u64);
    now.saturating_sub(unix_ms) / 1000
}

/// Submit a job to run in the background.
///
/// The body is a job envelope, as `thirdbody solve` takes: `{"kind": "sweep", "input":
/// {...}}`. The answer is `202` with the job's URL in `Location`; poll it, or follow
/// `/v1/jobs/{id}/events`. A job already in the cache is `succeeded` at once. The job and
/// its answer are kept for the history's retention, across restarts.
#[utoipa::path(
    post,
    path = "/v1/jobs",
    operation_id = "submit_job",
    tag = "jobs",
    params(OwnerParam),
    request_body(content = Envelope, content_type = "application/json"),
    responses(
        (status = 202, description = "Accepted: queued, running, or already succeeded",
            body = JobView, headers(
                ("location" = String, description = "The job's URL, /v1/jobs/{id}"),
                ("retry-after" = u32, description = "Seconds to wait before polling"))),
        BadBody, NotAcceptable, Busy,
    )
)]
pub async fn submit(
    State(state): State<AppState>,
    _: AcceptsJson,
    caller: Caller,
    OwnerHeader(token): OwnerHeader,
    body: JsonBody,
) -> Result<Response, ApiError> {
    let owner = caller.owner(token);
    let limits = state.config().limits;
    let tenant = caller.tenant().map(str::to_string);
    let keyed = body
        .read(&state, move |envelope| {
            Ok(Job::from_value(envelope, &limits)?
                .keyed()
                .scoped(tenant.as_deref()))
        })
        .await?;
    // The tenant's turn is held until the job is stored: its quotas were counted in it.
    let admitted = access::admit_job(&state, &caller, &keyed).await?;
    let record = state.engine().submit(keyed, owner, admitted.charge).await?;
    drop(admitted.turn);
    let location = format!("/v1/jobs/{}", record.id);
    let view = JobView::of(&record);
    let headers = [
        (header::LOCATION, location),
        (header::RETRY_AFTER, "1".into()),
    ];
    Ok((StatusCode::ACCEPTED, headers, Json(view)).into_response())
}

/// A job's status, progress, and result or problem.
#[utoipa::path(
    get,
    path = "/v1/jobs/{id}",
    operation_id = "get_job",
    tag = "jobs",
    params(JobId),
    responses((status = 200, description = "The job", body = JobView), NotFound, Gone, NotAcceptable)
)]
pub async fn status(_: AcceptsJson, FoundJob(record): FoundJob) -> Json<JobView> {
    Json(JobView::of(&record))
}

/// Cancel a job.
///
/// A queued job is cancelled at once, a running one at the solver's next check (between two
/// rolling solves); the answer is the job once it stopped. The job stays, `cancelled`, for
/// its retention time. A finished job is left as it is. A job submitted with an owner's
/// token is cancelled only by a request with the same token (its link may be shared).
#[utoipa::path(
    post,
    path = "/v1/jobs/{id}/cancel",
    operation_id = "cancel_job",
    tag = "jobs",
    params(JobId, OwnerParam),
    responses((status = 200, description = "The job after the cancel", body = JobView),
        NotTheOwner, InvalidParameters, NotFound, Gone, NotAcceptable)
)]
pub async fn cancel(_: AcceptsJson, job: ChangeableJob) -> Json<JobView> {
    job.change(false).await
}

/// The job of the path, which the request may change (cancel or delete): its owner's (the
/// same API key's tenant, or the same owner's token) or an admin's; a job without an owner
/// is anyone's who holds its id.
pub struct ChangeableJob {
    record: JobRecord,
    engine: Arc<Engine>,
}

impl ChangeableJob {
    /// Cancels the job, and with `delete` forgets it; the job as it ended (as it was, if it
    /// was gone meanwhile).
    async fn change(self, delete: bool) -> Json<JobView> {
        let (jobs, id) = (&self.engine.jobs, self.record.id);
        let ended = match delete {
            true => jobs.delete(id).await,
            false => jobs.cancel(id).await,
        };
        Json(JobView::of(&ended.unwrap_or(self.record)))
    }
}

impl FromRequestParts<AppState> for ChangeableJob {
    type Rejection = ApiError;

    async fn from_request_parts(parts: &mut Parts, state: &AppState) -> Result<Self, ApiError> {
        let OwnerHeader(token) = OwnerHeader::from_request_parts(parts, state).await?;
        let FoundJob(record) = FoundJob::from_request_parts(parts, state).await?;
        if Caller::of(&parts.extensions).may_change(record.owner.as_ref(), token) {
            let engine = state.engine().clone();
            return Ok(ChangeableJob { record, engine });
        }
        Err(ApiError::forbidden(format!(
            "job {} was submitted with an owner's token: only a request with the same \
             {OWNER_HEADER} header (or an admin's API key) may cancel or delete it",
            record.id
        )))
    }
}

/// The owner's token, for a job submitted with one.
#[derive(IntoParams)]
#[into_params(parameter_in = Header)]
pub struct OwnerParam {
    /// A token of 16 to 128 characters the client keeps: a job submitted with it is listed
    /// to its holder (`GET /v1/jobs`), and only a request with it cancels or deletes the job.
    // A string when sent (not `null`: a client generated from the spec sent "null").
    #[param(
        rename = "thirdbody-owner",
        value_type = String,
        required = false,
        pattern = r"^[A-Za-z0-9._~-]{16,128}$"
    )]
    #[allow(dead_code)]
    owner: Option<String>,
}

/// Delete a job.
///
/// Cancels it if it has not finished (as `POST /v1/jobs/{id}/cancel` does), then forgets
/// it: the answer is the job as it ended, and its URL answers 404 from then on. A job
/// submitted with an owner's token is deleted only by a request with the same token.
#[utoipa::path(
    delete,
    path = "/v1/jobs/{id}",
    operation_id = "delete_job",
    tag = "jobs",
    params(JobId, OwnerParam),
    responses((status = 200, description = "The job as it ended, now forgotten", body = JobView),
        NotTheOwner, InvalidParameters, NotFound, Gone, NotAcceptable)
)]
pub async fn delete(_: AcceptsJson, job: ChangeableJob) -> Json<JobView> {
    job.change(true).await
}

/// A finished job's answer.
///
/// The answer alone, in the form the client accepts: JSON (as the job's `result`) or, with
/// `Accept: text/csv`, CSV, with its `ETag` and provenance headers, as the synchronous
/// endpoints give it. A job still queued or running answers 409 `not-ready` (with
/// `Retry-After`); a cancelled one 409 `cancelled`; a failed one the problem it failed with.
#[utoipa::path(
    get,
    path = "/v1/jobs/{id}/result",
    operation_id = "get_job_result",
    tag = "jobs",
    params(JobId, FormatQuery),
    responses(
        ReadBack,
        NotModified,
        NotFound,
        Gone,
        NotAcceptable,
        Unfinished,
        JobFailure
    )
)]
pub async fn result(
    answering: Answering,
    FoundJob(record): FoundJob,
) -> Result<Response, ApiError> {
    if let Some(result) = record.state.result() {
        return answering.respond_result(result).await;
    }
    match record.state {
        JobState::Failed { error, .. } => Err(error.into()),
        JobState::Cancelled { .. } => Err(JobError::Cancelled.into()),
        JobState::Interrupted => Err(ApiError::interrupted(format!(
            "job {} was interrupted: the service stopped before it finished. Submit it again",
            record.id
        ))),
        JobState::Succeeded(_) | JobState::Queued | JobState::Running => {
            Err(ApiError::not_ready(format!(
                "job {} is {}: poll /v1/jobs/{0}, or follow /v1/jobs/{0}/events",
                record.id,
                record.state.status().as_str()
            )))
        }
    }
}

/// One server-sent event of a job's stream.
#[derive(ToSchema)]
pub struct JobEvent {
    /// `progress` (the job without its result) or `completion` (the job with its result or
    /// problem; the last event).
    event: JobEventName,
    /// The job, a `JobView`, as JSON text.
    #[schema(content_media_type = "application/json")]
    data: String,
}

/// The names of a job's events.
#[derive(Clone, Copy, ToSchema)]
#[serde(rename_all = "lowercase")]
pub enum JobEventName {
    Progress,
    Completion,
}

impl JobEvent {
    fn new(event: JobEventName, view: &JobView) -> Result<JobEvent, axum::Error> {
        let data = serde_json::to_string(view).map_err(axum::Error::new)?;
        Ok(JobEvent { event, data })
    }

    fn into_sse(self) -> Event {
        let name = match self.event {
            JobEventName::Progress => "progress",
            JobEventName::Completion => "completion",
        };
        Event::default().event(name).data(self.data)
    }
}

/// Follow a job as server-sent events.
///
/// `progress` events (the job without its result) whenever its status or count changes,
/// at most every 100 ms; then one `completion` event, the job with its result or problem,
/// and the stream ends.
#[utoipa::path(
    get,
    path = "/v1/jobs/{id}/events",
    operation_id = "follow_job",
    tag = "jobs",
    params(JobId),
    responses(
        (status = 200, description = "A text/event-stream of `progress` events and one \
            `completion` event, each with a JobView as data",
            content_type = "text/event-stream", body = JobEvent),
        NotFound, Gone, NotAcceptable, TooManyStreams,
    )
)]
pub async fn events(
    State(state): State<AppState>,
    accept: Accept,
    FoundJob(record): FoundJob,
) -> Result<Sse<impl Stream<Item = Result<Event, axum::Error>>>, ApiError> {
    accept.require("text/event-stream")?;
    let permit = state.stream_permit()?;
    let watcher = Watcher {
        _permit: permit,
        engine: state.engine().clone(),
        changes: state.engine().jobs.watch(record.id),
        record,
        last: None,
        finished: false,
    };
    let events = stream::unfold(watcher, |mut w| async move {
        let event = w.next().await?;
        Some((event, w))
    });
    Ok(Sse::new(events).keep_alive(KeepAlive::default()))
}

/// Turns a job's changes into events.
struct Watcher {
    /// The stream's place among the event streams' share of `--max-connections`, given back when the stream ends.
    _permit: tokio::sync::OwnedSemaphorePermit,
    engine: Arc<Engine>,
    /// The job as last read.
    record: JobRecord,
    /// Status changes, while this process runs the job (else the watcher polls).
    changes: Option<watch::Receiver<JobStatus>>,
    /// The status and count last sent.
    last: Option<(JobStatus, usize)>,
    finished: bool,
}

impl Watcher {
    /// The next event, or `None` after the completion.
    async fn next(&mut self) -> Option<Result<Event, axum::Error>> {
        if self.finished {
            return None;
        }
        let mut tick = tokio::time::interval(PROGRESS_INTERVAL);
        loop {
            let status = self.record.state.status();
            let now = (status, self.record.done);
            if status.is_finished() {
                self.finished = true;
                return Some(self.event(JobEventName::Completion));
            }
            if self.last != Some(now) {
                self.last = Some(now);
                return Some(self.event(JobEventName::Progress));
            }
            let changed = async {
                let closed = match &mut self.changes {
                    Some(changes) => changes.changed().await.is_err(),
                    None => true,
                };
                if closed {
                    std::future::pending::<()>().await;
                }
            };
            tokio::select! {
                () = changed => {}
                _ = tick.tick() => {}
            }
            // Gone (expired) while followed: the last record read stands.
            if let Some(record) = self.engine.jobs.job(self.record.id).await {
                self.record = record;
            }
        }
    }

    /// The event `name` for the job now.
    fn event(&self, name: JobEventName) -> Result<Event, axum::Error> {
        JobEvent::new(name, &JobView::of(&self.record)).map(JobEvent::into_sse)
    }
}
