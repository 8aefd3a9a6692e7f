//! The history: an owner's jobs listed (`GET /v1/jobs`), and an input's answer at a stable
//! link (`GET /v1/results/{input_hash}`). Jobs and their results are kept for the history's
//! retention, across restarts (in the database of saved analyses, or a fleet's Redis).
//!
//! An owner is the tenant of the API key a job was submitted with; without a key, whoever
//! holds the token sent in `Thirdbody-Owner` with the submissions: the dashboard keeps a
//! random one in the browser's storage, so that a browser lists its own jobs and nobody
//! else's. An admin key lists any tenant's jobs (`?tenant=`).

use axum::extract::{Path, RawQuery, State};
use axum::http::StatusCode;
use axum::response::Response;
use axum::Json;
use serde::{Deserialize, Serialize};
use serde_json::Value;
use utoipa::{IntoParams, ToSchema};

use super::shared::{invalid, JobView, OwnerHeader, OWNER_HEADER};
use super::{Answering, FormatQuery};
use crate::engine::store::{JobStatus, Listing, Owner};
use crate::engine::EngineError;
use crate::http::accept::AcceptsJson;
use crate::http::access::keys::is_tenant_name;
use crate::http::access::Caller;
use crate::http::error::ApiError;
use crate::http::responses::{
    HistoryUnreadable, InvalidParameters, NotAcceptable, NotAnAdmin, NotFound, NotModified,
    ReadBack,
};
use crate::http::AppState;
use crate::job::registry::KindName;
use crate::job::scoped_key;

/// Jobs on a page unless `limit` says, and at most.
const PAGE: usize = 20;
const MAX_PAGE: usize = 100;

/// The history's store failing a read: 503, saying why (not a submission's refusal).
fn unreadable(error: EngineError) -> ApiError {
    match error {
        EngineError::Unavailable(why) => ApiError::from_status(
            StatusCode::SERVICE_UNAVAILABLE,
            format!("the history cannot be read now: {why}"),
        ),
        other => other.into(),
    }
}

/// `GET /v1/jobs`'s query: filters and the page. Read by hand, so that every bad query
/// (a parameter given twice too) is a 422 naming the parameter.
#[derive(Default, IntoParams)]
#[into_params(parameter_in = Query)]
pub struct ListQuery {
    /// Only jobs of this kind.
    #[param(value_type = Option<KindName>)]
    kind: Option<String>,
    /// Only jobs in this status.
    #[param(value_type = Option<JobStatus>)]
    status: Option<String>,
    /// Jobs on the page: 1 to 100 (default 20).
    #[param(value_type = Option<usize>, minimum = 1, maximum = 100)]
    limit: Option<String>,
    /// Jobs skipped: those of the pages before (default 0).
    #[param(value_type = Option<usize>)]
    offset: Option<String>,
    /// The jobs of the API keys of this name instead of the caller's (an admin key only).
    #[param(pattern = r"^[A-Za-z0-9._-]{1,64}$")]
    tenant: Option<String>,
}

impl ListQuery {
    /// The parameters of the query string `query` (others are ignored).
    fn parse(query: Option<&str>) -> Result<ListQuery, ApiError> {
        let mut read = ListQuery::default();
        for pair in query
            .unwrap_or_default()
            .split('&')
            .filter(|p| !p.is_empty())
        {
            let (name, value) = pair.split_once('=').unwrap_or((pair, ""));
            let slot = match name {
                "kind" => &mut read.kind,
                "status" => &mut read.status,
                "limit" => &mut read.limit,
                "offset" => &mut read.offset,
                "tenant" => &mut read.tenant,
                _ => continue,
            };
            if slot.replace(value.to_string()).is_some() {
                return Err(invalid(
                    name,
                    Value::String(value.to_string()),
                    "one value: the parameter is given twice",
                ));
            }
        }
        Ok(read)
    }

