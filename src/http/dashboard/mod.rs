//! The dashboard at `/`: one page, a script and a style sheet, embedded in the binary (no
//! CDN, no build step). The page only talks to this server, which its
//! `Content-Security-Policy` enforces, and only its own pages may frame it; pictures are
//! inlined SVG.

use axum::http::{header, HeaderValue};
use axum::response::IntoResponse;
use axum::routing::get;
use axum::Router;

use super::AppState;

const PAGE: &str = include_str!("index.html");
const SCRIPT: &str = include_str!("app.js");
const PLOT: &str = include_str!("plot.js");
const STYLE: &str = include_str!("app.css");
const ICON: &str = include_str!("icon.svg");

/// Nothing but this server, no inline script or style; and framed by no other site's page
/// (`frame-ancestors` has no fallback to `default-src`): a page that frames the dashboard
/// could lure a click onto its Solve, Cancel or Delete buttons.
const POLICY: &str = "default-src 'self'; frame-ancestors 'self'";

/// The dashboard's routes (outside the API and its OpenAPI description).
pub fn router() -> Router<AppState> {
    Router::new()
        .route("/", get(|| asset("text/html; charset=utf-8", PAGE)))
        .route(
            "/assets/app.js",
            get(|| asset("text/javascript; charset=utf-8", SCRIPT)),
        )
        .route(
            "/assets/plot.js",
            get(|| asset("text/javascript; charset=utf-8", PLOT)),
        )
        .route(
            "/assets/app.css",
            get(|| asset("text/css; charset=utf-8", STYLE)),
        )
        .route("/assets/icon.svg", get(|| asset("image/svg+xml", ICON)))
        .route("/favicon.ico", get(|| asset("image/svg+xml", ICON)))
}

async fn asset(content_type: &'static str, body: &'static str) -> impl IntoResponse {
    (
        [
            (header::CONTENT_TYPE, HeaderValue::from_static(content_type)),
            (
                header::CONTENT_SECURITY_POLICY,
                HeaderValue::from_static(POLICY),
            ),
            (
                header::X_CONTENT_TYPE_OPTIONS,
                HeaderValue::from_static("nosniff"),
            ),
            (header::CACHE_CONTROL, HeaderValue::from_static("no-cache")),
        ],
        body,
    )
}
