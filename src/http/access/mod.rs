//! Who is asking and what they may do: optional API keys ([`keys`]), the scopes each
//! route needs ([`admit`]), whose jobs a caller sees ([`Caller`]), and the cross-origin
//! preflights this service does not allow, answered with the flag that would allow them
//! ([`refuse_foreign_preflight`]).
//!
//! A caller without a key is anonymous and may do what `--anonymous` says (by default
//! submit, read and metrics: a service on a laptop needs no keys). A key has a name (its
//! tenant) and scopes; jobs submitted with it belong to the tenant and are seen by its keys
//! and by admin keys only.

pub mod keys;

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, SystemTime};

use axum::extract::{FromRequestParts, Request, State};
use axum::http::request::Parts;
use axum::http::{header, Extensions, HeaderMap, Method};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};

pub use keys::{Keys, Scopes, Source};

use super::error::ApiError;
use super::AppState;
use crate::engine::admission::Turn;
use crate::engine::quota::{Charge, Exceeded};
use crate::engine::store::Owner;
use crate::job::{Keyed, Work};

/// The header that carries an API key (`Authorization: Bearer` does too).
pub const API_KEY_HEADER: &str = "x-api-key";

/// The service's access rules: its keys, what anonymous callers may do, and the quota.
#[derive(Debug)]
pub struct Access {
    pub keys: Keys,
    /// What a caller without a key may do.
    pub anonymous: Scopes,
    /// What each tenant may use: each API key's name, and the anonymous callers together.
    pub quota: Quota,
    /// Whether a refused cross-origin preflight has been logged (it is, once).
    preflight_logged: AtomicBool,
}

/// What one tenant may use (0: no limit): the work it asks for, and the jobs it leaves
/// waiting.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Quota {
    /// Points asked to be computed in a minute.
    pub points_per_minute: u64,
    /// Unfinished asynchronous jobs at once.
    pub jobs: usize,
}

impl Access {
    /// Keys and anonymous scopes, without quotas.
    pub fn new(keys: Keys, anonymous: Scopes) -> Access {
        Access {
            keys,
            anonymous,
            quota: Quota::default(),
            preflight_logged: AtomicBool::new(false),
        }
    }

    /// The caller presenting `headers`' key (or none) at `now`; 401 for a key that is not
    /// accepted.
    fn caller(&self, headers: &HeaderMap, now: SystemTime) -> Result<Caller, ApiError> {
        let Some(presented) = presented_key(headers)? else {
            return Ok(Caller {
                key: None,
                scopes: self.anonymous,
            });
        };
        match self.keys.look_up(presented, now) {
            keys::Lookup::Valid(key) => Ok(Caller {
                scopes: key.scopes,
                key: Some(key),
            }),
            keys::Lookup::Expired(key) => Err(ApiError::unauthorized(format!(
                "the API key of {:?} expired at {}: ask its issuer for a new one",
                key.name,
                key.expires
                    .map(|at| humantime::format_rfc3339_seconds(at).to_string())
                    .unwrap_or_default()
            ))),
            keys::Lookup::Unknown if !self.keys.configured() => Err(ApiError::unauthorized(
                "this service accepts no API keys (it was started without --api-keys): \
                 send the request without x-api-key or Authorization",
            )),
            keys::Lookup::Unknown => Err(ApiError::unauthorized(
                "the API key is not known here: revoked, mistyped, or another service's",
            )),
        }
    }

    /// Why `caller` may not do what needs `needed`.
    fn refusal(&self, caller: &Caller, needed: Scopes) -> ApiError {
        match &caller.key {
            None => ApiError::unauthorized(format!(
                "this needs the {needed} scope, which callers without an API key do not have \
                 here (anonymous: {}): send a key in x-api-key or Authorization: Bearer",
                self.anonymous
            )),
            Some(key) => ApiError::forbidden(format!(
                "the API key of {:?} has the scopes {}, not {needed}",
                key.name, key.scopes
            )),
        }
    }
}

/// The key a request presents in `x-api-key` or `Authorization: Bearer`, if any.
fn presented_key(headers: &HeaderMap) -> Result<Option<&str>, ApiError> {
    fn text(value: &axum::http::HeaderValue) -> Result<&str, ApiError> {
        value
            .to_str()
            .map(str::trim)
            .map_err(|_| ApiError::unauthorized("the API key is not ASCII text"))
    }
    let in_header = headers.get(API_KEY_HEADER).map(text).transpose()?;
    // Another scheme (a proxy's Basic credentials, say) is not this service's to read.
    let bearer = match headers.get(header::AUTHORIZATION).map(text).transpose()? {
        Some(value) => value
            .split_once(' ')
            .filter(|(scheme, _)| scheme.eq_ignore_ascii_case("bearer"))
            .map(|(_, key)| key.trim()),
        None => None,
    };
    match (in_header, bearer) {
        (Some(a), Some(b)) if a != b => Err(ApiError::unauthorized(
            "x-api-key and Authorization name two different keys: send one",
        )),
        (Some(key), _) | (None, Some(key)) if key.is_empty() => {
            Err(ApiError::unauthorized("the API key is empty"))
        }
        (key, other) => Ok(key.or(other)),
    }
}