    /// Whose jobs `caller` (with the owner's token `token`) asks to list: its own, or, for
    /// an admin, the tenant's it names.
    fn owner(&self, caller: &Caller, token: Option<Owner>) -> Result<Owner, ApiError> {
        match &self.tenant {
            Some(name) if !is_tenant_name(name) => Err(invalid(
                "tenant",
                Value::String(name.clone()),
                "the name of API keys: 1 to 64 characters of A-Z, a-z, 0-9, '-', '_' and '.'",
            )),
            Some(name) if caller.is_admin() || caller.tenant() == Some(name.as_str()) => {
                Ok(Owner::of_tenant(name))
            }
            Some(name) => Err(ApiError::forbidden(format!(
                "tenant={name}: only an admin's API key lists another tenant's jobs ({} is \
                 not one)",
                caller.describe()
            ))),
            None => caller.owner(token).ok_or_else(|| {
                invalid(
                    &format!("header {OWNER_HEADER}"),
                    Value::Null,
                    "an API key (x-api-key or Authorization: Bearer), or the token sent with \
                     the jobs' submissions (16 to 128 characters): jobs are listed to their \
                     owner only",
                )
            }),
        }
    }

    /// The listing asked for `owner`; a value out of range is a 422 naming it.
    fn listing(&self, owner: Owner) -> Result<Listing, ApiError> {
        let number = |name: &str, text: &Option<String>, default: usize, most: usize| {
            let Some(text) = text else {
                return Ok(default);
            };
            let least = usize::from(name == "limit");
            match text.parse::<usize>() {
                Ok(n) if (least..=most).contains(&n) => Ok(n),
                _ => Err(invalid(
                    name,
                    Value::String(text.clone()),
                    &format!("a whole number from {least} to {most}"),
                )),
            }
        };
        let kind = match &self.kind {
            None => None,
            Some(name) => Some(KindName::find(name).map_err(|_| {
                invalid(
                    "kind",
                    Value::String(name.clone()),
                    &crate::job::registry::NAMES.join(", "),
                )
            })?),
        };
        let status = match &self.status {
            None => None,
            Some(name) => Some(JobStatus::parse(name).ok_or_else(|| {
                let names: Vec<&str> = JobStatus::ALL.map(JobStatus::as_str).to_vec();
                invalid("status", Value::String(name.clone()), &names.join(", "))
            })?),
        };
        Ok(Listing {
            owner,
            kind,
            status,
            limit: number("limit", &self.limit, PAGE, MAX_PAGE)?,
            offset: number("offset", &self.offset, 0, usize::MAX / 2)?,
        })
    }
}

/// The URL of the page after `listing`'s (of the tenant's jobs `tenant` names, if it does).
fn next_page(listing: &Listing, tenant: Option<&str>) -> String {
    let mut url = format!(
        "/v1/jobs?limit={}&offset={}",
        listing.limit,
        listing.offset + listing.limit
    );
    if let Some(tenant) = tenant {
        url.push_str(&format!("&tenant={tenant}"));
    }
    if let Some(kind) = listing.kind {
        url.push_str(&format!("&kind={}", kind.name()));
    }
    if let Some(status) = listing.status {
        url.push_str(&format!("&status={}", status.as_str()));
    }
    url
}

/// A page of an owner's jobs.
#[derive(Serialize, ToSchema)]
pub struct JobList {
    /// The page's jobs, newest first (each as `GET /v1/jobs/{id}` shows it).
    pub jobs: Vec<JobView>,
    /// The owner's jobs that pass the filters, on every page.
    pub total: usize,
    /// The next page's URL, while there is one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub next: Option<String>,
}

/// List your jobs.
///
/// The jobs submitted with an API key of the same name as this request's (its tenant's),
/// or, without a key, with the same `Thirdbody-Owner` token, newest first, within the
/// history's retention (across restarts): queued and running ones, and finished ones with
/// their results. The dashboard keeps its token in the browser's storage. Without either
/// the answer is 422: nobody lists jobs that are not theirs. An admin key lists a tenant's
/// jobs with `?tenant=`.
#[utoipa::path(
    get,
    path = "/v1/jobs",
    operation_id = "list_jobs",
    tag = "jobs",
    params(ListQuery, ("thirdbody-owner" = String, Header, pattern = r"^[A-Za-z0-9._~-]{16,128}$",
        description = "The token sent with the jobs' submissions (16 to 128 characters)")),
    responses((status = 200, description = "A page of the owner's jobs", body = JobList),
        InvalidParameters, NotAnAdmin, NotAcceptable, HistoryUnreadable)
)]
pub async fn list(
    State(state): State<AppState>,
    _: AcceptsJson,
    caller: Caller,
    OwnerHeader(token): OwnerHeader,
    RawQuery(query): RawQuery,
) -> Result<Json<JobList>, ApiError> {
    let query = ListQuery::parse(query.as_deref())?;
    let listing = query.listing(query.owner(&caller, token)?)?;
    let page = state
        .engine()
        .jobs
        .list(&listing)
        .await
        .map_err(unreadable)?;
    let next = (listing.offset + page.jobs.len() < page.total)
        .then(|| next_page(&listing, query.tenant.as_deref()));
    Ok(Json(JobList {
        jobs: page.jobs.iter().map(JobView::of).collect(),
        total: page.total,
        next,
    }))
}

