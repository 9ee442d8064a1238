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
    /// The fault `walk-sim --inject` injects to evaluate walkd's controlled stop, named the same by
    /// `walkctl evaluate --inject` (`sim_adapter::inject`).
    pub enum InjectedFault {
        /// One sample with a NaN joint angle.
        Nan = 0 => "nan",
        /// One sample with a joint 0.2 rad beyond its upper limit.
        JointOutOfLimits = 1 => "joint-out-of-limits",
        /// One sample in which every force-torque sensor reads zero (not a fault walkd can tell
        /// from a sole bouncing off the ground: the walk goes on).
        ZeroForce = 2 => "zero-force",
        /// walkd is asked to hold.
        Hold = 3 => "hold",
        /// walkd is asked to abort.
        Abort = 4 => "abort",
        /// The foot in the air never reports contact again: its wrench reads zero from then on.
        WithheldTouchdown = 5 => "withheld-touchdown",
        /// Every force-torque sensor reads zero for 0.1 s (a sensor dropout).
        ForceDropout = 6 => "force-dropout",
    }
}

impl InjectedFault {
    /// Every kind, in the order the evaluation tries them.
    pub const ALL: [InjectedFault; 7] = [
        Self::Nan,
        Self::JointOutOfLimits,
        Self::ZeroForce,
        Self::ForceDropout,
        Self::Hold,
        Self::Abort,
        Self::WithheldTouchdown,
    ];

    /// Whether walkd must end the walk for it (all but a single zero-force sample, which
    /// physics can produce too).
    pub fn must_stop(self) -> bool {
        self != Self::ZeroForce
    }
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
