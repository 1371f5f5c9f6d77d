//! The endpoints workers call, under the worker token: claim a lease, then heartbeat (with
//! impacts and checkpoints), complete, fail or release the job it holds. A checkpoint is
//! verified (`crate::checkpoint::verify_upload`) before the store sees the request, so a
//! refused one leaves nothing of its request stored, impacts included; the store gets the
//! bytes and checksum that check produced, and decodes nothing again. A job reports its units
//! (impacts, slices) as its scene records them, under `units` (or the older names `impacts`
//! and `slices`); each body is read as the union of the four requests.

use axum::body::Bytes;
use axum::extract::{FromRequest, Path, Request, State};
use axum::http::StatusCode;
use axum::response::{IntoResponse, Response};
use axum::routing::post;
use axum::{Json, Router};
use serde::Deserialize;
use serde_json::Value;
use uuid::Uuid;

use super::AppState;
use crate::api::*;
use crate::db::Reported;
use crate::error::{Error, Result};

/// A heartbeat, complete, fail or release body: `HeartbeatRequest` and its kin in one, each
/// field optional as in all of them. Its units are decoded as the job's scene records them.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Report {
    lease_id: Uuid,
    #[serde(default, alias = "impacts", alias = "slices")]
    units: Vec<Value>,
    #[serde(default)]
    checkpoint: Option<Checkpoint>,
    /// Only in a fail body.
    #[serde(default)]
    error: Option<String>,
}

impl Report {
    /// The units and checkpoint of a write to job `job`, checked by the job's scene: the
    /// units decoded as its records (a 422 naming `units[i]…` for one that is not), the
    /// checkpoint verified (`crate::checkpoint::verify_upload`) as the job's own. One read of
    /// the job serves both; 404 for an unknown job.
    async fn checked(&mut self, s: &AppState, job: i64) -> Result<Reported> {
        let units = std::mem::take(&mut self.units);
        let checkpoint = self.checkpoint.take();
        if units.is_empty() && checkpoint.is_none() {
            return Ok(Reported::none());
        }
        let stored = s.store.stored_job(job).await?;
        let scene = s.store.scenes.get(&stored.scene)?;
        let reported = scene.decode(units)?;
        let Some(c) = checkpoint else {
            return Ok(reported);
        };
        // Decoding a checkpoint of a large surface or a jet's world takes milliseconds: off
        // the async threads.
        let checked = tokio::task::spawn_blocking(move || scene.verify_upload(&c, &stored))
            .await
            .map_err(|e| Error::Internal(format!("checkpoint check panicked: {e}")))?;
        let bytes = checked.map_err(|e| {
            tracing::warn!(job, error = %e, "checkpoint refused; nothing of the request stored");
            Error::invalid(e.field, e.rule)
        })?;
        Ok(reported.with_checkpoint(Some(bytes)))
    }

    /// A heartbeat, complete or release body for job `raw` (which takes no `error`): the job
    /// id, lease, and the units and checkpoint checked by [`Report::checked`].
    async fn without_error(
        mut self,
        s: &AppState,
        raw: &str,
        endpoint: &str,
    ) -> Result<(i64, Uuid, Reported)> {
        let job = job_id(raw)?;
        if self.error.is_some() {
            return Err(Report::refuse("error", endpoint));
        }
        let reported = self.checked(s, job).await?;
        Ok((job, self.lease_id, reported))
    }

    /// The 422 for a field the endpoint does not take.
    fn refuse(field: &str, endpoint: &str) -> Error {
        Error::invalid(field, format!("unknown field for {endpoint}"))
    }
}

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
#[openapi(
    paths(claim, heartbeat, complete, fail, release),
    components(schemas(HeartbeatRequest, CompleteRequest, FailRequest))
)]
pub struct Doc;

/// What a 422 to a request with a checkpoint may mean, for the OpenAPI document.
const CHECKPOINT_422: &str = "a value breaking a rule, `field` naming it; a checkpoint that is not this job's \
(`checkpoint.job_id`), cut short (`checkpoint truncated`), damaged (`checkpoint checksum mismatch`) or \
not a checkpoint of this job's scene and seed: nothing of the request was stored, impacts included";