/// The input named in the path by its hash.
#[derive(Deserialize, IntoParams)]
#[into_params(parameter_in = Path)]
pub struct InputHash {
    /// The hash of a job's canonical input: `meta.input_hash` of its answer, `input_hash`
    /// of its job.
    input_hash: String,
}

/// Whose answers an input's link is looked up among: an admin may name a tenant.
#[derive(IntoParams)]
#[into_params(parameter_in = Query)]
#[allow(dead_code)]
pub struct LinkQuery {
    /// The tenant whose answer to give (an admin's API key only; default: the caller's own).
    #[param(pattern = r"^[A-Za-z0-9._-]{1,64}$")]
    tenant: Option<String>,
}

/// An input's answer, at a stable link.
///
/// Answers are content-addressed: equal inputs (in canonical form) have equal answers. This
/// is the answer to the input whose hash is `input_hash`, as cached, or as the newest job
/// on it that succeeded within the history's retention left it; in the form the client
/// accepts (or `?format=`), as `GET /v1/jobs/{id}/result` gives it. Answers are found
/// among those the caller's tenant asked for (an API key's), or among those of callers
/// without a key: whether an answer exists tells that somebody asked for it, so a tenant
/// learns of its own only. An admin names another tenant with `?tenant=`.
#[utoipa::path(
    get,
    path = "/v1/results/{input_hash}",
    operation_id = "get_result_by_input",
    tag = "jobs",
    params(InputHash, FormatQuery, LinkQuery),
    responses(
        ReadBack,
        NotModified,
        NotFound,
        InvalidParameters,
        NotAnAdmin,
        NotAcceptable,
        HistoryUnreadable
    )
)]
pub async fn by_input(
    State(state): State<AppState>,
    caller: Caller,
    answering: Answering,
    Path(InputHash { input_hash }): Path<InputHash>,
    RawQuery(query): RawQuery,
) -> Result<Response, ApiError> {
    let named = query
        .as_deref()
        .and_then(|q| q.split('&').find_map(|pair| pair.strip_prefix("tenant=")));
    let tenant = match named {
        Some(name) if !is_tenant_name(name) => {
            return Err(invalid("tenant", name.into(), "a tenant's name"))
        }
        Some(name) if caller.is_admin() || caller.tenant() == Some(name) => Some(name),
        Some(name) => {
            return Err(ApiError::forbidden(format!(
                "tenant={name}: only an admin's API key reads another tenant's answers ({} is \
                 not one)",
                caller.describe()
            )))
        }
        None => caller.tenant(),
    };
    let missing = || {
        let shown: String = input_hash.chars().take(64).collect();
        ApiError::not_found(format!(
            "no answer to the input {shown}: it is not cached, and no job on it succeeded \
             within the history's retention"
        ))
    };
    let key = scoped_key(&input_hash, tenant).ok_or_else(missing)?;
    let engine = state.engine();
    if let Some(solved) = engine.solver.cached(&key).await {
        return answering.respond(&solved, None);
    }
    let mut record = engine.jobs.with_input(&key).await.map_err(unreadable)?;
    if record.is_none() && tenant.is_some() {
        // A tenant's job saved before answers were kept by tenant: under the bare hash.
        record = engine
            .jobs
            .with_input(&input_hash)
            .await
            .map_err(unreadable)?;
    }
    let record = record.filter(|r| match tenant {
        Some(name) => r.owner == Some(Owner::of_tenant(name)),
        None => caller.may_read(r.owner.as_ref()),
    });
    match record.as_ref().and_then(|r| r.state.result()) {
        Some(result) => answering.respond_result(result).await,
        None => Err(missing()),
    }
}
