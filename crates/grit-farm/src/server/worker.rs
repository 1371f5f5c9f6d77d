//! The endpoints workers call, under the worker token: claim a lease, then heartbeat (with
//! impacts and checkpoints), complete, fail or release the job it holds.

use axum::extract::{FromRequest, Path, Request, State};
use axum::http::StatusCode;
use axum::response::{IntoResponse, Response};
use axum::routing::post;
use axum::{Json, Router};

use super::AppState;
use crate::api::*;
use crate::error::{Error, Result};

/// The worker routes, relative to `/api/v1`.
pub fn router() -> Router<AppState> {
    Router::new()
        .route("/worker/claim", post(claim))
        .route("/worker/jobs/{job_id}/heartbeat", post(heartbeat))
        .route("/worker/jobs/{job_id}/complete", post(complete))
        .route("/worker/jobs/{job_id}/fail", post(fail))
        .route("/worker/jobs/{job_id}/release", post(release))
}

/// The worker endpoints' part of the OpenAPI document.
#[derive(utoipa::OpenApi)]
#[openapi(paths(claim, heartbeat, complete, fail, release))]
pub struct Doc;

/// JSON body extractor whose rejections use the API's error body (status kept: 400 for
/// syntax, 422 naming the field for a wrong value, 413 for too large, 415 for no JSON type).
pub struct ApiJson<T>(pub T);

impl<S, T> FromRequest<S> for ApiJson<T>
where
    Json<T>: FromRequest<S, Rejection = axum::extract::rejection::JsonRejection>,
    S: Send + Sync,
{
    type Rejection = Error;

    async fn from_request(req: Request, state: &S) -> Result<Self, Error> {
        match Json::<T>::from_request(req, state).await {
            Ok(Json(v)) => Ok(ApiJson(v)),
            Err(r) => Err(Error::BadRequest {
                status: r.status(),
                message: r.body_text(),
            }),
        }
    }
}

/// Leases the next job; 204 when the queue is empty.
#[utoipa::path(post, path = "/api/v1/worker/claim", request_body = ClaimRequest,
    responses((status = 200, body = ClaimedJob), (status = 204, description = "no job queued"), (status = 401)),
    security(("worker_token" = [])))]
async fn claim(State(s): State<AppState>, ApiJson(req): ApiJson<ClaimRequest>) -> Result<Response> {
    if req.worker.len() > 200 {
        return Err(Error::invalid("worker", "must be at most 200 characters"));
    }
    Ok(match s.store.claim(&req.worker).await? {
        Some(job) => Json(job).into_response(),
        None => StatusCode::NO_CONTENT.into_response(),
    })
}

#[utoipa::path(post, path = "/api/v1/worker/jobs/{job_id}/heartbeat", params(("job_id" = i64, Path)),
    request_body = HeartbeatRequest,
    responses((status = 200, body = HeartbeatResponse), (status = 401), (status = 404, body = ErrorBody),
        (status = 409, body = ErrorBody, description = "not the lease holder; nothing stored"),
        (status = 410, body = ErrorBody, description = "campaign cancelled; drop the job"), (status = 422, body = ErrorBody)),
    security(("worker_token" = [])))]
async fn heartbeat(
    State(s): State<AppState>,
    Path(job): Path<i64>,
    ApiJson(req): ApiJson<HeartbeatRequest>,
) -> Result<Json<HeartbeatResponse>> {
    Ok(Json(
        s.store
            .heartbeat(job, req.lease_id, &req.impacts, req.checkpoint.as_ref())
            .await?,
    ))
}

#[utoipa::path(post, path = "/api/v1/worker/jobs/{job_id}/complete", params(("job_id" = i64, Path)),
    request_body = CompleteRequest,
    responses((status = 204), (status = 401), (status = 404, body = ErrorBody), (status = 409, body = ErrorBody),
        (status = 410, body = ErrorBody), (status = 422, body = ErrorBody)),
    security(("worker_token" = [])))]
async fn complete(
    State(s): State<AppState>,
    Path(job): Path<i64>,
    ApiJson(req): ApiJson<CompleteRequest>,
) -> Result<StatusCode> {
    s.store
        .complete(job, req.lease_id, &req.impacts, req.checkpoint.as_ref())
        .await?;
    Ok(StatusCode::NO_CONTENT)
}

#[utoipa::path(post, path = "/api/v1/worker/jobs/{job_id}/fail", params(("job_id" = i64, Path)),
    request_body = FailRequest,
    responses((status = 204), (status = 401), (status = 404, body = ErrorBody), (status = 409, body = ErrorBody), (status = 410, body = ErrorBody)),
    security(("worker_token" = [])))]
async fn fail(
    State(s): State<AppState>,
    Path(job): Path<i64>,
    ApiJson(req): ApiJson<FailRequest>,
) -> Result<StatusCode> {
    s.store
        .fail(job, req.lease_id, &req.error, &req.impacts)
        .await?;
    Ok(StatusCode::NO_CONTENT)
}

#[utoipa::path(post, path = "/api/v1/worker/jobs/{job_id}/release", params(("job_id" = i64, Path)),
    request_body = ReleaseRequest,
    responses((status = 204), (status = 401), (status = 404, body = ErrorBody), (status = 409, body = ErrorBody), (status = 410, body = ErrorBody)),
    security(("worker_token" = [])))]
async fn release(
    State(s): State<AppState>,
    Path(job): Path<i64>,
    ApiJson(req): ApiJson<ReleaseRequest>,
) -> Result<StatusCode> {
    s.store
        .release(job, req.lease_id, &req.impacts, req.checkpoint.as_ref())
        .await?;
    Ok(StatusCode::NO_CONTENT)
}
