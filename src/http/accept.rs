//! The client's `Accept`, for every route: the answer's form is negotiated by
//! [`render::negotiate`](crate::render::negotiate), and a route that offers nothing the
//! client accepts answers 406 before doing any work.

use axum::extract::FromRequestParts;
use axum::http::request::Parts;
use axum::http::{header, HeaderMap};

use super::error::ApiError;
use crate::render::{negotiate, Format};

/// The values of a request's `Accept` headers.
#[derive(Clone, Debug, Default)]
pub struct Accept(Vec<String>);

impl Accept {
    pub fn from_headers(headers: &HeaderMap) -> Accept {
        let values = headers.get_all(header::ACCEPT).iter();
        Accept(
            values
                .filter_map(|v| v.to_str().ok())
                .map(str::to_string)
                .collect(),
        )
    }

    fn values(&self) -> impl Iterator<Item = &str> {
        self.0.iter().map(String::as_str)
    }

    /// The format the client prefers among `offered`, or 406 naming what is offered.
    pub fn choose(&self, offered: &[Format]) -> Result<Format, ApiError> {
        Format::negotiate(self.values(), offered).ok_or_else(|| {
            let types: Vec<&str> = offered.iter().map(|f| f.media_type()).collect();
            self.refusal(&types)
        })
    }

    /// The media type the client prefers among `offered`, or 406.
    pub fn choose_media<'a>(&self, offered: &[&'a str]) -> Result<&'a str, ApiError> {
        match negotiate(self.values(), offered) {
            Some(i) => Ok(offered[i]),
            None => Err(self.refusal(offered)),
        }
    }

    /// Checks that the client accepts `media_type`, the one form of a route's answer.
    pub fn require(&self, media_type: &str) -> Result<(), ApiError> {
        self.choose_media(&[media_type]).map(|_| ())
    }

    fn refusal(&self, offered: &[&str]) -> ApiError {
        ApiError::not_acceptable(format!(
            "Accept: {} names none of the forms this resource offers: {}",
            self.0.join(", "),
            offered.join(", ")
        ))
    }
}

impl<S: Send + Sync> FromRequestParts<S> for Accept {
    type Rejection = ApiError;

    async fn from_request_parts(parts: &mut Parts, _state: &S) -> Result<Self, ApiError> {
        Ok(Accept::from_headers(&parts.headers))
    }
}

/// A JSON resource: extracting it checks that the client accepts `application/json`.
pub struct AcceptsJson;

impl<S: Send + Sync> FromRequestParts<S> for AcceptsJson {
    type Rejection = ApiError;

    async fn from_request_parts(parts: &mut Parts, _state: &S) -> Result<Self, ApiError> {
        Accept::from_headers(&parts.headers).require(Format::Json.media_type())?;
        Ok(AcceptsJson)
    }
}
