//! grit-farm: the job farm of DESIGN.md. A coordinator (axum + SQLite) stores campaigns and
//! leases their jobs to workers over a REST API; workers run the impacts with grit-erosion
//! and report them by heartbeat with periodic checkpoints; `grit run` does it all in one
//! process. Depends on grit-erosion for the campaign spec, samples and aggregation.
#![warn(missing_docs)]

pub mod api;
pub mod bench;
pub mod cli;
pub mod client;
pub mod dashboard;
pub mod db;
pub mod embedded;
pub mod error;
pub mod server;
pub mod studies;
pub mod worker;

pub use client::{Client, ClientError};
pub use db::Store;
pub use error::{Error, Result};
pub use server::{app, AppState, Config, Secret};
