//! The wire contract between `walkd`, its adapters and its clients (DESIGN.md §6).
//!
//! Every robot gets its own set of iceoryx2 services under a prefix (`[runtime] service_prefix`,
//! e.g. `walk/armar4`):
//!
//! | service | pattern | from → to | payload |
//! |---|---|---|---|
//! | `sensors` | publish-subscribe + event | adapter → daemon | [`SensorSample`] |
//! | `commands` | publish-subscribe + event | daemon → adapter | [`JointCommand`] |
//! | `status` | publish-subscribe | daemon → clients | [`DaemonStatus`] |
//! | `stances` | request-response | client → daemon | JSON bytes → [`SubmitReply`] |
//! | `control` | request-response | client → daemon | [`ControlRequest`] → [`ControlReply`] |
//! | `sim-truth` | publish-subscribe | simulator → clients | [`SimTruth`] |
//! | `telemetry` | publish-subscribe | daemon → observers | [`Telemetry`], one per control tick |
//!
//! Every message type is `#[repr(C)]`, `ZeroCopySend` and carries a `#[type_name]` that contains
//! the [`PROTOCOL_VERSION`]; a peer built against another protocol version is refused by iceoryx2
//! when it opens a service and the port wrappers turn that into [`ShmError::ProtocolMismatch`].
//!
//! Processes never touch iceoryx2 directly: each role has a typed port wrapper
//! ([`DaemonLoopPorts`] + [`DaemonServicePorts`], [`AdapterPorts`], [`ClientPorts`],
//! [`ObserverPorts`] for observers, and for the simulator's ground truth [`TruthPublisher`] +
//! [`TruthSubscriber`]) that opens the services with
//! the one set of QoS settings defined in [`services`].

mod clock;
pub mod config;
mod error;
mod messages;
pub mod ports;
pub mod process;
pub mod services;
mod telemetry;
mod text;
pub mod wire;

pub use ports::{
    AdapterPorts, ClientPorts, DaemonLoopPorts, DaemonServicePorts, Observed, ObserverPorts, Peer,
    Pin, PublisherId, Refusals, Roster, TruthPublisher, TruthSubscriber,
};

pub use clock::{current_thread_is_fifo, monotonic_ns, sleep_then_spin_until, sleep_until};
pub use config::{ConfigError, RuntimeBound, RuntimeConfig, RuntimeOverrides, WATCHDOG_MAX_S};
pub use error::ShmError;
pub use messages::{
    ActuatorLoad, ClockMode, CommandMode, ControlCommand, ControlReply, ControlRequest,
    DaemonState, DaemonStatus, FAULT_TEXT, HISTOGRAM_BUCKETS, JointCommand, LatencySummary,
    LinkState, LogHistogram, SensorSample, SimTruth, SubmitReply, WRENCH_ORDER,
};
pub use wire::{Code, DecodeError, Flag};

pub use services::ServiceNames;
pub use telemetry::{SUPPORT_VERTICES, Telemetry, TimingSource, WalkPhase};
pub use text::FixedText;

/// Version of the wire protocol; part of every message's `#[type_name]`. Version 2: enums and
/// flags travel as checked integers ([`wire`]); version 3: the daemon state `controlled_stop`;
/// version 4: the simulator's actuator load in [`SimTruth`]; version 5: the count of the legs'
/// terrain collisions in [`SimTruth`]; version 6: the environment's force on each palm in
/// [`SimTruth`]; version 7: the planned duration of the dynamic gait's current phase and its
/// source in [`Telemetry`]; version 8: the vertical force asked of each held hand in
/// [`Telemetry`].
pub const PROTOCOL_VERSION: u32 = 8;

/// Fixed joint capacity of the joint arrays; messages carry the used count explicitly.
pub const MAX_JOINTS: usize = 64;

/// Default of `[runtime] max_submission_bytes`: the largest post-processed sequence (JSON
/// bytes) walkd reads.
pub const MAX_SEQUENCE_BYTES: usize = 16 * 1024 * 1024;
