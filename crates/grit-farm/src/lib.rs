//! grit-farm: the job farm (docs/design.md). A coordinator (axum + SQLite) stores campaigns and
//! leases their jobs to workers over a REST API; workers run the impacts with grit-erosion
//! and report them by heartbeat with periodic checkpoints; the embedded mode (`grit run`) does
//! it all in one process; the load test (`grit bench farm`) measures the coordinator alone.
//! Depends on grit-erosion for the campaign spec, samples and aggregation. The command line
//! lives in the `grit` binary.
#![warn(missing_docs)]

pub mod api;
pub mod checkpoint;
pub mod client;
pub mod dashboard;
pub mod db;
pub mod embedded;
pub mod error;
pub mod loadtest;
pub mod scenes;
pub mod server;
pub mod worker;

pub use client::{Client, ClientError};
pub use db::{OwnEngine, Store, Synchronous};
pub use error::{Error, Result};
pub use server::{app, AppState, Config, Secret};