/// JSON body extractor whose rejections use the API's error body: 415 without a JSON content
/// type, 413 for too large, 400 for malformed JSON, and 422 naming the field for a wrong value.
pub struct ApiJson<T>(pub T);

/// Whether a `Content-Type` names JSON: `application/json` or a `+json` type, any parameters.
fn is_json(content_type: &str) -> bool {
    let mime = content_type
        .split(';')
        .next()
        .unwrap_or("")
        .trim()
        .to_ascii_lowercase();
    mime == "application/json" || (mime.ends_with("+json") && mime.len() > 5)
}

impl<S, T> FromRequest<S> for ApiJson<T>
where
    T: serde::de::DeserializeOwned,
    S: Send + Sync,
{
    type Rejection = Error;

    async fn from_request(req: Request, state: &S) -> Result<Self, Error> {
        let json = req
            .headers()
            .get(axum::http::header::CONTENT_TYPE)
            .and_then(|v| v.to_str().ok())
            .is_some_and(is_json);
        if !json {
            return Err(Error::BadRequest {
                status: StatusCode::UNSUPPORTED_MEDIA_TYPE,
                message: "expected a body with Content-Type: application/json".into(),
            });
        }
        let body = Bytes::from_request(req, state)
            .await
            .map_err(|r| Error::BadRequest {
                status: r.status(),
                message: r.body_text(),
            })?;
        let malformed = |e: serde_json::Error| Error::BadRequest {
            status: StatusCode::BAD_REQUEST,
            message: format!("malformed JSON: {e}"),
        };
        let de = &mut serde_json::Deserializer::from_slice(&body);
        let value = serde_path_to_error::deserialize(&mut *de).map_err(|e| {
            let path = e.path().to_string();
            let inner = e.into_inner();
            if inner.is_data() && path != "." {
                Error::invalid(path, inner.to_string())
            } else if inner.is_data() {
                // A missing field is reported at the body; name the field itself.
                let message = inner.to_string();
                let field = message
                    .strip_prefix("missing field `")
                    .and_then(|rest| rest.split('`').next())
                    .unwrap_or("(body)")
                    .to_string();
                Error::invalid(field, message)
            } else {
                malformed(inner)
            }
        })?;
        de.end().map_err(malformed)?;
        Ok(ApiJson(value))
    }
}

/// A job id from the path; one that is not an integer names no job (404).
fn job_id(raw: &str) -> Result<i64> {
    raw.parse()
        .map_err(|_| Error::NotFound(format!("job {raw} (job ids are integers)")))
}

/// The header of a 204 claim that says why queued jobs were not leased.
pub const NO_JOB_HEADER: &str = "grit-no-job";

/// Leases the next job of a campaign pinned to the worker's engine; 204 when there is none,
/// with [`NO_JOB_HEADER`] saying why when jobs are queued for other engines.
#[utoipa::path(post, path = "/api/v1/worker/claim", request_body = ClaimRequest,
    responses((status = 200, body = ClaimedJob),
        (status = 204, description = "no job for this worker's engine queued"), (status = 401),
        (status = 422, body = ErrorBody, description = "no or a malformed `worker` or `engine`")),
    security(("worker_token" = [])))]
async fn claim(State(s): State<AppState>, ApiJson(req): ApiJson<ClaimRequest>) -> Result<Response> {
    if req.worker.trim().is_empty() || req.worker.len() > 200 {
        return Err(Error::invalid(
            "worker",
            "must be 1 to 200 characters, not all blank",
        ));
    }
    let engines = req
        .engine
        .to_json()
        .map_err(|(field, rule)| Error::invalid(field, rule))?;
    if let Some(job) = s.store.claim_for(&req.worker, &engines).await? {
        return Ok(Json(job).into_response());
    }
    let mut answer = StatusCode::NO_CONTENT.into_response();
    if let Some(why) = s.store.why_no_job(&engines).await? {
        if s.told
            .lock()
            .expect("the told set")
            .insert(req.worker.clone())
        {
            tracing::warn!(worker = %req.worker, "{why}");
        }
        if let Ok(v) = axum::http::HeaderValue::from_str(&why) {
            answer.headers_mut().insert(NO_JOB_HEADER, v);
        }
    }
    Ok(answer)
}

