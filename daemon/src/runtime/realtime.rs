//! Real-time process and thread settings; each degrades to a warning when not permitted.

/// Locks memory so page faults cannot stall the control loop: everything mapped now is faulted
/// in and locked (`MCL_CURRENT`), and every page mapped later is locked once it is first
/// touched (`MCL_FUTURE | MCL_ONFAULT`). Touched-on-fault rather than all at once, so a large
/// reservation (a thread stack, a shared-memory segment sized for the largest submission)
/// locks only what is used; [`release_free_memory`] returns what a finished walk freed.
pub fn lock_memory() {
    // SAFETY: mlockall has no memory-safety preconditions.
    let locked = unsafe {
        libc::mlockall(libc::MCL_CURRENT) == 0
            && libc::mlockall(libc::MCL_CURRENT | libc::MCL_FUTURE | libc::MCL_ONFAULT) == 0
    };
    if locked {
        tracing::info!("memory locked (mlockall: current, future on fault)");
    } else {
        tracing::warn!(
            error = %std::io::Error::last_os_error(),
            "mlockall not permitted: memory stays pageable (raise RLIMIT_MEMLOCK or grant CAP_IPC_LOCK)"
        );
    }
}

/// Hands memory the allocator keeps after frees (a parsed submission, a finished walk) back to
/// the operating system, so walkd's resident and locked memory shrink again. Service thread
/// only: it may take the allocator's locks.
pub fn release_free_memory() {
    // SAFETY: malloc_trim only releases free heap memory; it has no preconditions.
    unsafe { libc::malloc_trim(0) };
}

/// Gives the calling thread SCHED_FIFO at `priority`; returns whether it was granted.
pub fn set_fifo_priority(priority: i32) -> bool {
    let param = libc::sched_param {
        sched_priority: priority,
    };
    // SAFETY: `param` is a valid sched_param for the calling thread.
    let result =
        unsafe { libc::pthread_setschedparam(libc::pthread_self(), libc::SCHED_FIFO, &param) };
    if result != 0 {
        tracing::warn!(
            priority,
            error = %std::io::Error::from_raw_os_error(result),
            "SCHED_FIFO not permitted: the control thread keeps normal scheduling (grant CAP_SYS_NICE or an RLIMIT_RTPRIO)"
        );
        false
    } else {
        tracing::info!(priority, "control thread runs SCHED_FIFO");
        true
    }
}

/// Pins the calling thread to `cpu`.
pub fn pin_to_cpu(cpu: usize) {
    // SAFETY: a zeroed cpu_set_t is a valid empty set; CPU_SET stays inside it for cpu <
    // CPU_SETSIZE, which is checked first.
    let result = unsafe {
        let mut set: libc::cpu_set_t = std::mem::zeroed();
        if cpu >= libc::CPU_SETSIZE as usize {
            -1
        } else {
            libc::CPU_SET(cpu, &mut set);
            libc::sched_setaffinity(0, std::mem::size_of::<libc::cpu_set_t>(), &set)
        }
    };
    if result != 0 {
        tracing::warn!(
            cpu,
            error = %std::io::Error::last_os_error(),
            "CPU affinity not applied: the control thread may migrate between CPUs"
        );
    } else {
        tracing::info!(cpu, "control thread pinned");
    }
}

/// Sets the calling thread's timer slack to 1 ns, so its `clock_nanosleep` wake-ups are not
/// deferred by the default 50 µs slack that normal (non-real-time) threads get.
pub fn minimize_timer_slack() {
    // SAFETY: PR_SET_TIMERSLACK takes an integer argument and has no memory-safety
    // preconditions; it only affects the calling thread.
    if unsafe { libc::prctl(libc::PR_SET_TIMERSLACK, 1 as libc::c_ulong) } != 0 {
        tracing::warn!(
            error = %std::io::Error::last_os_error(),
            "timer slack not reduced: wake-ups may come up to 50 µs late"
        );
    }
}
