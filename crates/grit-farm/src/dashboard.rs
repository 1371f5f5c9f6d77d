//! The dashboard at `/`: one static HTML page (inline CSS and JS, charts drawn as inline SVG)
//! that reads the public API with the submit token in the browser. The page holds no data,
//! so it is served without a token; the token comes from the URL fragment `#token=...` or a
//! password field, stays in the tab's sessionStorage, and is only ever sent in the
//! Authorization header of same-origin API calls.

use axum::http::header;
use axum::response::IntoResponse;
use axum::routing::get;
use axum::Router;

use crate::server::AppState;

/// The page, embedded so the coordinator stays one binary.
pub const PAGE: &str = include_str!("dashboard.html");

/// Nothing but the page's own inline code may run, and it may only talk to this origin, so
/// the token in its memory cannot be sent elsewhere even by a bug. Inline script and style
/// need 'unsafe-inline' (the page is one file with no build step); the page never writes API
/// data as HTML, only as text nodes.
const CSP: &str = "default-src 'none'; script-src 'unsafe-inline'; style-src 'unsafe-inline'; \
    connect-src 'self'; img-src data: blob:; base-uri 'none'; form-action 'none'; \
    frame-ancestors 'none'";

async fn page() -> impl IntoResponse {
    (
        [
            (header::CONTENT_TYPE, "text/html; charset=utf-8"),
            (header::CONTENT_SECURITY_POLICY, CSP),
            // The fragment never leaves the browser, but a referrer must not carry the URL either.
            (header::REFERRER_POLICY, "no-referrer"),
            (header::X_CONTENT_TYPE_OPTIONS, "nosniff"),
            (header::X_FRAME_OPTIONS, "DENY"),
            (header::CACHE_CONTROL, "no-cache"),
        ],
        PAGE,
    )
}

/// The dashboard's route: `GET /`, open (the page carries no data).
pub fn router() -> Router<AppState> {
    Router::new().route("/", get(page))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn page_loads_nothing_from_elsewhere() {
        let lower = PAGE.to_ascii_lowercase();
        for banned in [
            "<script src",
            "<link rel=\"stylesheet\"",
            "@import",
            "http://",
            "https://",
        ] {
            // The SVG namespace is an identifier, not a URL the browser fetches.
            let hits = lower
                .match_indices(banned)
                .filter(|(i, _)| !lower[*i..].starts_with("http://www.w3.org/2000/svg"))
                .count();
            assert_eq!(hits, 0, "the page must be self-contained: found {banned:?}");
        }
    }

    #[test]
    fn page_sends_the_token_only_to_same_origin_api_paths() {
        // Every fetch goes through one helper whose URLs are relative `api/v1/` paths.
        assert_eq!(PAGE.matches("fetch(").count(), 1, "one fetch call site");
        assert!(PAGE.contains("fetch(\"api/v1/\" + path"));
        assert!(
            !PAGE.contains("innerHTML"),
            "API data is written as text only"
        );
    }
}
