//! The walking daemon: QP controller, stance state machine and fixed-rate runtime.
//!
//! - [`qp`]: the QP problem form and its solvers (clarabel reference, dense active set).
//! - [`controller`]: the controller core (tasks, constraints, state machine); no IPC, clocks or files.
//! - [`bench`]: `walkd bench`, an in-process walk against the kinematic simulator.
//! - [`runtime`]: the daemon process (fixed-rate loop, IPC, signals, systemd).

pub mod bench;
pub mod controller;
pub mod qp;
pub mod runtime;
