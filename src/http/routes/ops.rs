//! Operations: liveness, readiness (fails while draining) and Prometheus metrics.

use std::collections::BTreeMap;

use axum::extract::State;
use axum::http::header;
use axum::response::IntoResponse;
use axum::Json;
use serde::Serialize;
use utoipa::ToSchema;

use crate::http::accept::{Accept, AcceptsJson};
use crate::http::error::ApiError;
use crate::http::responses::{Draining, NotAcceptable};
use crate::http::AppState;

/// A probe's answer.
#[derive(Serialize, ToSchema)]
pub struct Health {
    /// `ok` (alive), `ready` (taking work), or `degraded` (taking work, but a Redis of the
    /// fleet is down, slow, full or refusing its credentials: synchronous solves answer from
    /// this process alone, and job submissions are refused with 503 while the job store
    /// cannot take them; or the API keys' file cannot be used).
    pub status: &'static str,
    /// In a fleet: each Redis role (`cache`, `jobs`) with `up`, `slow`, `full`, `down` or
    /// `denied` (its credentials refused).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub redis: Option<BTreeMap<&'static str, &'static str>>,
    /// Why the service is degraded, in a sentence per Redis role not `up` (and one for the
    /// API keys' file, if it cannot be used).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub reasons: Vec<String>,
}

/// Liveness: the process answers requests.
#[utoipa::path(
    get,
    path = "/healthz",
    operation_id = "healthz",
    tag = "operations",
    responses((status = 200, description = "Alive", body = Health), NotAcceptable)
)]
pub async fn healthz(_: AcceptsJson) -> Json<Health> {
    Json(Health {
        status: "ok",
        redis: None,
        reasons: Vec::new(),
    })
}

/// Readiness: the service takes new work (`degraded`, with the reasons, when a Redis of its
/// fleet is down, slow or full, or its database of saved analyses cannot be written: it
/// still answers synchronous solves); 503 once it is shutting down.
#[utoipa::path(
    get,
    path = "/readyz",
    operation_id = "readyz",
    tag = "operations",
    responses((status = 200, description = "Ready", body = Health), NotAcceptable, Draining)
)]
pub async fn readyz(
    State(state): State<AppState>,
    _: AcceptsJson,
) -> Result<Json<Health>, ApiError> {
    let engine = state.engine();
    if engine.jobs.is_draining() {
        return Err(ApiError::draining());
    }
    let roles = engine.jobs.fleet_health();
    let redis = roles.as_ref().map(|roles| {
        roles
            .iter()
            .map(|(role, health)| (*role, health.as_str()))
            .collect()
    });
    let reasons: Vec<String> = roles
        .iter()
        .flatten()
        .filter_map(|(role, health)| health.reason(role))
        .chain(engine.jobs.store_problem())
        .chain(state.config().access.keys.problem())
        .collect();
    Ok(Json(Health {
        status: if reasons.is_empty() {
            "ready"
        } else {
            "degraded"
        },
        redis,
        reasons,
    }))
}

/// Metrics in the Prometheus text format.
///
/// `http_requests_total` and `http_request_duration_seconds` by method, route and status;
/// `thirdbody_solve_duration_seconds` by job kind and outcome (its `_count` is the number of
/// solves); `thirdbody_cache_hits_total`, `thirdbody_cache_misses_total`;
/// `thirdbody_jobs_queued`, `thirdbody_jobs_running`; `thirdbody_rejections_total` by reason;
/// in a fleet, `thirdbody_redis_up` by role, `thirdbody_parts_total` by outcome and
/// `thirdbody_redeliveries_total`.
#[utoipa::path(
    get,
    path = "/metrics",
    operation_id = "metrics",
    tag = "operations",
    responses((status = 200, description = "Prometheus text exposition format",
        content_type = "text/plain; version=0.0.4", body = String), NotAcceptable)
)]
pub async fn metrics(
    State(state): State<AppState>,
    accept: Accept,
) -> Result<impl IntoResponse, ApiError> {
    accept.require("text/plain")?;
    Ok((
        [(
            header::CONTENT_TYPE,
            "text/plain; version=0.0.4; charset=utf-8",
        )],
        state.render_metrics(),
    ))
}
