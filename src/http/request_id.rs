//! The request id: the client's `x-request-id` if it is one a client may choose
//! ([`valid`]), else a new random UUID; set on the request before the tracing span reads it,
//! and on the answer unless the answer carries one already.
//!
//! One layer for what three did (`sanitize_request_id`, tower-http's `SetRequestId` and
//! `PropagateRequestId`, issue 46): the same headers, without an `axum::middleware::from_fn`
//! (which clones the service below it and boxes its future on every request), and with the
//! id formatted into a stack buffer rather than through `Display` into a `String`. Nothing
//! reads tower-http's `RequestId` extension, so none is set.

use std::future::Future;
use std::pin::Pin;
use std::task::{Context, Poll};

use axum::http::{HeaderName, HeaderValue, Request, Response};
use tower::Service;
use uuid::Uuid;

/// The request id header, set by the client or by the service.
pub const X_REQUEST_ID: HeaderName = HeaderName::from_static("x-request-id");

/// A request id a client may choose: up to 128 letters, digits and `-_.:`; anything else
/// (which could forge fields in a text log line) is replaced by one of ours.
fn valid(value: &HeaderValue) -> bool {
    let bytes = value.as_bytes();
    !bytes.is_empty()
        && bytes.len() <= 128
        && bytes
            .iter()
            .all(|b| b.is_ascii_alphanumeric() || b"-_.:".contains(b))
}

/// A new request id: a random (version 4) UUID in lower-case hyphenated form.
fn new_id() -> HeaderValue {
    let mut buffer = [0; uuid::fmt::Hyphenated::LENGTH];
    let text = Uuid::new_v4().hyphenated().encode_lower(&mut buffer);
    HeaderValue::from_str(text).expect("a UUID is a header value")
}

/// Gives every request and its answer a request id.
#[derive(Clone, Debug)]
pub struct RequestId<S> {
    pub inner: S,
}

impl<S, ReqBody, ResBody> Service<Request<ReqBody>> for RequestId<S>
where
    S: Service<Request<ReqBody>, Response = Response<ResBody>>,
    S::Future: Unpin,
{
    type Response = Response<ResBody>;
    type Error = S::Error;
    type Future = WithRequestId<S::Future>;

    fn poll_ready(&mut self, cx: &mut Context<'_>) -> Poll<Result<(), Self::Error>> {
        self.inner.poll_ready(cx)
    }

    fn call(&mut self, mut request: Request<ReqBody>) -> Self::Future {
        let headers = request.headers_mut();
        let id = match headers.get(X_REQUEST_ID) {
            Some(id) if valid(id) => id.clone(),
            _ => {
                let id = new_id();
                headers.insert(X_REQUEST_ID, id.clone());
                id
            }
        };
        WithRequestId {
            inner: self.inner.call(request),
            id: Some(id),
        }
    }
}

/// An answer's future, whose answer gets the request's id unless it has one. (The futures
/// below it, tracing's around the metrics layer's box, are `Unpin`: no pin projection is
/// needed.)
pub struct WithRequestId<F> {
    inner: F,
    id: Option<HeaderValue>,
}

impl<F, B, E> Future for WithRequestId<F>
where
    F: Future<Output = Result<Response<B>, E>> + Unpin,
{
    type Output = Result<Response<B>, E>;

    fn poll(self: Pin<&mut Self>, cx: &mut Context<'_>) -> Poll<Self::Output> {
        let this = self.get_mut();
        let mut response = std::task::ready!(Pin::new(&mut this.inner).poll(cx))?;
        if let Some(id) = this.id.take() {
            response.headers_mut().entry(X_REQUEST_ID).or_insert(id);
        }
        Poll::Ready(Ok(response))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_new_id_is_a_version_4_uuid_in_lower_case() {
        let id = new_id();
        let text = id.to_str().unwrap();
        let parsed = Uuid::parse_str(text).unwrap();
        assert_eq!(parsed.get_version_num(), 4);
        assert_eq!(parsed.hyphenated().to_string(), text);
    }

    #[test]
    fn a_client_chooses_ids_of_safe_characters_only() {
        assert!(valid(&HeaderValue::from_static("my-id.1:a_b")));
        assert!(!valid(&HeaderValue::from_static("")));
        assert!(!valid(&HeaderValue::from_static("bad id")));
        assert!(!valid(&HeaderValue::from_str(&"a".repeat(129)).unwrap()));
    }
}
