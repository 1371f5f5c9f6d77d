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
    /// Database failure (500, or 503 when its disk refused the write; details logged, not sent).
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
/// SQLite's extended result code for a write the filesystem refused for any other reason than
/// `ENOSPC`: over a disk quota (`EDQUOT`, the usual "full disk" of a shared cluster), over the
/// process's file-size limit (`EFBIG`), or an I/O error.
const SQLITE_IOERR_WRITE: i32 = 778;

/// Why the database refused a write that succeeds unchanged once the disk takes writes again.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WriteRefused {
    /// `SQLITE_FULL`: no space left on the filesystem.
    Full,
    /// `SQLITE_IOERR_WRITE`: a quota, a file-size limit or a disk error.
    IoErrWrite,
}

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

    /// Whether SQLite refused a write because the database's filesystem would not take it
    /// (full, over a quota or a file-size limit), and how: nothing was written, and the same
    /// request succeeds once the disk takes writes again, so it is answered 503 rather than
    /// 500 and workers retry it.
    pub fn write_refused(&self) -> Option<WriteRefused> {
        let Error::Db(sqlx::Error::Database(e)) = self else {
            return None;
        };
        let code = e.code().and_then(|c| c.parse::<i32>().ok())?;
        if code == SQLITE_IOERR_WRITE {
            Some(WriteRefused::IoErrWrite)
        } else if code & 0xff == SQLITE_FULL {
            // The primary result code is the low byte of an extended one.
            Some(WriteRefused::Full)
        } else {
            None
        }
    }

    /// Whether SQLite refused a write because the database's filesystem is full
    /// (`SQLITE_FULL`, "database or disk is full").
    pub fn is_disk_full(&self) -> bool {
        self.write_refused() == Some(WriteRefused::Full)
    }

    /// The HTTP status this error is answered with.
    pub fn status(&self) -> StatusCode {
        match self {
            e if e.write_refused().is_some() => StatusCode::SERVICE_UNAVAILABLE,
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
            e if e.write_refused().is_some() => {
                tracing::error!(error = %self, "the database's disk refused the write: raise the quota or file-size limit, free space, or check the disk; workers retry the refused writes");
                ErrorBody {
                    error: "the coordinator's database disk refused the write (SQLITE_IOERR_WRITE: over a quota or file-size limit, or a disk error); nothing was stored, retry once it takes writes".into(),
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
