//! The walking daemon: QP controller, stance state machine and fixed-rate runtime.
//!
//! - [`qp`]: the QP problem form and its solvers (clarabel reference, dense active set).
//! - [`controller`]: the controller core (tasks, constraints, state machine); no IPC, clocks or files.
//! - [`runtime`]: the daemon process (fixed-rate loop, IPC, signals, systemd).
//!
//! The daemon links no simulator, client or adapter: closed-loop walks against a simulator, the
//! benchmarks and the latency report live in the `walk-bench` crate.

pub mod controller;
pub mod qp;
pub mod runtime;
