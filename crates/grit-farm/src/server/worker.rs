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
use grit_erosion::jet::JetSlice;
use grit_erosion::ImpactRecord;
use serde::Deserialize;
use serde_json::Value;
use uuid::Uuid;

use super::AppState;
use crate::api::*;
use crate::checkpoint::{verify_any_upload, CheckpointBytes};
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

/// A report's units decoded as its job's scene's records.
#[derive(Default)]
struct Units {
    impacts: Vec<ImpactRecord>,
    slices: Vec<JetSlice>,
}

impl Units {
    fn reported(&self) -> Reported<'_> {
        Reported {
            impacts: &self.impacts,
            slices: &self.slices,
        }
    }
}

/// Each of `units` as a record of `R`; a unit that is not one is a 422 naming its field.
fn records<R: serde::de::DeserializeOwned>(units: Vec<Value>) -> Result<Vec<R>> {
    units
        .into_iter()
        .enumerate()
        .map(|(i, v)| {
            serde_path_to_error::deserialize(v).map_err(|e| {
                let path = e.path().to_string();
                let at = if path == "." {
                    format!("units[{i}]")
                } else {
                    format!("units[{i}].{path}")
                };
                Error::invalid(at, e.into_inner().to_string())
            })
        })
        .collect()
}

impl Report {
    /// The units as job `job`'s scene's records; 404 for an unknown job.
    async fn units(&mut self, s: &AppState, job: i64) -> Result<Units> {
        let units = std::mem::take(&mut self.units);
        if units.is_empty() {
            return Ok(Units::default());
        }
        Ok(match s.store.job_scene(job).await?.as_str() {
            "jet" => Units {
                slices: records(units)?,
                ..Units::default()
            },
            _ => Units {
                impacts: records(units)?,
                ..Units::default()
            },
        })
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
    components(schemas(HeartbeatRequest, CompleteRequest, FailRequest, ReleaseRequest))
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
                Error::invalid("(body)", inner.to_string())
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

/// The bytes and checksum of `checkpoint` for the store, refused with a 422 naming the field
/// at fault unless it is intact and job `job_id`'s own (`crate::checkpoint::verify_upload`);
/// 404 for an unknown job.
async fn check_checkpoint(
    s: &AppState,
    job_id: i64,
    checkpoint: Option<Checkpoint>,
) -> Result<Option<CheckpointBytes>> {
    let Some(c) = checkpoint else {
        return Ok(None);
    };
    let (params, seed) = s.store.job_params(job_id).await?;
    // Decoding a checkpoint of a large surface or a jet's world takes milliseconds: off the
    // async threads.
    let checked = tokio::task::spawn_blocking(move || verify_any_upload(&c, job_id, &params, seed))
        .await
        .map_err(|e| Error::Internal(format!("checkpoint check panicked: {e}")))?;
    checked.map(Some).map_err(|e| {
        tracing::warn!(job = job_id, error = %e, "checkpoint refused; nothing of the request stored");
        Error::invalid(e.field, e.rule)
    })
}

/// Leases the next job; 204 when the queue is empty.
#[utoipa::path(post, path = "/api/v1/worker/claim", request_body = ClaimRequest,
    responses((status = 200, body = ClaimedJob), (status = 204, description = "no job queued"), (status = 401)),
    security(("worker_token" = [])))]
async fn claim(State(s): State<AppState>, ApiJson(req): ApiJson<ClaimRequest>) -> Result<Response> {
    if req.worker.trim().is_empty() || req.worker.len() > 200 {
        return Err(Error::invalid(
            "worker",
            "must be 1 to 200 characters, not all blank",
        ));
    }
    Ok(match s.store.claim(&req.worker).await? {
        Some(job) => Json(job).into_response(),
        None => StatusCode::NO_CONTENT.into_response(),
    })
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
    ApiJson(mut req): ApiJson<Report>,
) -> Result<Json<HeartbeatResponse>> {
    let job = job_id(&job)?;
    if req.error.is_some() {
        return Err(Report::refuse("error", "heartbeat"));
    }
    let units = req.units(&s, job).await?;
    let checkpoint = check_checkpoint(&s, job, req.checkpoint.take()).await?;
    Ok(Json(
        s.store
            .heartbeat_with(job, req.lease_id, units.reported(), checkpoint)
            .await?,
    ))
}

#[utoipa::path(post, path = "/api/v1/worker/jobs/{job_id}/complete", params(("job_id" = i64, Path)),
    request_body(content = CompleteRequest, description = "units as the job's scene records them"),
    responses((status = 204), (status = 401), (status = 404, body = ErrorBody), (status = 409, body = ErrorBody),
        (status = 410, body = ErrorBody), (status = 422, body = ErrorBody, description = CHECKPOINT_422)),
    security(("worker_token" = [])))]
async fn complete(
    State(s): State<AppState>,
    Path(job): Path<String>,
    ApiJson(mut req): ApiJson<Report>,
) -> Result<StatusCode> {
    let job = job_id(&job)?;
    if req.error.is_some() {
        return Err(Report::refuse("error", "complete"));
    }
    let units = req.units(&s, job).await?;
    let checkpoint = check_checkpoint(&s, job, req.checkpoint.take()).await?;
    s.store
        .complete_with(job, req.lease_id, units.reported(), checkpoint)
        .await?;
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
    let units = req.units(&s, job).await?;
    s.store
        .fail_with(job, req.lease_id, &error, units.reported())
        .await?;
    Ok(StatusCode::NO_CONTENT)
}

#[utoipa::path(post, path = "/api/v1/worker/jobs/{job_id}/release", params(("job_id" = i64, Path)),
    request_body(content = ReleaseRequest, description = "units as the job's scene records them"),
    responses((status = 204), (status = 401), (status = 404, body = ErrorBody), (status = 409, body = ErrorBody), (status = 410, body = ErrorBody),
        (status = 422, body = ErrorBody, description = CHECKPOINT_422)),
    security(("worker_token" = [])))]
async fn release(
    State(s): State<AppState>,
    Path(job): Path<String>,
    ApiJson(mut req): ApiJson<Report>,
) -> Result<StatusCode> {
    let job = job_id(&job)?;
    if req.error.is_some() {
        return Err(Report::refuse("error", "release"));
    }
    let units = req.units(&s, job).await?;
    let checkpoint = check_checkpoint(&s, job, req.checkpoint.take()).await?;
    s.store
        .release_with(job, req.lease_id, units.reported(), checkpoint)
        .await?;
    Ok(StatusCode::NO_CONTENT)
}
