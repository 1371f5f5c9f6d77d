//! Bearer tokens: the `Secret` that holds one, and the middleware that checks the submit or
//! the worker token before a route runs.

use axum::extract::{Request, State};
use axum::http::HeaderMap;
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};
use subtle::ConstantTimeEq;

use super::AppState;
use crate::error::Error;

/// A bearer token; its `Debug` never shows the value, so it cannot reach a log by accident.
#[derive(Clone, Default)]
pub struct Secret(Option<String>);

impl Secret {
    /// Wraps a token; empty strings count as no token.
    pub fn new(token: Option<String>) -> Self {
        Secret(
            token
                .map(|t| t.trim().to_string())
                .filter(|t| !t.is_empty()),
        )
    }

    /// The token, for sending it.
    pub fn expose(&self) -> Option<&str> {
        self.0.as_deref()
    }

    /// Whether `presented` equals the token, compared in constant time.
    fn accepts(&self, presented: Option<&str>) -> bool {
        match (&self.0, presented) {
            (None, _) => true,
            (Some(want), Some(got)) => bool::from(want.as_bytes().ct_eq(got.as_bytes())),
            (Some(_), None) => false,
        }
    }
}

impl std::fmt::Debug for Secret {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(if self.0.is_some() {
            "Secret(***)"
        } else {
            "Secret(none)"
        })
    }
}

fn bearer(headers: &HeaderMap) -> Option<&str> {
    headers
        .get(axum::http::header::AUTHORIZATION)?
        .to_str()
        .ok()?
        .strip_prefix("Bearer ")
        .map(str::trim)
}

/// Middleware of the campaign and workers routes: the submit token or 401.
pub(super) async fn require_submit(
    State(s): State<AppState>,
    req: Request,
    next: Next,
) -> Response {
    if s.config.submit_token.accepts(bearer(req.headers())) {
        next.run(req).await
    } else {
        Error::Unauthorized.into_response()
    }
}

/// Middleware of the worker routes: the worker token or 401.
pub(super) async fn require_worker(
    State(s): State<AppState>,
    req: Request,
    next: Next,
) -> Response {
    if s.config.worker_token.accepts(bearer(req.headers())) {
        next.run(req).await
    } else {
        Error::Unauthorized.into_response()
    }
}
