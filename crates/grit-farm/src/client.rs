//! HTTP client of the coordinator API, used by the CLI, the worker and the benchmark.

use std::sync::Arc;
use std::time::Duration;

use reqwest::StatusCode;
use serde::de::DeserializeOwned;
use serde::Serialize;
use uuid::Uuid;

use crate::api::*;
use crate::server::Secret;

/// How long a request may take before the client gives up on it: long enough for a
/// checkpoint upload of a few MB over a slow link.
pub const DEFAULT_REQUEST_TIMEOUT: Duration = Duration::from_secs(300);

/// Why a call failed.
#[derive(Debug, thiserror::Error)]
pub enum ClientError {
    /// The coordinator could not be reached (connection refused, timeout); worth retrying.
    #[error("coordinator unreachable: {0}")]
    Unreachable(String),
    /// The coordinator answered with an error status.
    #[error("HTTP {status}: {message}")]
    Status {
        /// HTTP status.
        status: StatusCode,
        /// The error body's message.
        message: String,
        /// The field it names, if any.
        field: Option<String>,
    },
    /// The answer was not the expected JSON.
    #[error("unexpected answer: {0}")]
    Decode(String),
}

impl ClientError {
    /// The HTTP status, for an error answer.
    pub fn status(&self) -> Option<StatusCode> {
        match self {
            ClientError::Status { status, .. } => Some(*status),
            _ => None,
        }
    }

    /// Whether trying again later may succeed (unreachable, or a 5xx answer).
    pub fn is_transient(&self) -> bool {
        match self {
            ClientError::Unreachable(_) => true,
            ClientError::Status { status, .. } => status.is_server_error(),
            ClientError::Decode(_) => false,
        }
    }
}

/// A coordinator at a base URL, with a bearer token.
#[derive(Clone)]
pub struct Client {
    http: reqwest::Client,
    base: String,
    token: Secret,
    timeout: Duration,
    /// Whether the coordinator's reason for an empty claim was logged already.
    told: Arc<std::sync::atomic::AtomicBool>,
}

impl Client {
    /// A client for `base` (e.g. `http://127.0.0.1:8080`), sending `token` if any, whose
    /// requests time out after [`DEFAULT_REQUEST_TIMEOUT`].
    pub fn new(base: &str, token: Secret) -> Result<Client, ClientError> {
        Self::with_timeout(base, token, DEFAULT_REQUEST_TIMEOUT)
    }

    /// A client whose requests give up after `request_timeout` (counted as unreachable, so
    /// retried): how long a stalled coordinator can hold a worker's heartbeat.
    pub fn with_timeout(
        base: &str,
        token: Secret,
        request_timeout: Duration,
    ) -> Result<Client, ClientError> {
        let http = reqwest::Client::builder()
            .connect_timeout(Duration::from_secs(10).min(request_timeout))
            .timeout(request_timeout)
            .build()
            .map_err(|e| ClientError::Unreachable(e.to_string()))?;
        if !(base.starts_with("http://") || base.starts_with("https://")) {
            return Err(ClientError::Unreachable(format!(
                "the coordinator URL must start with http:// or https://, got {base:?}"
            )));
        }
        Ok(Client {
            http,
            base: base.trim_end_matches('/').to_string(),
            token,
            timeout: request_timeout,
            told: Arc::default(),
        })
    }

    /// The base URL.
    pub fn base(&self) -> &str {
        &self.base
    }

    fn url(&self, path: &str) -> String {
        format!("{}/api/v1{path}", self.base)
    }

    fn auth(&self, rb: reqwest::RequestBuilder) -> reqwest::RequestBuilder {
        match self.token.expose() {
            Some(t) => rb.bearer_auth(t),
            None => rb,
        }
    }

    /// Why a request got no answer, in words: a timeout says how long it waited.
    fn unreachable(&self, e: reqwest::Error) -> ClientError {
        ClientError::Unreachable(if e.is_timeout() {
            format!(
                "{}: no answer within {} s",
                self.base,
                self.timeout.as_secs_f64()
            )
        } else {
            format!("{}: {e}", self.base)
        })
    }

    async fn send(&self, rb: reqwest::RequestBuilder) -> Result<reqwest::Response, ClientError> {
        let resp = self
            .auth(rb)
            .send()
            .await
            .map_err(|e| self.unreachable(e))?;
        if resp.status().is_success() {
            return Ok(resp);
        }
        let status = resp.status();
        let text = resp.text().await.unwrap_or_default();
        let (message, field) = match serde_json::from_str::<ErrorBody>(&text) {
            Ok(b) => (b.error, b.field),
            Err(_) => (text, None),
        };
        Err(ClientError::Status {
            status,
            message,
            field,
        })
    }

    async fn json<T: DeserializeOwned>(resp: reqwest::Response) -> Result<T, ClientError> {
        let bytes = resp
            .bytes()
            .await
            .map_err(|e| ClientError::Unreachable(e.to_string()))?;
        serde_json::from_slice(&bytes).map_err(|e| ClientError::Decode(e.to_string()))
    }

    async fn post<B: Serialize, T: DeserializeOwned>(
        &self,
        path: &str,
        body: &B,
    ) -> Result<T, ClientError> {
        let resp = self.send(self.http.post(self.url(path)).json(body)).await?;
        Self::json(resp).await
    }

