//! Errors of the port wrappers, each naming the service concerned.

/// Why a port could not be created or a message not be moved.
#[derive(Debug, thiserror::Error)]
pub enum ShmError {
    /// The prefix or a service name built from it is not a valid iceoryx2 service name.
    #[error("invalid service name `{name}`: {detail}")]
    InvalidServiceName {
        /// The offending name.
        name: String,
        /// What iceoryx2 objected to.
        detail: String,
    },
    /// The peer created the service with other message types: another protocol version.
    #[error(
        "service `{service}` exists with a different message layout: its peer speaks another \
         protocol version than v{ours} (restart both sides from the same build)"
    )]
    ProtocolMismatch {
        /// The service.
        service: String,
        /// Our [`crate::PROTOCOL_VERSION`].
        ours: u32,
    },
    /// A service a client needs does not exist: no daemon serves this prefix.
    #[error("no walkd serves `{service}` (is walkd running with this service prefix?)")]
    NotRunning {
        /// The missing service.
        service: String,
    },
    /// Every port of a service is taken (by other processes: iceoryx2 limits ports per
    /// service, not per process).
    #[error(
        "all {limit} {port} slots of `{service}` are taken by other processes; stop the \
         process that holds them (`walkctl` ports are released when it exits)"
    )]
    ServiceFull {
        /// The service.
        service: String,
        /// `client`, `subscriber` or `publisher`.
        port: &'static str,
        /// The service's limit.
        limit: usize,
    },
    /// The daemon did not answer in time.
    #[error("no answer on `{service}` within {timeout_ms} ms")]
    Timeout {
        /// The service asked.
        service: String,
        /// How long we waited.
        timeout_ms: u64,
    },
    /// Any other iceoryx2 failure, with the operation and the service.
    #[error("iceoryx2 failed to {operation} `{service}`: {detail}")]
    Ipc {
        /// What we tried (open, create publisher, send, ...).
        operation: &'static str,
        /// The service.
        service: String,
        /// iceoryx2's error.
        detail: String,
    },
}

impl ShmError {
    /// Wraps an iceoryx2 error value.
    pub(crate) fn ipc(
        operation: &'static str,
        service: &str,
        detail: impl core::fmt::Debug,
    ) -> Self {
        Self::Ipc {
            operation,
            service: service.to_owned(),
            detail: format!("{detail:?}"),
        }
    }
}