/// Who sent a request: their key, if any, and what they may do.
#[derive(Clone, Debug)]
pub struct Caller {
    key: Option<Arc<keys::Key>>,
    scopes: Scopes,
}

impl Caller {
    /// Who owns what this caller submits: its key's tenant, else the holder of the
    /// `thirdbody-owner` token it sent (if any).
    pub fn owner(&self, token: Option<Owner>) -> Option<Owner> {
        match &self.key {
            Some(key) => Some(Owner::of_tenant(&key.name)),
            None => token,
        }
    }

    pub fn is_admin(&self) -> bool {
        self.scopes.is_admin()
    }

    /// Whether this caller may read a job owned by `owner`: a tenant's jobs are read by its
    /// keys and by admins; other jobs by anyone holding their id (a link may be shared).
    pub fn may_read(&self, owner: Option<&Owner>) -> bool {
        match owner {
            Some(owner) if owner.is_tenant() => {
                self.is_admin() || self.owner(None).as_ref() == Some(owner)
            }
            _ => true,
        }
    }

    /// Whether this caller, with the token `token`, may cancel or delete a job owned by
    /// `owner`: its owner (its key's tenant, or the holder of its token) or an admin (a job
    /// nobody owns, anyone).
    pub fn may_change(&self, owner: Option<&Owner>, token: Option<Owner>) -> bool {
        owner.is_none_or(|owner| {
            self.is_admin()
                || self.owner(None).as_ref() == Some(owner)
                || token.as_ref() == Some(owner)
        })
    }

    /// The name of this caller's tenant, if it has a key.
    pub fn tenant(&self) -> Option<&str> {
        self.key.as_ref().map(|key| key.name.as_str())
    }

    /// The name this caller's quota is counted under: its tenant's, or the anonymous
    /// callers' together.
    fn tenant_name(&self) -> String {
        match self.owner(None) {
            Some(tenant) => tenant.as_str().to_string(),
            None => "anonymous".to_string(),
        }
    }

    /// The caller, in a sentence.
    pub fn describe(&self) -> String {
        match &self.key {
            Some(key) => format!("the API key of {:?}", key.name),
            None => "a caller without an API key".to_string(),
        }
    }

    /// The caller [`admit`] let in (a route it does not guard has a caller with no scope),
    /// from a request's extensions.
    pub fn of(extensions: &Extensions) -> Caller {
        extensions.get::<Caller>().cloned().unwrap_or(Caller {
            key: None,
            scopes: Scopes::NONE,
        })
    }
}

impl<S: Send + Sync> FromRequestParts<S> for Caller {
    type Rejection = std::convert::Infallible;

    async fn from_request_parts(parts: &mut Parts, _: &S) -> Result<Self, Self::Rejection> {
        Ok(Caller::of(&parts.extensions))
    }
}

/// Charges the points `keyed` is estimated to cost to `caller`'s quota, unless its answer is
/// cached (it costs nothing then); past the quota, 429 `quota-exceeded` with `Retry-After`
/// (the end of the minute). The charge made, to true up once the work is done
/// ([`crate::engine::Engine::true_up`]).
pub async fn charge(
    state: &AppState,
    caller: &Caller,
    keyed: &Keyed,
) -> Result<Option<Charge>, ApiError> {
    charge_all(state, caller, std::slice::from_ref(keyed)).await
}

/// Charges the points of all of `jobs` (a checks suite's) to `caller`'s quota at once, as
/// [`charge`] does one's: all are let in, or none.
pub async fn charge_all(
    state: &AppState,
    caller: &Caller,
    jobs: &[Keyed],
) -> Result<Option<Charge>, ApiError> {
    let tenant = caller.tenant_name();
    let limit = state.config().access.quota.points_per_minute;
    if limit == 0 {
        return Ok(None);
    }
    // What each job is estimated to cost (`Cost`: a point a local answer).
    let (mut points, mut guessed) = (0, false);
    for keyed in jobs {
        if state.engine().solver.cached(keyed.key()).await.is_none() {
            points += keyed.job().cost().points;
            guessed |= keyed.job().work() == Work::Unknown;
        }
    }
    if points == 0 {
        return Ok(None);
    }
    let (used, retry_after) = match state
        .engine()
        .points
        .charge(&tenant, points, limit, SystemTime::now())
        .await
    {
        Ok(window) => {
            return Ok(Some(Charge {
                tenant,
                points,
                window,
                guessed,
            }))
        }
        Err(Exceeded { used, retry_after }) => (used, retry_after),
    };
    let whose = caller.describe();
    let detail = match retry_after {
        None => format!(
            "this asks for {points} points, more than the {limit} a minute {whose} may ask \
             for (--quota-points): split it"
        ),
        Some(wait) => format!(
            "{whose} asked for {used} points this minute, of the {limit} it may; this asks for \
             {points} more. Retry in {} s, or ask an admin for a larger quota",
            wait.as_secs()
        ),
    };
    Err(ApiError::quota_exceeded(detail, retry_after))
}