    async fn post_empty<B: Serialize>(&self, path: &str, body: &B) -> Result<(), ClientError> {
        self.send(self.http.post(self.url(path)).json(body)).await?;
        Ok(())
    }

    /// A POST of campaign spec text as it was written, so the coordinator names its fields.
    fn post_spec(&self, path: &str, spec: &str) -> reqwest::RequestBuilder {
        self.http
            .post(self.url(path))
            .header(reqwest::header::CONTENT_TYPE, "application/json")
            .body(spec.to_string())
    }

    /// Submits campaign spec text; `key` is sent as `Idempotency-Key`.
    pub async fn submit(
        &self,
        spec: &str,
        key: Option<&str>,
    ) -> Result<CampaignCreated, ClientError> {
        let mut rb = self.post_spec("/campaigns", spec);
        if let Some(k) = key {
            rb = rb.header("Idempotency-Key", k);
        }
        Self::json(self.send(rb).await?).await
    }

    /// Lists campaigns.
    pub async fn list(&self) -> Result<Vec<CampaignSummary>, ClientError> {
        Self::json(self.send(self.http.get(self.url("/campaigns"))).await?).await
    }

    /// Progress of a campaign.
    pub async fn status(&self, id: Uuid) -> Result<CampaignStatus, ClientError> {
        Self::json(
            self.send(self.http.get(self.url(&format!("/campaigns/{id}"))))
                .await?,
        )
        .await
    }

    /// Results JSON of a campaign, as the coordinator sent it.
    pub async fn results_value(
        &self,
        id: Uuid,
        raw: bool,
    ) -> Result<serde_json::Value, ClientError> {
        let url = self.url(&format!("/campaigns/{id}/results?raw={raw}"));
        Self::json(self.send(self.http.get(url)).await?).await
    }

    /// Cancels a campaign.
    pub async fn cancel(&self, id: Uuid) -> Result<JobsChanged, ClientError> {
        self.post(&format!("/campaigns/{id}/cancel"), &serde_json::json!({}))
            .await
    }

    /// Raises a campaign's `until_steady` caps to those of `spec`, its spec with higher caps.
    pub async fn raise_caps(&self, id: Uuid, spec: &str) -> Result<CapsRaised, ClientError> {
        let rb = self.post_spec(&format!("/campaigns/{id}/raise-caps"), spec);
        Self::json(self.send(rb).await?).await
    }

    /// Requeues a campaign's failed jobs.
    pub async fn retry_failed(&self, id: Uuid) -> Result<JobsChanged, ClientError> {
        self.post(
            &format!("/campaigns/{id}/retry-failed"),
            &serde_json::json!({}),
        )
        .await
    }

    /// [`Client::claim_with`] the fingerprints of grit's own scenes as this binary computes
    /// them.
    pub async fn claim(&self, worker: &str) -> Result<Option<ClaimedJob>, ClientError> {
        let engines = grit_erosion::scene::engines::<grit_erosion::Scenes>()
            .map_err(|e| ClientError::Decode(format!("engine fingerprint: {e}")))?;
        self.claim_with(worker, &WorkerEngine::PerScene(engines))
            .await
    }

    /// Leases a job of a campaign pinned to `engine`, or `None` when there is none. Why
    /// queued jobs were not leased, when the coordinator says, is logged once per client.
    pub async fn claim_with(
        &self,
        worker: &str,
        engine: &WorkerEngine,
    ) -> Result<Option<ClaimedJob>, ClientError> {
        let resp = self
            .send(
                self.http
                    .post(self.url("/worker/claim"))
                    .json(&ClaimRequest {
                        worker: worker.to_string(),
                        engine: engine.clone(),
                    }),
            )
            .await?;
        if resp.status() == StatusCode::NO_CONTENT {
            let why = resp.headers().get(crate::server::NO_JOB_HEADER);
            if let Some(why) = why.and_then(|v| v.to_str().ok()) {
                if !self.told.swap(true, std::sync::atomic::Ordering::Relaxed) {
                    tracing::warn!("no job for this worker: {why}");
                }
            }
            return Ok(None);
        }
        Self::json(resp).await.map(Some)
    }

    /// Renews a lease, delivering finished units and maybe a checkpoint.
    pub async fn heartbeat(
        &self,
        job: i64,
        req: &HeartbeatRequest,
    ) -> Result<HeartbeatResponse, ClientError> {
        self.post(&format!("/worker/jobs/{job}/heartbeat"), req)
            .await
    }

    /// Completes a job.
    pub async fn complete(&self, job: i64, req: &CompleteRequest) -> Result<(), ClientError> {
        self.post_empty(&format!("/worker/jobs/{job}/complete"), req)
            .await
    }

    /// Reports a failed attempt.
    pub async fn fail(&self, job: i64, req: &FailRequest) -> Result<(), ClientError> {
        self.post_empty(&format!("/worker/jobs/{job}/fail"), req)
            .await
    }

    /// Gives a job back.
    pub async fn release(&self, job: i64, req: &ReleaseRequest) -> Result<(), ClientError> {
        self.post_empty(&format!("/worker/jobs/{job}/release"), req)
            .await
    }
}
