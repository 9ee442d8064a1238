//! What every process of the system does the same way: exit codes, termination requests, and
//! the names of the simulators `walk-sim` runs (so the clients that start it pass the same).

use std::sync::atomic::{AtomicBool, Ordering};

use crate::wire::wire_enum;

/// Exit codes shared by `walkd` and the adapters (documented in docs/ipc.md).
pub mod exit_code {
    /// Clean shutdown (also after SIGTERM / SIGINT).
    pub const OK: u8 = 0;
    /// A runtime failure not covered below.
    pub const FAILURE: u8 = 1;
    /// Bad command line (clap's own code).
    pub const USAGE: u8 = 2;
    /// The config file or the robot model could not be loaded.
    pub const CONFIG: u8 = 3;
    /// iceoryx2 services could not be created or opened (e.g. protocol mismatch).
    pub const IPC: u8 = 4;
    /// The control loop could not start (controller construction failed).
    pub const CONTROLLER: u8 = 5;
}

static TERMINATION_REQUESTED: AtomicBool = AtomicBool::new(false);

extern "C" fn on_termination_signal(_: libc::c_int) {
    TERMINATION_REQUESTED.store(true, Ordering::SeqCst);
}

/// Installs SIGTERM and SIGINT handlers that only set a flag, read with
/// [`termination_requested`]. Loops poll it at least every few tens of milliseconds.
pub fn install_termination_handler() {
    for signal in [libc::SIGTERM, libc::SIGINT] {
        // SAFETY: the handler only stores to an atomic, which is async-signal-safe.
        unsafe {
            libc::signal(
                signal,
                on_termination_signal as extern "C" fn(libc::c_int) as libc::sighandler_t,
            );
        }
    }
}

/// Whether SIGTERM or SIGINT arrived since [`install_termination_handler`].
pub fn termination_requested() -> bool {
    TERMINATION_REQUESTED.load(Ordering::SeqCst)
}

wire_enum! {
    /// The simulator behind `walk-sim --physics`, named the same by every process that starts it.
    pub enum Physics {
        /// The deterministic kinematic simulator (ideal servos, feet anchored in contact).
        Kinematic = 0 => "kinematic",
        /// MuJoCo rigid-body dynamics with contacts (walk-sim built with the `mujoco` feature).
        Mujoco = 1 => "mujoco",
    }
}
