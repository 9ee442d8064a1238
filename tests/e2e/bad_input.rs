//! Bad input to the processes themselves: a recording onto a full disk, and numbers outside
//! their documented ranges in a config file or on a command line. Each ends in a clear error
//! naming the file and key (or the flag) and the documented exit code, never in a panic, an
//! abort or a process that cannot be stopped.

use std::time::{Duration, Instant};

use client::process::Process;
use walk_tests::{bin_dir, config, start_connected, unique_prefix};

/// Starts `binary` of the workspace with `args` and waits up to `timeout` for it to exit on its
/// own; a process still running then is stopped with SIGTERM (and the test fails).
fn run_to_exit(binary: &str, args: &[&str], timeout: Duration) -> (Option<i32>, String) {
    let process = Process::start(&bin_dir().join(binary), args, &[]).unwrap();
    let status = process.wait_exit(timeout);
    if status.is_none() {
        process.signal(libc::SIGTERM);
        let stopped = process.wait_exit(Duration::from_secs(2)).is_some();
        panic!(
            "{binary} {} still ran after {timeout:?} (it {} SIGTERM)\n{}",
            args.join(" "),
            if stopped { "ended at" } else { "ignored" },
            process.log()
        );
    }
    (status.unwrap().code(), process.log_text())
}

/// `walkctl record` onto a full disk (`/dev/full` answers every write with ENOSPC) stops at the
/// first failed write, well before its duration, and says which file and why: exit 1, no panic.
#[test]
fn record_onto_a_full_disk_stops_and_names_the_file_and_the_os_error() {
    let prefix = unique_prefix("record-full");
    let (_walkd, _sim, _client) = start_connected("jvrc1", &prefix, "realtime").unwrap();
    let config = config("jvrc1");
    let args = [
        "record",
        "--config",
        config.to_str().unwrap(),
        "--service-prefix",
        &prefix,
        "-o",
        "/dev/full",
        "--duration",
        "30",
    ];
    let start = Instant::now();
    let (code, log) = run_to_exit("walkctl", &args, Duration::from_secs(20));
    let elapsed = start.elapsed();
    assert_eq!(code, Some(1), "{log}");
    assert!(!log.contains("panicked"), "{log}");
    assert!(
        log.contains("writing /dev/full: No space left on device (os error 28)"),
        "{log}"
    );
    assert!(
        elapsed < Duration::from_secs(10),
        "the recording ran on for {elapsed:?} after its file failed\n{log}"
    );
}
