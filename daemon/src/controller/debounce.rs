//! A contact change confirmed once force-torque has shown it for a set time, so the
//! confirmation takes as long at 1 kHz as at 500 Hz.

/// Rounding allowed when a hold made of whole ticks is compared with its configured time (s).
const HOLD_ROUNDING_S: f64 = 1e-9;

/// How long a condition has held without a break.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Debounce {
    held_s: f64,
}

impl Debounce {
    /// One tick of `dt` (s) with or without `condition`: true once it has held for `hold_s`.
    pub fn update(&mut self, condition: bool, dt: f64, hold_s: f64) -> bool {
        self.held_s = if condition { self.held_s + dt } else { 0.0 };
        condition && self.held_s >= hold_s - HOLD_ROUNDING_S
    }

    /// Starts over: a new phase counts its own hold.
    pub fn reset(&mut self) {
        self.held_s = 0.0;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Ticks of `dt` until a condition held throughout is confirmed.
    fn ticks_to_confirm(dt: f64, hold_s: f64) -> u32 {
        let mut debounce = Debounce::default();
        (1..1000)
            .find(|_| debounce.update(true, dt, hold_s))
            .expect("confirmed")
    }

    #[test]
    fn the_hold_is_a_time_not_a_count_of_ticks() {
        assert_eq!(ticks_to_confirm(0.002, 0.006), 3);
        assert_eq!(ticks_to_confirm(0.001, 0.006), 6);
        assert_eq!(ticks_to_confirm(0.002, 0.0), 1);
    }

    #[test]
    fn a_break_or_a_reset_starts_the_hold_over() {
        let mut debounce = Debounce::default();
        assert!(!debounce.update(true, 0.002, 0.006));
        assert!(!debounce.update(true, 0.002, 0.006));
        assert!(!debounce.update(false, 0.002, 0.006));
        assert!(!debounce.update(true, 0.002, 0.006));
        assert!(!debounce.update(true, 0.002, 0.006));
        debounce.reset();
        assert!(!debounce.update(true, 0.002, 0.006));
        assert!(!debounce.update(true, 0.002, 0.006));
        assert!(debounce.update(true, 0.002, 0.006));
    }
}
