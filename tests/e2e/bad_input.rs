//! Bad input to the processes themselves: a recording onto a full disk, and numbers outside
//! their documented ranges in a config file or on a command line. Each ends in a clear error
//! naming the file and key (or the flag) and the documented exit code, never in a panic, an
//! abort or a process that cannot be stopped.

use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use client::process::Process;
use walk_tests::{bin_dir, config, start_connected, unique_prefix};

/// A copy of `configs/<robot>.toml` (its URDF path made absolute) with each `key = ...` line
/// of `replacements` replaced by `key = value`; the copy is removed when the guard drops.
struct ConfigCopy(PathBuf);

impl ConfigCopy {
    fn new(robot: &str, test: &str, replacements: &[(&str, &str)]) -> Self {
        let original = config(robot);
        let configs = original.parent().unwrap().canonicalize().unwrap();
        let mut text = std::fs::read_to_string(&original).unwrap().replace(
            "urdf = \"robots/",
            &format!("urdf = \"{}/robots/", configs.display()),
        );
        for (key, value) in replacements {
            let line = text
                .lines()
                .find(|line| line.starts_with(&format!("{key} =")))
                .unwrap_or_else(|| panic!("{key} is not in {}", original.display()))
                .to_owned();
            text = text.replace(&line, &format!("{key} = {value}"));
        }
        let path = std::env::temp_dir().join(format!(
            "walk-e2e-{}-{test}-{robot}.toml",
            std::process::id()
        ));
        std::fs::write(&path, text).unwrap();
        Self(path)
    }

    fn path(&self) -> &Path {
        &self.0
    }
}

impl Drop for ConfigCopy {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

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

/// The command line of a kinematic walk-sim for JVRC-1 on a prefix of its own, with `arg`.
fn walk_sim_args(arg: &str) -> Vec<String> {
    let config = config("jvrc1");
    let prefix = unique_prefix("walk-sim");
    [
        "--config",
        config.to_str().unwrap(),
        "--physics",
        "kinematic",
        "--service-prefix",
    ]
    .into_iter()
    .chain([prefix.as_str(), arg])
    .map(str::to_owned)
    .collect()
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

/// A status rate of 1e-300 Hz (a status every 1e300 s) is refused at load, naming the file and
/// the key: exit 3 (config), not a panic (exit 101).
#[test]
fn walkd_refuses_a_vanishing_status_rate_naming_the_file_and_key() {
    let copy = ConfigCopy::new("jvrc1", "status-rate", &[("status_rate_hz", "1e-300")]);
    let prefix = unique_prefix("status-rate");
    let args = [
        "--config",
        copy.path().to_str().unwrap(),
        "--service-prefix",
        &prefix,
        "--no-lock-memory",
    ];
    let (code, log) = run_to_exit("walkd", &args, Duration::from_secs(10));
    assert_eq!(code, Some(3), "{log}");
    assert!(
        log.contains(&copy.path().display().to_string())
            && log.contains("[runtime]")
            && log.contains("status_rate_hz"),
        "{log}"
    );
}

/// walk-sim's `--rate-hz` is checked like `[runtime] rate_hz`: 1e12 Hz (a period of 0 ns) and
/// 1e-3 Hz (a period of 1000 s, slept through SIGTERM) are refused at once, naming the flag:
/// exit 2 (usage), no panic.
#[test]
fn walk_sim_refuses_rates_outside_the_range_naming_the_flag() {
    for rate in ["1e12", "1e-3", "NaN", "-500"] {
        let args = walk_sim_args(&format!("--rate-hz={rate}"));
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let (code, log) = run_to_exit("walk-sim", &args, Duration::from_secs(10));
        assert_eq!(code, Some(2), "--rate-hz {rate}: {log}");
        assert!(
            log.contains("--rate-hz") && !log.contains("panicked"),
            "--rate-hz {rate}: {log}"
        );
    }
}

/// walk-sim's numbers, fuzzed on the binary itself (its arguments live in it): every value
/// either starts it, and then SIGTERM ends it within a second, or is refused at once naming the
/// flag (exit 2). Never a panic, never a process that runs on.
#[test]
fn walk_sim_takes_every_number_in_range_or_refuses_it_by_flag() {
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    let mut random = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    let (mut tried, mut started) = (0, 0);
    for flag in ["--rate-hz", "--snapshot-period", "--snapshot-lookat"] {
        let mut values: Vec<String> = [
            "0",
            "-1",
            "1e-300",
            "1e300",
            "NaN",
            "inf",
            "-inf",
            "4294967296",
            "1e400",
            "fast",
            "10",
            "500",
            "0.5",
            "10000",
        ]
        .map(str::to_owned)
        .to_vec();
        values.extend((0..6).map(|_| {
            let exponent = (random() % 16) as i32 - 8;
            format!("{:?}", (1 + random() % 9) as f64 * 10f64.powi(exponent))
        }));
        for value in values {
            tried += 1;
            let value = if flag == "--snapshot-lookat" {
                format!("0,{value},0.8")
            } else {
                value
            };
            let arg = format!("{flag}={value}");
            let args = walk_sim_args(&arg);
            let process = Process::start(&bin_dir().join("walk-sim"), args, &[]).unwrap();
            let start = Instant::now();
            while process.is_running()
                && !process.log_text().contains("walk-sim running")
                && start.elapsed() < Duration::from_secs(5)
            {
                std::thread::sleep(Duration::from_millis(5));
            }
            if process.is_running() {
                started += 1;
                process.signal(libc::SIGTERM);
                let exit = process.wait_exit(Duration::from_secs(1));
                assert_eq!(
                    exit.and_then(|s| s.code()),
                    Some(0),
                    "{arg}: {}",
                    process.log()
                );
            } else {
                let exit = process.wait_exit(Duration::from_secs(5));
                let log = process.log();
                assert_eq!(exit.and_then(|s| s.code()), Some(2), "{arg}: {log}");
                assert!(
                    log.contains(flag) && !log.contains("panicked"),
                    "{arg}: {log}"
                );
            }
        }
    }
    eprintln!("walk-sim: {tried} values tried, {started} started and stopped at SIGTERM, 0 panics");
}
