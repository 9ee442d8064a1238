//! The fault text of the daemon's status: the first cause of a fault, then what followed from
//! it, kept until a person acknowledges it (hold or abort), a new walk starts, or a walk ends
//! `done`. A later effect (the adapter link going stale after an invalid sample) never replaces
//! the cause.

use core::fmt::{Display, Write};

use shm_types::{FAULT_TEXT, FixedText};

/// Separates the cause from each later effect.
const THEN: &str = "; then ";

/// The unacknowledged fault; no allocation.
pub struct FaultLog {
    text: FixedText<FAULT_TEXT>,
}

impl FaultLog {
    /// No fault.
    pub fn new() -> Self {
        Self {
            text: FixedText::EMPTY,
        }
    }

    /// Records `what`: the cause if nothing is recorded yet, else an effect appended to it.
    pub fn record(&mut self, what: impl Display) {
        // FixedText cuts at its capacity and never fails.
        if !self.text.is_empty() {
            let _ = self.text.write_str(THEN);
        }
        let _ = write!(self.text, "{what}");
    }

    /// Forgets the fault (acknowledged, or superseded by a new walk or its end).
    pub fn clear(&mut self) {
        self.text.clear();
    }

    /// The text for the status.
    pub fn text(&self) -> &FixedText<FAULT_TEXT> {
        &self.text
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_cause_comes_first_and_effects_follow() {
        let mut log = FaultLog::new();
        log.record("invalid measurement: q of KNEE is not finite");
        log.record("adapter link stale");
        assert_eq!(
            log.text().as_str(),
            "invalid measurement: q of KNEE is not finite; then adapter link stale"
        );
        log.clear();
        assert!(log.text().is_empty());
    }
}