/// A job `caller` submits: within its tenant's unfinished jobs (anonymous callers: theirs
/// together, and the service's own limits), and its points charged. The quota is counted in
/// the tenant's turn ([`Engine::turn`](crate::engine::Engine::turn)), which the caller holds
/// until the job is stored: two submissions never both pass the last place.
pub async fn admit_job(
    state: &AppState,
    caller: &Caller,
    keyed: &Keyed,
) -> Result<Admitted, ApiError> {
    let jobs = state.config().access.quota.jobs;
    let turn = match jobs > 0 {
        true => Some(state.engine().turn(&caller.tenant_name()).await?),
        false => None,
    };
    if jobs > 0 {
        within_jobs(state, caller, jobs).await?;
    }
    let charge = charge(state, caller, keyed).await?;
    Ok(Admitted { turn, charge })
}

/// Lets `caller` leave one more job unfinished if its tenant has fewer than `limit`; else
/// 429, to retry in a few seconds.
async fn within_jobs(state: &AppState, caller: &Caller, limit: usize) -> Result<(), ApiError> {
    let tenant = caller.owner(None);
    let unfinished = match &tenant {
        Some(owner) => state.engine().unfinished_of(owner).await?,
        None => state.engine().jobs.unfinished_anonymous(),
    };
    if unfinished < limit {
        return Ok(());
    }
    let who = match tenant {
        Some(_) => format!("{} has", caller.describe()),
        None => "the callers without an API key together have".to_string(),
    };
    Err(ApiError::quota_exceeded(
        format!(
            "{who} {unfinished} unfinished jobs, as many as allowed at once (--quota-jobs \
             {limit}): wait for one to end, or cancel one"
        ),
        Some(Duration::from_secs(5)),
    ))
}

/// A job let in: its tenant's turn, held until the job is stored, and its points charged.
pub struct Admitted {
    pub turn: Option<Turn>,
    pub charge: Option<Charge>,
}

/// The scope a request needs: the API's reads `read` and its other methods `submit`,
/// `/metrics` `metrics`, the API's docs `read`; the dashboard's files and the probes none.
fn needed(method: &Method, path: &str) -> Option<Scopes> {
    if path == "/metrics" {
        return Some(Scopes::METRICS);
    }
    if path == "/openapi.json" || path == "/docs" || path.starts_with("/docs/") {
        return Some(Scopes::READ);
    }
    if !path.starts_with("/v1/") {
        return None;
    }
    match *method {
        Method::GET | Method::HEAD => Some(Scopes::READ),
        Method::OPTIONS => None,
        _ => Some(Scopes::SUBMIT),
    }
}

/// Lets a request in if its caller may do what it asks ([`needed`]), the caller then
/// known to the handlers ([`Caller`]); else 401 (no key, or a key not accepted) or 403 (a
/// key without the scope).
pub async fn admit(State(state): State<AppState>, mut request: Request, next: Next) -> Response {
    match refuse_or_admit(&state, &mut request) {
        Some(refused) => refused,
        None => next.run(request).await,
    }
}

/// What [`admit`] answers a request it does not let in; `None` (and the caller in the
/// request's extensions) for one it does.
pub fn refuse_or_admit(state: &AppState, request: &mut Request) -> Option<Response> {
    let needed = needed(request.method(), request.uri().path())?;
    let access = &state.config().access;
    let caller = match access.caller(request.headers(), SystemTime::now()) {
        Ok(caller) => caller,
        Err(refused) => return Some(refused.into_response()),
    };
    if !caller.scopes.allow(needed) {
        return Some(access.refusal(&caller, needed).into_response());
    }
    request.extensions_mut().insert(caller);
    None
}

/// Answers a cross-origin preflight from an origin `--cors-origin` does not allow with a
/// problem naming the flag (a browser shows only "Failed to fetch", so the log says it
/// too, once); `None` for other requests, which go on.
pub fn refuse_foreign_preflight(state: &AppState, request: &Request) -> Option<Response> {
    let headers = request.headers();
    let preflight = request.method() == Method::OPTIONS
        && headers.contains_key(header::ACCESS_CONTROL_REQUEST_METHOD);
    let origin = headers.get(header::ORIGIN).filter(|_| preflight)?;
    let detail = state.config().cors_origins.refusal(origin)?;
    let shown = String::from_utf8_lossy(origin.as_bytes()).into_owned();
    let access = &state.config().access;
    if !access.preflight_logged.swap(true, Ordering::Relaxed) {
        tracing::warn!(origin = %shown, "cross-origin request refused: {detail} (said once)");
    }
    Some(ApiError::forbidden(detail).into_response())
}
