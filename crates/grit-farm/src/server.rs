//! The coordinator's HTTP API under `/api/v1`: routes, bearer-token checks, body limits and
//! the OpenAPI document. `app` builds the router so tests and the embedded mode run the same
//! service as `grit serve`.

use std::collections::BTreeMap;
use std::net::SocketAddr;
use std::sync::Arc;
use std::time::Duration;

use axum::body::Bytes;
use axum::extract::{DefaultBodyLimit, FromRequest, Path, Query, Request, State};
use axum::http::{HeaderMap, StatusCode};
use axum::middleware::{self, Next};
use axum::response::{IntoResponse, Response};
use axum::routing::{get, post};
use axum::{Json, Router};
use grit_erosion::campaign::CampaignSpec;
use serde::Deserialize;
use subtle::ConstantTimeEq;
use utoipa::OpenApi;
use uuid::Uuid;

use crate::api::*;
use crate::db::Store;
use crate::error::{Error, Result};

/// Largest campaign spec accepted (bytes); larger gets 413.
pub const DEFAULT_SUBMIT_LIMIT: usize = 1 << 20;
/// Largest worker request (bytes): a heartbeat may carry a base64 checkpoint of a few MB.
pub const DEFAULT_WORKER_LIMIT: usize = 256 << 20;

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

/// Coordinator configuration beyond the database.
#[derive(Debug, Clone)]
pub struct Config {
    /// Token for submitting and reading campaigns.
    pub submit_token: Secret,
    /// Token for workers.
    pub worker_token: Secret,
    /// Largest campaign spec body, bytes.
    pub submit_limit: usize,
    /// Largest worker body, bytes.
    pub worker_limit: usize,
}

impl Default for Config {
    fn default() -> Self {
        Config {
            submit_token: Secret::default(),
            worker_token: Secret::default(),
            submit_limit: DEFAULT_SUBMIT_LIMIT,
            worker_limit: DEFAULT_WORKER_LIMIT,
        }
    }
}

/// Shared state of the handlers.
#[derive(Clone)]
pub struct AppState {
    /// The database.
    pub store: Store,
    /// Tokens and limits.
    pub config: Arc<Config>,
}

fn bearer(headers: &HeaderMap) -> Option<&str> {
    headers
        .get(axum::http::header::AUTHORIZATION)?
        .to_str()
        .ok()?
        .strip_prefix("Bearer ")
        .map(str::trim)
}

async fn require_submit(State(s): State<AppState>, req: Request, next: Next) -> Response {
    if s.config.submit_token.accepts(bearer(req.headers())) {
        next.run(req).await
    } else {
        Error::Unauthorized.into_response()
    }
}

async fn require_worker(State(s): State<AppState>, req: Request, next: Next) -> Response {
    if s.config.worker_token.accepts(bearer(req.headers())) {
        next.run(req).await
    } else {
        Error::Unauthorized.into_response()
    }
}

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

fn campaign_id(raw: &str) -> Result<Uuid> {
    raw.parse()
        .map_err(|_| Error::NotFound(format!("campaign {raw}")))
}

#[utoipa::path(get, path = "/api/v1/healthz", responses((status = 200, body = Health)))]
async fn healthz(State(s): State<AppState>) -> Result<Json<Health>> {
    s.store.ping().await?;
    Ok(Json(Health {
        status: "ok".into(),
        version: env!("CARGO_PKG_VERSION").into(),
    }))
}

/// Submits a campaign (issue 3 campaign spec).
#[utoipa::path(post, path = "/api/v1/campaigns",
    request_body(content = Object, description = "campaign spec (issue 3); every field optional"),
    params(("Idempotency-Key" = Option<String>, Header, description = "a retried submit with the same key returns the first campaign")),
    responses((status = 201, body = CampaignCreated), (status = 200, body = CampaignCreated, description = "idempotent replay"),
        (status = 400, body = ErrorBody), (status = 401), (status = 409, body = ErrorBody), (status = 413), (status = 422, body = ErrorBody)),
    security(("submit_token" = [])))]
async fn create_campaign(
    State(s): State<AppState>,
    headers: HeaderMap,
    body: Bytes,
) -> Result<(StatusCode, Json<CampaignCreated>)> {
    let text = std::str::from_utf8(&body).map_err(|_| Error::BadRequest {
        status: StatusCode::BAD_REQUEST,
        message: "body is not UTF-8 JSON".into(),
    })?;
    let spec = CampaignSpec::from_json(text).map_err(|e| {
        if e.field == "(json)" {
            Error::BadRequest {
                status: StatusCode::BAD_REQUEST,
                message: format!("malformed JSON: {}", e.rule),
            }
        } else {
            e.into()
        }
    })?;
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
    let created = s.store.create_campaign(&spec, key).await?;
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

#[derive(Deserialize, utoipa::IntoParams)]
struct ResultsQuery {
    /// Include every sample's per-impact series.
    #[serde(default)]
    raw: bool,
}

#[utoipa::path(get, path = "/api/v1/campaigns/{id}/results", params(("id" = Uuid, Path), ResultsQuery),
    responses((status = 200, body = ResultsResponse), (status = 401), (status = 404, body = ErrorBody)),
    security(("submit_token" = [])))]
