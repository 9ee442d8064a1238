//! The simulator's ground truth (`sim-truth`): a simulator publishes its true state, evaluation
//! clients subscribe. A hardware adapter has no such service.

use super::topic::{TopicReceiver, TopicSender};
use crate::services::{self, IpcNode};
use crate::{ServiceNames, ShmError, SimTruth};

/// The simulator's end: publishes its true state. Allocation-free after `open`.
pub struct TruthPublisher {
    sender: TopicSender<SimTruth>,
    _node: IpcNode,
}

impl TruthPublisher {
    /// Opens (or creates) `sim-truth` under `names`.
    pub fn open(names: &ServiceNames, node_name: &str) -> Result<Self, ShmError> {
        let (node, _) = services::create_node(node_name)?;
        Ok(Self {
            sender: TopicSender::open(&node, names, 2)?,
            _node: node,
        })
    }

    /// Publishes one state.
    pub fn publish(&self, truth: &SimTruth) -> Result<(), ShmError> {
        self.sender.send_copy(truth)
    }
}

/// An evaluation client's end: receives the simulator's states. It holds at most
/// [`services::SIM_TRUTH_BUFFER`] unread states (then the oldest are dropped, visible as gaps in
/// [`SimTruth::seq`]), so drain it often.
pub struct TruthSubscriber {
    receiver: TopicReceiver<SimTruth>,
    _node: IpcNode,
}

impl TruthSubscriber {
    /// Opens (or creates) `sim-truth` under `names`; states published from now on (and the
    /// newest one before) are received.
    pub fn open(names: &ServiceNames, node_name: &str) -> Result<Self, ShmError> {
        let (node, _) = services::create_node(node_name)?;
        Ok(Self {
            receiver: TopicReceiver::open(&node, names, services::SIM_TRUTH_BUFFER)?,
            _node: node,
        })
    }

    /// Passes every state received since the last call to `each`, oldest first; returns how many.
    pub fn drain(&self, each: impl FnMut(&SimTruth)) -> Result<usize, ShmError> {
        self.receiver.drain(each)
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
