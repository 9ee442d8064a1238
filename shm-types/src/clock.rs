//! The one clock every process stamps messages with.

/// Nanoseconds on `CLOCK_MONOTONIC`, shared by all processes on the machine, so a sample's
/// timestamp taken by the adapter can be compared with the daemon's clock.
pub fn monotonic_ns() -> u64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec; CLOCK_MONOTONIC always exists on Linux.
    unsafe { libc::clock_gettime(libc::CLOCK_MONOTONIC, &mut ts) };
    ts.tv_sec as u64 * 1_000_000_000 + ts.tv_nsec as u64
}

/// Sleeps until the absolute time `deadline_ns` on [`monotonic_ns`]'s clock
/// (`clock_nanosleep(TIMER_ABSTIME)`), so periodic loops never accumulate drift. Returns at once
/// if the deadline has passed; resumes the sleep after a signal.
pub fn sleep_until(deadline_ns: u64) {
    let deadline = libc::timespec {
        tv_sec: (deadline_ns / 1_000_000_000) as libc::time_t,
        tv_nsec: (deadline_ns % 1_000_000_000) as libc::c_long,
    };
    loop {
        // SAFETY: `deadline` is a valid timespec; the remaining-time pointer may be null with
        // TIMER_ABSTIME.
        let result = unsafe {
            libc::clock_nanosleep(
                libc::CLOCK_MONOTONIC,
                libc::TIMER_ABSTIME,
                &deadline,
                core::ptr::null_mut(),
            )
        };
        if result != libc::EINTR {
            return;
        }
    }
}

/// Sleeps until `spin_ns` before `deadline_ns`, then busy-waits to the deadline. A thread that is
/// already running is not delayed by a late timer wake-up (on kernels without full preemption
/// these can be late by more than a 1 ms period); the cost is `spin_ns` of CPU per call.
pub fn sleep_then_spin_until(deadline_ns: u64, spin_ns: u64) {
    sleep_until(deadline_ns.saturating_sub(spin_ns));
    while monotonic_ns() < deadline_ns {
        core::hint::spin_loop();
    }
}

/// Whether the calling thread runs under `SCHED_FIFO`. Busy-waiting only pays off then: under
/// the normal scheduler a spinning thread takes the CPU from the process it is waiting for.
pub fn current_thread_is_fifo() -> bool {
    // SAFETY: sched_getscheduler(0) only reads the calling thread's policy.
    unsafe { libc::sched_getscheduler(0) == libc::SCHED_FIFO }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sleep_then_spin_until_returns_at_the_deadline() {
        let deadline = monotonic_ns() + 2_000_000;
        sleep_then_spin_until(deadline, 500_000);
        assert!(monotonic_ns() >= deadline);
        sleep_then_spin_until(0, 500_000); // a past deadline returns at once
    }

    #[test]
    fn sleep_until_does_not_return_early() {
        let deadline = monotonic_ns() + 2_000_000;
        sleep_until(deadline);
        assert!(monotonic_ns() >= deadline);
        sleep_until(0); // a past deadline returns at once
    }
}
