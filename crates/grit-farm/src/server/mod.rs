//! The coordinator's HTTP API under `/api/v1`: one router per resource (`campaigns`, the
//! `worker` lease endpoints, the `workers` list), merged by `app` with the bearer-token
//! checks, body limits and the OpenAPI document. `app` builds the whole service so tests and
//! the embedded mode run the same one as `grit serve`.

use std::net::SocketAddr;
use std::sync::Arc;
use std::time::Duration;

use axum::extract::{DefaultBodyLimit, State};
use axum::middleware;
use axum::routing::get;
use axum::{Json, Router};
use utoipa::OpenApi;

use crate::api::Health;
use crate::db::Store;
use crate::error::{Error, Result};

mod auth;
pub mod campaigns;
pub mod worker;
pub mod workers;

pub use auth::Secret;
pub use worker::{ApiJson, NO_JOB_HEADER};

/// Largest campaign spec accepted (bytes); larger gets 413.
pub const DEFAULT_SUBMIT_LIMIT: usize = 1 << 20;
/// Largest worker request (bytes): a heartbeat may carry a base64 checkpoint of a few MB.
pub const DEFAULT_WORKER_LIMIT: usize = 256 << 20;

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
    /// Workers already told in the log why they get no job, so each is told once.
    pub told: Arc<std::sync::Mutex<std::collections::HashSet<String>>>,
}

/// The 422 for a query parameter an endpoint does not take, listing the ones it does.
fn unknown_param(name: &str, expected: &str) -> Error {
    Error::invalid(
        name,
        format!("unknown query parameter; this endpoint takes {expected}"),
    )
}

#[utoipa::path(get, path = "/api/v1/healthz", responses((status = 200, body = Health)))]
async fn healthz(State(s): State<AppState>) -> Result<Json<Health>> {
    s.store.ping().await?;
    Ok(Json(Health {
        status: "ok".into(),
        version: env!("CARGO_PKG_VERSION").into(),
    }))
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

/// Adds each resource's paths and schemas to the document.
struct Resources;

impl utoipa::Modify for Resources {
    fn modify(&self, openapi: &mut utoipa::openapi::OpenApi) {
        openapi.merge(campaigns::Doc::openapi());
        openapi.merge(workers::Doc::openapi());
        openapi.merge(worker::Doc::openapi());
    }
}

/// The OpenAPI document of the API.
#[derive(OpenApi)]
#[openapi(
    info(title = "grit coordinator", description = "Campaigns of SPH erosion impacts farmed out to workers."),
    paths(healthz),
    modifiers(&Resources, &Security)
)]
pub struct ApiDoc;

async fn openapi() -> Json<utoipa::openapi::OpenApi> {
    Json(ApiDoc::openapi())
}

async fn not_found() -> Error {
    Error::NotFound("route".into())
}

/// The API's JSON error body for the refusals the framework answers itself, which come as
/// plain text or empty: 413 for a body over the limit, 405 for a method the path does not
/// take, 400 for a query that does not parse. Status and headers stay.
async fn json_errors(resp: axum::response::Response) -> axum::response::Response {
    use axum::http::header::{CONTENT_LENGTH, CONTENT_TYPE};
    use axum::response::IntoResponse;
    let status = resp.status();
    let json = resp
        .headers()
        .get(CONTENT_TYPE)
        .and_then(|v| v.to_str().ok())
        .is_some_and(|c| c.starts_with("application/json"));
    if json || !(status.is_client_error() || status.is_server_error()) {
        return resp;
    }
    let (mut parts, body) = resp.into_parts();
    let text = axum::body::to_bytes(body, 64 << 10)
        .await
        .map(|b| String::from_utf8_lossy(&b).trim().to_string())
        .unwrap_or_default();
    let error = if status == axum::http::StatusCode::PAYLOAD_TOO_LARGE {
        "the body is over the coordinator's limit (grit serve --max-spec-bytes for campaign specs, --max-worker-bytes for worker requests)".into()
    } else if !text.is_empty() {
        text
    } else if status == axum::http::StatusCode::METHOD_NOT_ALLOWED {
        // The method router sets `Allow` outside this layer.
        "method not allowed; the Allow header lists the methods this path takes".into()
    } else {
        status.canonical_reason().unwrap_or("error").to_lowercase()
    };
    parts.headers.remove(CONTENT_LENGTH);
    parts.headers.remove(CONTENT_TYPE);
    let mut out = Json(crate::api::ErrorBody { error, field: None }).into_response();
    *out.status_mut() = status;
    for (name, value) in &parts.headers {
        out.headers_mut().insert(name.clone(), value.clone());
    }
    out
}

/// The whole service: the API under `/api/v1` and the dashboard page at `/`.
pub fn app(state: AppState) -> Router {
    let submit = Router::new()
        .merge(campaigns::router())
        .merge(workers::router())
        .route_layer(middleware::from_fn_with_state(
            state.clone(),
            auth::require_submit,
        ))
        .layer(DefaultBodyLimit::max(state.config.submit_limit));
    let worker = worker::router()
        .route_layer(middleware::from_fn_with_state(
            state.clone(),
            auth::require_worker,
        ))
        .layer(DefaultBodyLimit::max(state.config.worker_limit));
    let open = Router::new()
        .route("/healthz", get(healthz))
        .route("/openapi.json", get(openapi));
    Router::new()
        .nest(
            "/api/v1",
            Router::new().merge(submit).merge(worker).merge(open),
        )
        .route("/healthz", get(healthz))
        .merge(crate::dashboard::router())
        .fallback(not_found)
        .layer(middleware::map_response(json_errors))
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
        told: Default::default(),
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
