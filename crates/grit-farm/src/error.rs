//! The coordinator's error type and its mapping to HTTP status codes.

use axum::http::StatusCode;
use axum::response::{IntoResponse, Response};
use axum::Json;

use crate::api::ErrorBody;

/// Why a request was refused or failed.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// Well-formed JSON with a value that breaks a rule (422).
    #[error("{field}: {rule}")]
    Invalid {
        /// Path of the offending field.
        field: String,
        /// The rule broken.
        rule: String,
    },
    /// A body that is not JSON or not the expected shape (400, or the extractor's status).
    #[error("{message}")]
    BadRequest {
        /// HTTP status from the body extractor (400, 413, 415, 422).
        status: StatusCode,
        /// What was wrong.
        message: String,
    },
    /// Missing or wrong bearer token (401).
    #[error("missing or invalid bearer token")]
    Unauthorized,
    /// No such campaign or job (404).
    #[error("{0} not found")]
    NotFound(String),
    /// The caller does not hold the lease, or the state forbids the change (409).
    #[error("{0}")]
    Conflict(String),
    /// The job was cancelled; its worker should drop it (410).
    #[error("{0}")]
    Gone(String),
    /// Database failure (500, or 503 when its disk is full; details logged, not sent).
    #[error(transparent)]
    Db(#[from] sqlx::Error),
    /// Migration failure at start-up.
    #[error(transparent)]
    Migrate(#[from] sqlx::migrate::MigrateError),
    /// Anything else unexpected (500; details logged, not sent).
    #[error("{0}")]
    Internal(String),
}

/// SQLite's result code for a write that found no space left.
const SQLITE_FULL: i32 = 13;

/// Result with the coordinator's error.
pub type Result<T, E = Error> = std::result::Result<T, E>;

impl Error {
    /// A 422 naming `field` and `rule`.
    pub fn invalid(field: impl Into<String>, rule: impl Into<String>) -> Self {
        Error::Invalid {
            field: field.into(),
            rule: rule.into(),
        }
    }

    /// Whether SQLite refused a write because the database's filesystem is full
    /// (`SQLITE_FULL`, "database or disk is full"): nothing was written, and the same request
    /// succeeds once space is freed, so it is answered 503 rather than 500.
    pub fn is_disk_full(&self) -> bool {
        match self {
            Error::Db(sqlx::Error::Database(e)) => e
                .code()
                .and_then(|c| c.parse::<i32>().ok())
                // The primary result code is the low byte of an extended one.
                .is_some_and(|c| c & 0xff == SQLITE_FULL),
            _ => false,
        }
    }

    /// The HTTP status this error is answered with.
    pub fn status(&self) -> StatusCode {
        match self {
            e if e.is_disk_full() => StatusCode::SERVICE_UNAVAILABLE,
            Error::Invalid { .. } => StatusCode::UNPROCESSABLE_ENTITY,
            Error::BadRequest { status, .. } => *status,
            Error::Unauthorized => StatusCode::UNAUTHORIZED,
            Error::NotFound(_) => StatusCode::NOT_FOUND,
            Error::Conflict(_) => StatusCode::CONFLICT,
            Error::Gone(_) => StatusCode::GONE,
            Error::Db(_) | Error::Migrate(_) | Error::Internal(_) => {
                StatusCode::INTERNAL_SERVER_ERROR
            }
        }
    }
}

impl From<grit_erosion::campaign::SpecError> for Error {
    fn from(e: grit_erosion::campaign::SpecError) -> Self {
        Error::Invalid {
            field: e.field,
            rule: e.rule,
        }
    }
}

impl IntoResponse for Error {
    fn into_response(self) -> Response {
        let status = self.status();
        let body = match &self {
            e if e.is_disk_full() => {
                tracing::error!(error = %self, "the database's disk is full: free space on it; workers retry the refused writes");
                ErrorBody {
                    error: "the coordinator's database disk is full (SQLITE_FULL); nothing was stored, retry once space is freed".into(),
                    field: None,
                }
            }
            Error::Invalid { field, rule } => ErrorBody {
                error: format!("{field}: {rule}"),
                field: Some(field.clone()),
            },
            Error::Db(_) | Error::Migrate(_) | Error::Internal(_) => {
                tracing::error!(error = %self, "internal error");
                ErrorBody {
                    error: "internal error; see the coordinator log".into(),
                    field: None,
                }
            }
            other => ErrorBody {
                error: other.to_string(),
                field: None,
            },
        };
        let mut resp = (status, Json(body)).into_response();
        if status == StatusCode::UNAUTHORIZED {
            resp.headers_mut().insert(
                axum::http::header::WWW_AUTHENTICATE,
                axum::http::HeaderValue::from_static("Bearer"),
            );
        }
        resp
    }
}
