//! Request bodies: JSON declared as such, parsed by the job layer (which refuses a key sent
//! twice). A large body is parsed and read on a blocking thread, one of as many as there are
//! solver threads, so that no body holds an async worker (and with it `/healthz`) for long.

use axum::extract::{FromRequest, Request};
use axum::http::{header, HeaderMap, StatusCode};
use bytes::Bytes;
use serde_json::Value;

use super::error::ApiError;
use super::{server, AppState};
use crate::engine::{heavy, EngineError};
use crate::job::input;

/// Bodies up to this size are read where they arrive: parsing them takes microseconds.
const INLINE_BYTES: usize = 16 << 10;

/// A JSON body, not yet parsed.
pub struct JsonBody(Bytes);

impl FromRequest<AppState> for JsonBody {
    type Rejection = ApiError;

    async fn from_request(request: Request, state: &AppState) -> Result<Self, ApiError> {
        if !is_json(request.headers()) {
            let sent = match request.headers().get(header::CONTENT_TYPE) {
                Some(value) => format!(
                    "the body was sent as {}",
                    String::from_utf8_lossy(value.as_bytes())
                ),
                None => "the body was sent without a Content-Type".to_string(),
            };
            return Err(ApiError::unsupported_media_type(format!(
                "{sent}; send it as JSON, with Content-Type: application/json"
            )));
        }
        Bytes::from_request(request, state)
            .await
            .map(JsonBody)
            .map_err(|rejection| match server::slow_body_in(&rejection) {
                Some(slow) => ApiError::from_status(StatusCode::REQUEST_TIMEOUT, slow.to_string()),
                None => ApiError::unreadable_body(&rejection, state.config().body_limit),
            })
    }
}

impl JsonBody {
    /// Parses the body and reads it with `read` (see [`offload`]).
    pub async fn read<T: Send + 'static>(
        self,
        state: &AppState,
        read: impl FnOnce(Value) -> Result<T, ApiError> + Send + 'static,
    ) -> Result<T, ApiError> {
        let size = self.0.len();
        offload(state, size, move || read(input::parse(&self.0)?)).await
    }
}

/// Runs `work` on input of `size` bytes: at once if small, else on a blocking thread, and
/// 429 when as many large inputs as there are solver threads are being read already.
pub async fn offload<T: Send + 'static>(
    state: &AppState,
    size: usize,
    work: impl FnOnce() -> Result<T, ApiError> + Send + 'static,
) -> Result<T, ApiError> {
    if size <= INLINE_BYTES {
        return work();
    }
    let Some(permit) = state.reader_permit() else {
        return Err(EngineError::Overloaded.into());
    };
    heavy::run(move || {
        let _permit = permit;
        work()
    })
    .await
    .map_err(|e| ApiError::internal(format!("reading the body failed: {e}")))?
}

/// Whether the body is declared JSON: `application/json` or `application/*+json`.
fn is_json(headers: &HeaderMap) -> bool {
    let Some(media_type) = headers
        .get(header::CONTENT_TYPE)
        .and_then(|v| v.to_str().ok())
        .and_then(|v| v.split(';').next())
        .map(|v| v.trim().to_ascii_lowercase())
    else {
        return false;
    };
    media_type == "application/json"
        || media_type
            .strip_prefix("application/")
            .is_some_and(|subtype| subtype.ends_with("+json"))
}
