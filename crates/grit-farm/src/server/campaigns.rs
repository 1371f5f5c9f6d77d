//! Campaign endpoints, all under the submit token: submit, list, status, results, jobs,
//! cancel, retry-failed and raise-caps.

use std::collections::BTreeMap;

use axum::body::Bytes;
use axum::extract::{Path, Query, State};
use axum::http::{header, HeaderMap, StatusCode};
use axum::response::IntoResponse;
use axum::routing::{get, post};
use axum::{Json, Router};
use grit_erosion::campaign::AnySpec;
use uuid::Uuid;

use super::{unknown_param, AppState};
// Glob so the `utoipa::path` attributes below find the schema types (and ErrorBody) by name.
use crate::api::*;
use crate::error::{Error, Result};

/// The campaign routes, relative to `/api/v1`.
pub fn router() -> Router<AppState> {
    Router::new()
        .route("/campaigns", post(create_campaign).get(list_campaigns))
        .route("/campaigns/{id}", get(campaign_status))
        .route("/campaigns/{id}/results", get(campaign_results))
        .route("/campaigns/{id}/jobs", get(campaign_jobs))
        .route("/campaigns/{id}/cancel", post(cancel_campaign))
        .route("/campaigns/{id}/retry-failed", post(retry_failed))
        .route("/campaigns/{id}/raise-caps", post(raise_caps))
}

/// The campaign endpoints' part of the OpenAPI document.
#[derive(utoipa::OpenApi)]
#[openapi(paths(
    create_campaign,
    list_campaigns,
    campaign_status,
    campaign_results,
    campaign_jobs,
    cancel_campaign,
    retry_failed,
    raise_caps
))]
pub struct Doc;

/// A campaign id from the path; one that is not a uuid names no campaign (404).
fn campaign_id(raw: &str) -> Result<Uuid> {
    raw.parse()
        .map_err(|_| Error::NotFound(format!("campaign {raw}")))
}

/// A campaign spec from a request body: 400 for what is not JSON, 422 naming the field for a
/// rule broken.
fn spec_of(body: &Bytes) -> Result<AnySpec> {
    let text = std::str::from_utf8(body).map_err(|_| Error::BadRequest {
        status: StatusCode::BAD_REQUEST,
        message: "body is not UTF-8 JSON".into(),
    })?;
    AnySpec::from_json(text).map_err(|e| {
        if e.field == "(json)" {
            Error::BadRequest {
                status: StatusCode::BAD_REQUEST,
                message: format!("malformed JSON: {}", e.rule),
            }
        } else {
            e.into()
        }
    })
}

/// Submits a campaign (the campaign spec of README.md and docs/api.md; `"scene": "jet"` for a
/// jet campaign, docs/jet-campaigns.md).
#[utoipa::path(post, path = "/api/v1/campaigns",
    request_body(content = Object, description = "campaign spec; every field optional"),
    params(("Idempotency-Key" = Option<String>, Header, description = "a retried submit with the same key returns the first campaign")),
    responses((status = 201, body = CampaignCreated), (status = 200, body = CampaignCreated, description = "idempotent replay"),
        (status = 400, body = ErrorBody), (status = 401), (status = 409, body = ErrorBody), (status = 413), (status = 422, body = ErrorBody)),
    security(("submit_token" = [])))]
async fn create_campaign(
    State(s): State<AppState>,
    headers: HeaderMap,
    body: Bytes,
) -> Result<(StatusCode, Json<CampaignCreated>)> {
    let spec = spec_of(&body)?;
    let key = headers
        .get("idempotency-key")
        .map(|v| {
            v.to_str()
                .map_err(|_| Error::invalid("Idempotency-Key", "must be ASCII"))
        })
        .transpose()?;
    if key.is_some_and(|k| k.is_empty() || k.len() > 200) {
        return Err(Error::invalid(
            "Idempotency-Key",
            "must be 1 to 200 characters",
        ));
    }
    let created = s.store.create(&spec, key).await?;
    let status = if created.created {
        StatusCode::CREATED
    } else {
        StatusCode::OK
    };
    Ok((status, Json(created)))
}

#[utoipa::path(get, path = "/api/v1/campaigns",
    responses((status = 200, body = Vec<CampaignSummary>), (status = 401)), security(("submit_token" = [])))]
async fn list_campaigns(State(s): State<AppState>) -> Result<Json<Vec<CampaignSummary>>> {
    Ok(Json(s.store.list_campaigns().await?))
}

#[utoipa::path(get, path = "/api/v1/campaigns/{id}", params(("id" = Uuid, Path)),
    responses((status = 200, body = CampaignStatus), (status = 401), (status = 404, body = ErrorBody)),
    security(("submit_token" = [])))]
async fn campaign_status(
    State(s): State<AppState>,
    Path(id): Path<String>,
) -> Result<Json<CampaignStatus>> {
    Ok(Json(s.store.status(campaign_id(&id)?).await?))
}

/// Query of `GET /campaigns/{id}/results`.
#[derive(utoipa::IntoParams)]
#[into_params(parameter_in = Query)]
struct ResultsQuery {
    /// Include every sample's per-impact series (`true` or `false`, default false).
    raw: bool,
}

impl ResultsQuery {
    fn parse(q: &BTreeMap<String, String>) -> Result<ResultsQuery> {
        let mut out = ResultsQuery { raw: false };
        for (key, value) in q {
            match key.as_str() {
                "raw" => {
                    out.raw = value.parse().map_err(|_| {
                        Error::invalid("raw", format!("must be true or false, got {value:?}"))
                    })?
                }
                other => return Err(unknown_param(other, "raw")),
            }
        }
        Ok(out)
    }
}

