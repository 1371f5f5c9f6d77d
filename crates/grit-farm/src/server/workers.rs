//! `GET /workers`, under the submit token: the workers seen recently and the jobs they hold,
//! as the dashboard shows them.

use std::collections::BTreeMap;
use std::time::Duration;

use axum::extract::{Query, State};
use axum::routing::get;
use axum::{Json, Router};

use super::{unknown_param, AppState};
use crate::api::*;
use crate::error::{Error, Result};

/// The workers list route, relative to `/api/v1`.
pub fn router() -> Router<AppState> {
    Router::new().route("/workers", get(list_workers))
}

/// The workers list's part of the OpenAPI document.
#[derive(utoipa::OpenApi)]
#[openapi(paths(list_workers))]
pub struct Doc;

/// Query of `GET /workers`.
#[derive(utoipa::IntoParams)]
#[into_params(parameter_in = Query)]
struct WorkersQuery {
    /// Only workers heard from (a claim or a heartbeat) within this many seconds, up to 30
    /// days (default 900).
    seen_within_s: Option<f64>,
}

/// Longest window of `GET /workers`: workers silent for a week are forgotten anyway.
const MAX_SEEN_WITHIN_S: f64 = 30.0 * 24.0 * 3600.0;

impl WorkersQuery {
    fn parse(q: &BTreeMap<String, String>) -> Result<WorkersQuery> {
        let mut out = WorkersQuery {
            seen_within_s: None,
        };
        for (key, value) in q {
            match key.as_str() {
                "seen_within_s" => {
                    out.seen_within_s = Some(
                        value
                            .parse::<f64>()
                            .ok()
                            .filter(|w| w.is_finite() && *w > 0.0 && *w <= MAX_SEEN_WITHIN_S)
                            .ok_or_else(|| {
                                Error::invalid(
                                    "seen_within_s",
                                    format!(
                                        "must be a number of seconds above 0 and at most {MAX_SEEN_WITHIN_S}, got {value:?}"
                                    ),
                                )
                            })?,
                    )
                }
                other => return Err(unknown_param(other, "seen_within_s")),
            }
        }
        Ok(out)
    }
}

/// Workers seen recently, with the jobs they hold and their last heartbeats.
#[utoipa::path(get, path = "/api/v1/workers", params(WorkersQuery),
    responses((status = 200, body = WorkersResponse), (status = 401),
        (status = 422, body = ErrorBody, description = "a bad `seen_within_s`, or an unknown parameter")),
    security(("submit_token" = [])))]
async fn list_workers(
    State(s): State<AppState>,
    Query(q): Query<BTreeMap<String, String>>,
) -> Result<Json<WorkersResponse>> {
    let within = WorkersQuery::parse(&q)?.seen_within_s.unwrap_or(900.0);
    Ok(Json(
        s.store.workers(Duration::from_secs_f64(within)).await?,
    ))
}