#[utoipa::path(post, path = "/api/v1/worker/jobs/{job_id}/heartbeat", params(("job_id" = i64, Path)),
    request_body(content = HeartbeatRequest, description = "units as the job's scene records them"),
    responses((status = 200, body = HeartbeatResponse), (status = 401), (status = 404, body = ErrorBody),
        (status = 409, body = ErrorBody, description = "not the lease holder; nothing stored"),
        (status = 410, body = ErrorBody, description = "campaign cancelled; drop the job"),
        (status = 422, body = ErrorBody, description = CHECKPOINT_422)),
    security(("worker_token" = [])))]
async fn heartbeat(
    State(s): State<AppState>,
    Path(job): Path<String>,
    ApiJson(req): ApiJson<Report>,
) -> Result<Json<HeartbeatResponse>> {
    let (job, lease, reported) = req.without_error(&s, &job, "heartbeat").await?;
    Ok(Json(s.store.heartbeat(job, lease, reported).await?))
}

#[utoipa::path(post, path = "/api/v1/worker/jobs/{job_id}/complete", params(("job_id" = i64, Path)),
    request_body(content = CompleteRequest, description = "units as the job's scene records them"),
    responses((status = 204), (status = 401), (status = 404, body = ErrorBody), (status = 409, body = ErrorBody),
        (status = 410, body = ErrorBody), (status = 422, body = ErrorBody, description = CHECKPOINT_422)),
    security(("worker_token" = [])))]
async fn complete(
    State(s): State<AppState>,
    Path(job): Path<String>,
    ApiJson(req): ApiJson<Report>,
) -> Result<StatusCode> {
    let (job, lease, reported) = req.without_error(&s, &job, "complete").await?;
    s.store.complete(job, lease, reported).await?;
    Ok(StatusCode::NO_CONTENT)
}

#[utoipa::path(post, path = "/api/v1/worker/jobs/{job_id}/fail", params(("job_id" = i64, Path)),
    request_body(content = FailRequest, description = "units as the job's scene records them"),
    responses((status = 204), (status = 401), (status = 404, body = ErrorBody), (status = 409, body = ErrorBody), (status = 410, body = ErrorBody)),
    security(("worker_token" = [])))]
async fn fail(
    State(s): State<AppState>,
    Path(job): Path<String>,
    ApiJson(mut req): ApiJson<Report>,
) -> Result<StatusCode> {
    let job = job_id(&job)?;
    if req.checkpoint.is_some() {
        return Err(Report::refuse("checkpoint", "fail"));
    }
    let Some(error) = req.error.as_deref().filter(|e| !e.trim().is_empty()) else {
        return Err(Error::invalid(
            "error",
            "missing or empty: say what went wrong",
        ));
    };
    let error = error.to_string();
    let reported = req.checked(&s, job).await?;
    s.store.fail(job, req.lease_id, &error, reported).await?;
    Ok(StatusCode::NO_CONTENT)
}

#[utoipa::path(post, path = "/api/v1/worker/jobs/{job_id}/release", params(("job_id" = i64, Path)),
    request_body(content = HeartbeatRequest, description = "a heartbeat's body: units as the job's scene records them, a checkpoint to resume from"),
    responses((status = 204), (status = 401), (status = 404, body = ErrorBody), (status = 409, body = ErrorBody), (status = 410, body = ErrorBody),
        (status = 422, body = ErrorBody, description = CHECKPOINT_422)),
    security(("worker_token" = [])))]
async fn release(
    State(s): State<AppState>,
    Path(job): Path<String>,
    ApiJson(req): ApiJson<Report>,
) -> Result<StatusCode> {
    let (job, lease, reported) = req.without_error(&s, &job, "release").await?;
    s.store.release(job, lease, reported).await?;
    Ok(StatusCode::NO_CONTENT)
}