#[utoipa::path(get, path = "/api/v1/campaigns/{id}/results", params(("id" = Uuid, Path), ResultsQuery),
    responses((status = 200, body = AnyResults, description = "an impact campaign's ResultsResponse, or a jet campaign's JetResultsResponse (`scene: jet`)"),
        (status = 401), (status = 404, body = ErrorBody),
        (status = 422, body = ErrorBody, description = "a bad `raw`, or an unknown parameter")),
    security(("submit_token" = [])))]
async fn campaign_results(
    State(s): State<AppState>,
    Path(id): Path<String>,
    Query(q): Query<BTreeMap<String, String>>,
) -> Result<impl IntoResponse> {
    let id = campaign_id(&id)?;
    let q = ResultsQuery::parse(&q)?;
    let json = s.store.results_json(id, q.raw).await?;
    Ok(([(header::CONTENT_TYPE, "application/json")], json))
}

/// Query of `GET /campaigns/{id}/jobs`.
#[derive(utoipa::IntoParams)]
#[into_params(parameter_in = Query)]
struct JobsQuery {
    /// Only jobs in this state.
    #[param(inline)]
    state: Option<JobState>,
    /// At most this many jobs, 1 to 10000 (default 1000).
    limit: Option<u32>,
}

/// Most jobs one `GET /campaigns/{id}/jobs` answers with.
const MAX_JOBS_LIMIT: u32 = 10_000;

impl JobsQuery {
    fn parse(q: &BTreeMap<String, String>) -> Result<JobsQuery> {
        let mut out = JobsQuery {
            state: None,
            limit: None,
        };
        for (key, value) in q {
            match key.as_str() {
                "state" => {
                    out.state = Some(JobState::parse(value).ok_or_else(|| {
                        Error::invalid(
                            "state",
                            format!(
                                "must be one of {}, got {value:?}",
                                JobState::ALL.map(JobState::as_str).join(", ")
                            ),
                        )
                    })?)
                }
                "limit" => {
                    out.limit = Some(
                        value
                            .parse()
                            .ok()
                            .filter(|n| (1..=MAX_JOBS_LIMIT).contains(n))
                            .ok_or_else(|| {
                                Error::invalid(
                                    "limit",
                                    format!(
                                    "must be an integer from 1 to {MAX_JOBS_LIMIT}, got {value:?}"
                                ),
                                )
                            })?,
                    )
                }
                other => return Err(unknown_param(other, "state, limit")),
            }
        }
        Ok(out)
    }
}

/// A campaign's jobs, e.g. `?state=failed` for the failed ones with their errors.
#[utoipa::path(get, path = "/api/v1/campaigns/{id}/jobs", params(("id" = Uuid, Path), JobsQuery),
    responses((status = 200, body = Vec<JobInfo>, description = "in cell and sample order"), (status = 401),
        (status = 404, body = ErrorBody), (status = 422, body = ErrorBody, description = "a bad `state` or `limit`, or an unknown parameter")),
    security(("submit_token" = [])))]
async fn campaign_jobs(
    State(s): State<AppState>,
    Path(id): Path<String>,
    Query(q): Query<BTreeMap<String, String>>,
) -> Result<Json<Vec<JobInfo>>> {
    let id = campaign_id(&id)?;
    let q = JobsQuery::parse(&q)?;
    Ok(Json(
        s.store.jobs(id, q.state, q.limit.unwrap_or(1000)).await?,
    ))
}

#[utoipa::path(post, path = "/api/v1/campaigns/{id}/cancel", params(("id" = Uuid, Path)),
    responses((status = 200, body = JobsChanged), (status = 401), (status = 404, body = ErrorBody)),
    security(("submit_token" = [])))]
async fn cancel_campaign(
    State(s): State<AppState>,
    Path(id): Path<String>,
) -> Result<Json<JobsChanged>> {
    let jobs = s.store.cancel(campaign_id(&id)?).await?;
    Ok(Json(JobsChanged { jobs }))
}

#[utoipa::path(post, path = "/api/v1/campaigns/{id}/retry-failed", params(("id" = Uuid, Path)),
    responses((status = 200, body = JobsChanged), (status = 401), (status = 404, body = ErrorBody), (status = 409, body = ErrorBody)),
    security(("submit_token" = [])))]
async fn retry_failed(
    State(s): State<AppState>,
    Path(id): Path<String>,
) -> Result<Json<JobsChanged>> {
    let jobs = s.store.retry_failed(campaign_id(&id)?).await?;
    Ok(Json(JobsChanged { jobs }))
}

/// Raises the caps (`until_steady.max`) of a campaign to those of the body, the campaign's
/// spec with higher caps, and runs on every cell that had stopped at its old cap short of its
/// rule (docs/erosion.md, "Raising the cap").
#[utoipa::path(post, path = "/api/v1/campaigns/{id}/raise-caps", params(("id" = Uuid, Path)),
    request_body(content = Object, description = "the campaign's spec with higher until_steady.max values"),
    responses((status = 200, body = CapsRaised), (status = 400, body = ErrorBody), (status = 401),
        (status = 404, body = ErrorBody),
        (status = 409, body = ErrorBody, description = "another campaign's spec (what differs is named), a lower cap, or a cancelled campaign"),
        (status = 422, body = ErrorBody)),
    security(("submit_token" = [])))]
async fn raise_caps(
    State(s): State<AppState>,
    Path(id): Path<String>,
    body: Bytes,
) -> Result<Json<CapsRaised>> {
    let id = campaign_id(&id)?;
    let spec = spec_of(&body)?;
    let raised = s.store.raise_caps(id, &spec, None).await?;
    Ok(Json(CapsRaised { raised }))
}