async fn campaign_results(
    State(s): State<AppState>,
    Path(id): Path<String>,
    Query(q): Query<ResultsQuery>,
) -> Result<Json<ResultsResponse>> {
    Ok(Json(s.store.results(campaign_id(&id)?, q.raw).await?))
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

fn unknown_param(name: &str, expected: &str) -> Error {
    Error::invalid(
        name,
        format!("unknown query parameter; this endpoint takes {expected}"),
    )
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
    s.store.complete(job, req.lease_id, &req.impacts).await?;
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

struct Security;

impl utoipa::Modify for Security {
    fn modify(&self, openapi: &mut utoipa::openapi::OpenApi) {
        use utoipa::openapi::security::{HttpAuthScheme, HttpBuilder, SecurityScheme};
        let comps = openapi.components.get_or_insert_with(Default::default);
        for name in ["submit_token", "worker_token"] {
            comps.add_security_scheme(
                name,
                SecurityScheme::Http(HttpBuilder::new().scheme(HttpAuthScheme::Bearer).build()),
            );
        }
    }
}

/// The OpenAPI document of the API.
#[derive(OpenApi)]
#[openapi(
    info(title = "grit coordinator", description = "Campaigns of SPH erosion impacts farmed out to workers (issue 4)."),
    paths(healthz, create_campaign, list_campaigns, campaign_status, campaign_results,
          campaign_jobs, list_workers, cancel_campaign, retry_failed, claim, heartbeat, complete,
          fail, release),
    modifiers(&Security)
)]
pub struct ApiDoc;

async fn openapi() -> Json<utoipa::openapi::OpenApi> {
    Json(ApiDoc::openapi())
}

async fn not_found() -> Error {
    Error::NotFound("route".into())
}

/// The whole service: the API under `/api/v1` and the dashboard page at `/`.
pub fn app(state: AppState) -> Router {
    let campaigns = Router::new()
        .route("/campaigns", post(create_campaign).get(list_campaigns))
        .route("/campaigns/{id}", get(campaign_status))
        .route("/campaigns/{id}/results", get(campaign_results))
        .route("/campaigns/{id}/jobs", get(campaign_jobs))
        .route("/workers", get(list_workers))
        .route("/campaigns/{id}/cancel", post(cancel_campaign))
        .route("/campaigns/{id}/retry-failed", post(retry_failed))
        .route_layer(middleware::from_fn_with_state(
            state.clone(),
            require_submit,
        ))
        .layer(DefaultBodyLimit::max(state.config.submit_limit));
    let worker = Router::new()
        .route("/worker/claim", post(claim))
        .route("/worker/jobs/{job_id}/heartbeat", post(heartbeat))
        .route("/worker/jobs/{job_id}/complete", post(complete))
        .route("/worker/jobs/{job_id}/fail", post(fail))
        .route("/worker/jobs/{job_id}/release", post(release))
        .route_layer(middleware::from_fn_with_state(
            state.clone(),
            require_worker,
        ))
        .layer(DefaultBodyLimit::max(state.config.worker_limit));
    let open = Router::new()
        .route("/healthz", get(healthz))
        .route("/openapi.json", get(openapi));
    Router::new()
        .nest(
            "/api/v1",
            Router::new().merge(campaigns).merge(worker).merge(open),
        )
        .route("/healthz", get(healthz))
        .merge(crate::dashboard::router())
        .fallback(not_found)
        .layer(tower_http::trace::TraceLayer::new_for_http())
        .with_state(state)
}

/// A coordinator bound to its address, running in the background.
pub struct Running {
    /// The address actually bound (port 0 resolved).
    pub addr: SocketAddr,
    /// The store, shared with the handlers.
    pub store: Store,
    shutdown: tokio::sync::watch::Sender<bool>,
    task: tokio::task::JoinHandle<std::io::Result<()>>,
}

impl Running {
    /// Stops accepting connections and waits for the server to finish.
    pub async fn stop(self) {
        let _ = self.shutdown.send(true);
        let _ = self.task.await;
    }
}

/// Binds `listen` and serves the API until stopped; expired leases are reaped in the
/// background every quarter lease.
pub async fn start(listen: &str, store: Store, config: Config) -> std::io::Result<Running> {
    let listener = tokio::net::TcpListener::bind(listen).await?;
    let addr = listener.local_addr()?;
    let (tx, mut rx) = tokio::sync::watch::channel(false);
    let reaper_store = store.clone();
    let period = (store.lease_ttl / 4).clamp(Duration::from_millis(200), Duration::from_secs(10));
    let mut reaper_rx = rx.clone();
    tokio::spawn(async move {
        loop {
            tokio::select! {
                _ = tokio::time::sleep(period) => {}
                _ = reaper_rx.changed() => return,
            }
            if let Err(e) = reaper_store.reap_expired().await {
                tracing::error!(error = %e, "reaping expired leases failed");
            }
        }
    });
    let state = AppState {
        store: store.clone(),
        config: Arc::new(config),
    };
    let router = app(state);
    let task = tokio::spawn(async move {
        axum::serve(listener, router)
            .with_graceful_shutdown(async move {
                let _ = rx.changed().await;
            })
            .await
    });
    Ok(Running {
        addr,
        store,
        shutdown: tx,
        task,
    })
}
