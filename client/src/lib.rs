//! `walkctl` as a library: the operations on robot models, stance sequences and a running `walkd`.
//!
//! One module per subcommand; each exposes its `clap::Args` struct and a `run` function so the
//! binary only dispatches and programs can call the same operations. [`daemon_client`] is the
//! library API to a running walkd, [`process`] the one way to start and stop the system's
//! processes (walkctl, the latency report and the end-to-end tests use it).

pub mod args;
pub mod bench_coverage;
pub mod bench_postprocess;
pub mod control;
pub mod daemon_client;
pub mod demo;
pub mod evaluate;
pub mod generate;
pub mod init_robot;
pub mod inspect;
pub mod learn;
pub mod observe;
pub mod pace;
pub mod postprocess;
pub mod process;
pub mod realism;
pub mod status;
pub mod submit;
pub mod watch;
