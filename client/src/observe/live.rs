//! The live sink of `walkctl view`: the Foxglove SDK's WebSocket server (Foxglove WebSocket
//! protocol) on the observer's context. Each connected client is a sink of its own and gets the
//! channels it subscribes to.

use std::sync::Arc;

use anyhow::Context as _;
use foxglove::{Context, WebSocketServerHandle};

/// A running WebSocket server.
pub struct LiveView {
    handle: WebSocketServerHandle,
}

impl LiveView {
    /// Serves `context`'s channels on `host:port` (port 0: any free port).
    pub fn serve(context: &Arc<Context>, host: &str, port: u16) -> anyhow::Result<Self> {
        let handle = context
            .websocket_server()
            .name("walkd observer")
            .bind(host, port)
            .start_blocking()
            .with_context(|| format!("starting the Foxglove WebSocket server on {host}:{port}"))?;
        Ok(Self { handle })
    }

    /// The port the server listens on.
    pub fn port(&self) -> u16 {
        self.handle.port()
    }

    /// Clients connected now.
    pub fn clients(&self) -> usize {
        self.handle.client_count()
    }

    /// Disconnects the clients and stops the server.
    pub fn stop(self) {
        self.handle.stop().wait_blocking();
    }
}
