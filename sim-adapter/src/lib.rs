//! `walk-sim`: simulated robots behind the adapter side of the IPC contract.
