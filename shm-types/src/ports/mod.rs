//! Typed port wrappers, one per role. Each owns its own iceoryx2 node, so a process can give
//! each of its threads the ports it needs (iceoryx2 `ipc` ports are not shared between threads).

mod adapter;
mod client;
mod daemon;
mod observer;
mod stream;
mod topic;
mod trust;
mod truth;

pub use adapter::AdapterPorts;
pub use client::ClientPorts;
pub use daemon::{DaemonLoopPorts, DaemonServicePorts};
pub use observer::{Observed, ObserverPorts};
pub use trust::{Admission, Peer, Pin, PublisherId, Refusals, Roster, Taken};
pub use truth::{TruthPublisher, TruthSubscriber};
