//! The service's own layers in [`super::app`]'s stack, written as tower services rather
//! than with `axum::middleware::from_fn` or `map_response`: those clone the service below
//! them, box it into a `Next` and box their future on every request (issue 46). The work
//! is the same functions' ([`observe`], [`access`], [`error`]).

use std::convert::Infallible;
use std::future::Future;
use std::pin::Pin;
use std::task::{Context, Poll};

use axum::body::{Bytes, HttpBody};
use axum::extract::Request;
use axum::http::Response as HttpResponse;
use axum::response::{IntoResponse, Response};
use futures_util::future::{ready, Either, Ready};
use tower::Service;

use super::{access, error, observe, AppState};

type Boxed = Pin<Box<dyn Future<Output = Result<Response, Infallible>> + Send>>;
type Answer<F> = Either<Ready<Result<Response, Infallible>>, F>;

/// Counts and times every request ([`observe::Timing`]), and refuses a cross-origin
/// preflight this service does not allow ([`access::refuse_foreign_preflight`]).
#[derive(Clone)]
pub struct Observed<S> {
    pub state: AppState,
    pub inner: S,
}

impl<S, B> Service<Request> for Observed<S>
where
    S: Service<Request, Response = HttpResponse<B>, Error = Infallible>,
    S::Future: Send + 'static,
    B: HttpBody<Data = Bytes> + Send + 'static,
    B::Error: Into<axum::BoxError>,
{
    type Response = Response;
    type Error = Infallible;
    type Future = Boxed;

    fn poll_ready(&mut self, cx: &mut Context<'_>) -> Poll<Result<(), Self::Error>> {
        self.inner.poll_ready(cx)
    }

    fn call(&mut self, request: Request) -> Self::Future {
        let timing = observe::Timing::start(&request);
        let state = self.state.clone();
        let answer = match access::refuse_foreign_preflight(&state, &request) {
            Some(refused) => Err(refused),
            None => Ok(self.inner.call(request)),
        };
        Box::pin(async move {
            let response = match answer {
                Ok(answer) => answer.await?.into_response(),
                Err(refused) => refused,
            };
            timing.record(&state, &response);
            Ok(response)
        })
    }
}

/// Refuses at once (413) a body whose declared length is over the limit
/// ([`observe::declared_overflow`]), rather than reading it up to the limit first; then
/// lets the request in if its caller may do what it asks ([`access::refuse_or_admit`]).
#[derive(Clone)]
pub struct Admitted<S> {
    pub state: AppState,
    pub inner: S,
}

impl<S> Service<Request> for Admitted<S>
where
    S: Service<Request, Response = Response, Error = Infallible>,
{
    type Response = Response;
    type Error = Infallible;
    type Future = Answer<S::Future>;

    fn poll_ready(&mut self, cx: &mut Context<'_>) -> Poll<Result<(), Self::Error>> {
        self.inner.poll_ready(cx)
    }

    fn call(&mut self, mut request: Request) -> Self::Future {
        let refused = observe::declared_overflow(&self.state, &request)
            .or_else(|| access::refuse_or_admit(&self.state, &mut request));
        match refused {
            Some(refused) => Either::Left(ready(Ok(refused))),
            None => Either::Right(self.inner.call(request)),
        }
    }
}

/// An error's answer as a problem ([`error::problem_for_errors`], which reads its body),
/// for `ServiceBuilder::and_then`: other answers pass as they are, with nothing boxed.
pub fn problems(response: Response) -> Answer<Boxed> {
    let status = response.status();
    if status.is_client_error() || status.is_server_error() {
        Either::Right(Box::pin(async move {
            Ok(error::problem_for_errors(response).await)
        }))
    } else {
        Either::Left(ready(Ok(response)))
    }
}
