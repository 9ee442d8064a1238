//! The simulator's ground truth (`sim-truth`): a simulator publishes its true state, evaluation
//! clients subscribe. A hardware adapter has no such service.

use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::*;

use crate::services::{self, IpcNode, PubSub, SIM_TRUTH};
use crate::{ServiceNames, ShmError, SimTruth};

/// The simulator's end: publishes its true state. Allocation-free after `open`.
pub struct TruthPublisher {
    service_name: String,
    publisher: Publisher<ipc::Service, SimTruth, ()>,
    _service: PubSub<SimTruth>,
    _node: IpcNode,
}

impl TruthPublisher {
    /// Opens (or creates) `sim-truth` under `names`.
    pub fn open(names: &ServiceNames, node_name: &str) -> Result<Self, ShmError> {
        let (node, _) = services::create_node(node_name)?;
        let service_name = names.full(SIM_TRUTH);
        let service = services::sim_truth(&node, names)?;
        let publisher = service
            .publisher_builder()
            .create()
            .map_err(|e| ShmError::ipc("create publisher on", &service_name, e))?;
        Ok(Self {
            service_name,
            publisher,
            _service: service,
            _node: node,
        })
    }

    /// Publishes one state.
    pub fn publish(&self, truth: &SimTruth) -> Result<(), ShmError> {
        self.publisher
            .send_copy(*truth)
            .map(|_| ())
            .map_err(|e| ShmError::ipc("send on", &self.service_name, e))
    }
}

/// An evaluation client's end: receives the simulator's states. It holds at most
/// [`services::SIM_TRUTH_BUFFER`] unread states (then the oldest are dropped, visible as gaps in
/// [`SimTruth::seq`]), so drain it often.
pub struct TruthSubscriber {
    service_name: String,
    subscriber: Subscriber<ipc::Service, SimTruth, ()>,
    _service: PubSub<SimTruth>,
    _node: IpcNode,
}

impl TruthSubscriber {
    /// Opens (or creates) `sim-truth` under `names`; states published from now on (and the
    /// newest one before) are received.
    pub fn open(names: &ServiceNames, node_name: &str) -> Result<Self, ShmError> {
        let (node, _) = services::create_node(node_name)?;
        let service_name = names.full(SIM_TRUTH);
        let service = services::sim_truth(&node, names)?;
        let subscriber = service
            .subscriber_builder()
            .create()
            .map_err(|e| ShmError::ipc("create subscriber on", &service_name, e))?;
        Ok(Self {
            service_name,
            subscriber,
            _service: service,
            _node: node,
        })
    }

    /// Passes every state received since the last call to `each`, oldest first; returns how many.
    pub fn drain(&self, mut each: impl FnMut(&SimTruth)) -> Result<usize, ShmError> {
        let mut count = 0;
        while let Some(sample) = self
            .subscriber
            .receive()
            .map_err(|e| ShmError::ipc("receive from", &self.service_name, e))?
        {
            each(sample.payload());
            count += 1;
        }
        Ok(count)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::services::SIM_TRUTH_BUFFER;

    fn state(seq: u64) -> SimTruth {
        SimTruth {
            seq,
            sim_time_s: seq as f64 * 0.002,
            com: [seq as f64, 0.0, 0.8],
            ..SimTruth::ZERO
        }
    }

    fn drain_seqs(subscriber: &TruthSubscriber) -> Vec<u64> {
        let mut seqs = Vec::new();
        subscriber.drain(|truth| seqs.push(truth.seq)).unwrap();
        seqs
    }

    #[test]
    fn states_arrive_in_order_and_overflow_drops_the_oldest() {
        let prefix = format!("walk-test/shm-types/truth/{}", std::process::id());
        let names = ServiceNames::new(&prefix).unwrap();
        // The subscriber may come first: both sides open or create the service.
        let subscriber = TruthSubscriber::open(&names, "evaluator").unwrap();
        let publisher = TruthPublisher::open(&names, "simulator").unwrap();
        for seq in 1..=3 {
            publisher.publish(&state(seq)).unwrap();
        }
        let mut received = Vec::new();
        assert_eq!(subscriber.drain(|truth| received.push(*truth)).unwrap(), 3);
        assert_eq!(received, [state(1), state(2), state(3)]);
        assert!(drain_seqs(&subscriber).is_empty());

        let extra = 10;
        let last = 3 + (SIM_TRUTH_BUFFER + extra) as u64;
        for seq in 4..=last {
            publisher.publish(&state(seq)).unwrap();
        }
        let seqs = drain_seqs(&subscriber);
        assert_eq!(seqs.len(), SIM_TRUTH_BUFFER);
        assert_eq!(seqs.first(), Some(&(4 + extra as u64)));
        assert_eq!(seqs.last(), Some(&last));
    }
}
