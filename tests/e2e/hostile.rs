//! Hostile peers against a real walkd: a local process that writes raw message bytes to walkd's
//! services (`walk_tests::hostile`), an adapter that lies about time, joints or orientation, a
//! client that floods or hogs the services. walkd must refuse or fault with the reason, keep
//! running, and never command a joint outside its limits.

use std::mem::offset_of;
use std::time::{Duration, Instant};

use client::daemon_client::DaemonClient;
use client::process::Process;
use kinematics::robot::Robot;
use shm_types::{
    Code, CommandMode, ControlCommand, DaemonState, JointCommand, LinkState, SensorSample,
    Telemetry,
};
use walk_tests::hostile::{
    Feeder, MonitorHog, PortHog, Raw, RawAdapter, RawClient, RawDaemon, RawPublisher, Tap,
    command_answers, command_q, standing_sample,
};
use walk_tests::{
    assert_terminates, config, start_connected, start_sim, start_walkd, start_walking,
    unique_prefix, wait_for_status, wait_until, walk_json,
};

const START: Duration = Duration::from_secs(20);
const PERIOD: Duration = Duration::from_millis(2);
const REPLY: Duration = Duration::from_secs(5);

fn robot(name: &str) -> Robot {
    Robot::load(&config(name), None).unwrap()
}

/// Every command inside the joint limits (no tolerance: limits are hard).
fn assert_within_limits(robot: &Robot, commands: &[Raw<shm_types::JointCommand>]) {
    let limits = robot.model.joint_limits();
    let names = robot.model.joint_names();
    for command in commands {
        for (j, q) in command_q(command, limits.len()).iter().enumerate() {
            assert!(
                q.is_finite() && *q >= limits[j].lower && *q <= limits[j].upper,
                "command for {} = {q} outside [{}, {}]",
                names[j],
                limits[j].lower,
                limits[j].upper
            );
        }
    }
}

/// Item 1: a control request whose command field holds no known command, and a sample whose
/// flag bytes hold neither 0 nor 1, are refused with their reason; walkd lives on.
#[test]
fn unknown_enum_and_flag_values_are_refused_and_walkd_lives() {
    let prefix = unique_prefix("hostile_wire");
    let walkd = start_walkd("armar4", &prefix, "realtime", 500.0).unwrap();
    let robot = robot("armar4");
    let mut adapter = RawAdapter::open_when_ready(&prefix, START).unwrap();
    let standing = standing_sample(&robot);
    adapter.stream(&standing, PERIOD, Duration::from_millis(200));
    let raw = RawClient::connect(&prefix).unwrap();
    for value in [257u32, 0x8000_0000, 3] {
        let (accepted, message) = raw
            .control(value, REPLY)
            .unwrap_or_else(|e| panic!("command {value}: {e}\n{}", walkd.log()));
        assert!(!accepted, "command {value} was carried out: {message}");
        assert!(message.contains(&value.to_string()), "{message}");
        assert!(
            walkd.is_running(),
            "walkd died on command {value}\n{}",
            walkd.log()
        );
    }

    // has_imu = 2 with an IMU lying on its side: the sample is invalid, not "no IMU".
    let imu = offset_of!(SensorSample, imu_orientation);
    let half = std::f64::consts::FRAC_1_SQRT_2;
    for _ in 0..20 {
        adapter.publish(&standing, |raw| {
            raw.put::<u8>(offset_of!(SensorSample, has_imu), 2);
            raw.put::<[f64; 4]>(imu, [half, 0.0, 0.0, half]);
        });
        std::thread::sleep(PERIOD);
    }
    let client = walk_tests::connect(&prefix).unwrap();
    let status = wait_for_status(&client, "a fault", REPLY, |s| s.state == DaemonState::Fault)
        .unwrap_or_else(|e| panic!("{e}\n{}", walkd.log()));
    assert!(status.fault.as_str().contains("has_imu"), "{status:?}");
    assert!(walkd.is_running(), "{}", walkd.log());
}

/// Item 2: a sample stamped far in the future is refused and counted; the control thread does
/// not wait for that time, answers hold at once, and SIGTERM ends it within a second.
#[test]
fn a_sample_stamped_in_the_future_does_not_freeze_the_control_thread() {
    let prefix = unique_prefix("hostile_future");
    let walkd = start_walkd("armar4", &prefix, "realtime", 500.0).unwrap();
    let robot = robot("armar4");
    let mut adapter = RawAdapter::open_when_ready(&prefix, START).unwrap();
    let standing = standing_sample(&robot);
    let answered = adapter.stream(&standing, PERIOD, Duration::from_millis(300));
    assert!(
        !answered.is_empty(),
        "no command before the test\n{}",
        walkd.log()
    );

    for future in [20_000_000_000u64, u64::MAX / 2, u64::MAX] {
        adapter.publish(&standing, |raw| {
            let now = shm_types::monotonic_ns();
            raw.put(
                offset_of!(SensorSample, timestamp_ns),
                now.saturating_add(future),
            );
        });
        std::thread::sleep(PERIOD);
        // Ordinary samples again: each must be answered within a few periods.
        let commands = adapter.stream(&standing, PERIOD, Duration::from_millis(300));
        assert!(
            commands.len() > 50,
            "only {} commands in 300 ms after a sample stamped +{future} ns\n{}",
            commands.len(),
            walkd.log()
        );
    }
    // The link is read while ordinary samples still flow: once they stop, it goes stale within
    // the watchdog time (20 ms), sooner than a loaded machine may connect a client.
    let status = std::thread::scope(|scope| {
        let reader = scope.spawn(|| {
            let client = walk_tests::connect(&prefix).unwrap();
            std::thread::sleep(Duration::from_millis(100));
            client.status().unwrap()
        });
        while !reader.is_finished() {
            adapter.stream(&standing, PERIOD, Duration::from_millis(100));
        }
        reader.join().unwrap()
    });
    assert_eq!(status.link, LinkState::Fresh, "{status:?}");
    let client = walk_tests::connect(&prefix).unwrap();
    let json = client::daemon_client::status_json(&status);
    assert!(json["rejected_samples"].as_u64() >= Some(3), "{json}");
    assert!(status.stale_periods < 1_000_000, "{status:?}");
    let started = Instant::now();
    client.control(shm_types::ControlCommand::Hold).unwrap();
    assert!(started.elapsed() < Duration::from_secs(1));
    assert_terminates(&walkd, Duration::from_secs(1));
}

/// Item 3: joints measured outside their limits are a fault naming the joint; no walk starts,
/// and no command, hold included, leaves the limits. Before any valid measurement there is no
/// safe posture at all and walkd commands nothing (the adapter holds on its own).
#[test]
fn joints_measured_outside_their_limits_fault_and_commands_stay_inside() {
    let prefix = unique_prefix("hostile_limits");
    let walkd = start_walkd("armar4", &prefix, "realtime", 500.0).unwrap();
    let robot = robot("armar4");
    let dof = robot.model.dof();
    let mut adapter = RawAdapter::open_when_ready(&prefix, START).unwrap();
    let mut broken = standing_sample(&robot);
    broken.q[..dof].fill(100.0);
    let commands = adapter.stream(&broken, PERIOD, Duration::from_millis(300));
    assert!(
        commands.is_empty(),
        "commands before a valid measurement\n{}",
        walkd.log()
    );
    let client = walk_tests::connect(&prefix).unwrap();
    let status = client.status().unwrap();
    assert_eq!(status.state, DaemonState::Fault, "{status:?}");
    let first = &robot.model.joint_names()[0];
    assert!(status.fault.as_str().contains(first.as_str()), "{status:?}");

    // Valid, then broken again: hold keeps the last command, inside the limits.
    let standing = standing_sample(&robot);
    let valid = adapter.stream(&standing, PERIOD, Duration::from_millis(200));
    assert!(!valid.is_empty(), "{}", walkd.log());
    client.control(shm_types::ControlCommand::Hold).unwrap();
    let held = adapter.stream(&broken, PERIOD, Duration::from_millis(300));
    assert!(!held.is_empty(), "{}", walkd.log());
    assert_within_limits(&robot, &held);
    let last_valid = command_q(valid.last().unwrap(), dof);
    assert!(held.iter().all(|c| command_q(c, dof) == last_valid));

    // A walk cannot start, and while samples keep coming nothing leaves the limits.
    drop(adapter);
    let feeder = Feeder::start(&prefix, broken, PERIOD).unwrap();
    let (json, _) = walk_json("armar4", 0.3).unwrap();
    let submit = client.submit_json(&json);
    std::thread::sleep(Duration::from_millis(200));
    assert_within_limits(&robot, &feeder.take_commands());
    assert!(
        submit.is_err(),
        "a walk started with joints at 100 rad\n{}",
        walkd.log()
    );
}

/// Item 4: after the adapter restarts (kill -9, a new one), the first command holds the new
/// robot's measured posture, not the posture before the crash; a tipping fault is acknowledged
/// only once the robot stands upright, and says so until then.
#[test]
fn an_adapter_restart_holds_the_new_posture_and_tipping_can_be_acknowledged() {
    let prefix = unique_prefix("hostile_restart");
    let (walkd, sim, client) = start_connected("armar4", &prefix, "realtime").unwrap();
    let robot = robot("armar4");
    let dof = robot.model.dof();
    let (json, _) = walk_json("armar4", 1.0).unwrap();
    client.submit_json(&json).unwrap();
    std::thread::sleep(Duration::from_secs(3));
    client.control(shm_types::ControlCommand::Hold).unwrap();
    sim.signal(libc::SIGKILL);
    wait_for_status(&client, "a stale link", REPLY, |s| {
        s.link == LinkState::Stale
    })
    .unwrap();

    // The "new robot": standing in its configured posture with the torso turned 0.3 rad.
    let mut adapter = RawAdapter::open(&prefix).unwrap();
    let mut fresh = standing_sample(&robot);
    let torso = robot
        .model
        .joint_names()
        .iter()
        .position(|n| n == "torso_yaw_joint")
        .unwrap();
    fresh.q[torso] += 0.3;
    let mut first = None;
    let deadline = Instant::now() + REPLY;
    while first.is_none() && Instant::now() < deadline {
        let seq = adapter.publish(&fresh, |_| {});
        std::thread::sleep(PERIOD);
        first = adapter
            .commands()
            .into_iter()
            .find(|c| command_answers(c) == seq);
    }
    let first = first.unwrap_or_else(|| panic!("no command after the restart\n{}", walkd.log()));
    let error = command_q(&first, dof)
        .iter()
        .zip(&fresh.q[..dof])
        .map(|(c, m)| (c - m).abs())
        .fold(0.0, f64::max);
    assert!(
        error < 1e-9,
        "first command after the restart is {error} rad off the new posture"
    );

    // Tip the robot over: the IMU turns 0.5 rad from where leg odometry puts the base.
    drop(adapter);
    let feeder = Feeder::start(&prefix, fresh, PERIOD).unwrap();
    let roll = |roll: f64| {
        move |raw: &mut Raw<SensorSample>| {
            raw.put::<u8>(offset_of!(SensorSample, has_imu), 1);
            let (s, c) = (roll / 2.0).sin_cos();
            raw.put::<[f64; 4]>(offset_of!(SensorSample, imu_orientation), [s, 0.0, 0.0, c]);
        }
    };
    feeder.edit(roll(0.0));
    std::thread::sleep(Duration::from_millis(200));
    feeder.edit(roll(0.5));
    let status =
        wait_for_status(&client, "tipping", REPLY, |s| s.state == DaemonState::Fault).unwrap();
    assert!(status.fault.as_str().contains("tipping"), "{status:?}");
    // Lying: hold is refused and says what to do.
    let raw = RawClient::connect(&prefix).unwrap();
    let hold = shm_types::ControlCommand::Hold as u32;
    let (accepted, message) = raw.control(hold, REPLY).unwrap();
    assert!(
        !accepted,
        "hold acknowledged tipping while the robot lies: {message}"
    );
    assert!(message.contains("upright"), "{message}");
    // Stood up again: hold acknowledges it.
    feeder.edit(roll(0.0));
    std::thread::sleep(Duration::from_millis(200));
    let (accepted, message) = raw.control(hold, REPLY).unwrap();
    assert!(accepted, "hold refused once upright: {message}");
    std::thread::sleep(Duration::from_millis(200));
    let status = client.status().unwrap();
    assert_eq!(
        status.state,
        DaemonState::Holding,
        "{status:?}\n{}",
        walkd.log()
    );
}

/// A stance file of `count` copies of one standing stance of `json` (a valid walk).
fn repeated_stances(json: &str, count: usize) -> String {
    let mut value: serde_json::Value = serde_json::from_str(json).unwrap();
    let first = value["stances"][0].clone();
    value["stances"] = serde_json::Value::Array(vec![first; count]);
    value.to_string()
}

/// Item 5: submissions are bounded inside walkd (bytes before parsing, stances, busy before
/// parsing) and the memory of a big walk is returned after it.
#[test]
fn submissions_are_bounded_and_busy_is_decided_before_parsing() {
    let prefix = unique_prefix("hostile_size");
    let (walkd, _sim, client) = start_connected("armar4", &prefix, "lockstep").unwrap();
    let raw = RawClient::connect(&prefix).unwrap();
    let (json, _) = walk_json("armar4", 0.3).unwrap();

    let spaces = vec![b' '; 40 << 20];
    let started = Instant::now();
    let (accepted, reason) = raw.submit(&spaces, REPLY).unwrap();
    assert!(!accepted && reason.contains("bytes"), "{reason}");
    assert!(
        started.elapsed() < Duration::from_secs(2),
        "{:?}",
        started.elapsed()
    );

    let many = repeated_stances(&json, 12_000);
    let (accepted, reason) = raw.submit(many.as_bytes(), REPLY).unwrap();
    assert!(!accepted && reason.contains("stances"), "{reason}");

    let rss_before = rss_kib(walkd.pid());
    let big = repeated_stances(&json, 9_000);
    let (accepted, reason) = raw.submit(big.as_bytes(), REPLY).unwrap();
    assert!(accepted, "{reason}\n{}", walkd.log());
    // While it executes, anything submitted is "busy", even what would not parse.
    let (accepted, reason) = raw.submit(b"{ not json", REPLY).unwrap();
    assert!(!accepted && reason.contains("busy"), "{reason}");
    client.control(shm_types::ControlCommand::Abort).unwrap();
    // A small walk replaces the big one, which walkd then frees.
    client.submit_json(&json).unwrap();
    std::thread::sleep(Duration::from_millis(500));
    let rss_after = rss_kib(walkd.pid());
    assert!(
        rss_after < rss_before + 16 * 1024,
        "walkd kept {} KiB after the big walk (before: {rss_before} KiB)",
        rss_after
    );
}

fn rss_kib(pid: u32) -> u64 {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap();
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmRSS:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
        .unwrap()
}

/// Item 6: a target outside the workspace the config allows is refused, naming the stance.
#[test]
fn targets_outside_the_workspace_are_refused() {
    let prefix = unique_prefix("hostile_targets");
    let (_walkd, _sim, client) = start_connected("armar4", &prefix, "lockstep").unwrap();
    let (json, _) = walk_json("armar4", 0.3).unwrap();
    for x in [1e300, 1e6, 50.0] {
        let mut value: serde_json::Value = serde_json::from_str(&json).unwrap();
        let stances = value["stances"].as_array_mut().unwrap();
        let swing = stances
            .iter()
            .position(|s| s["contacts"].as_array().unwrap().len() == 1)
            .unwrap();
        let foot = if stances[swing]["contacts"][0] == "left_foot" {
            "right_foot"
        } else {
            "left_foot"
        };
        stances[swing]["targets"][foot]["translation"][0] = serde_json::json!(x);
        match client.submit_json(&value.to_string()) {
            Err(client::daemon_client::SubmitError::Refused(reason)) => {
                assert!(reason.contains(&format!("stance {swing}")), "{reason}");
                assert!(reason.contains(foot), "{reason}");
            }
            other => panic!("a {foot} target at x = {x} was not refused: {other:?}"),
        }
    }
}

/// Item 7: the first cause of a fault is kept until acknowledged, later effects are added to
/// it, and a walk that ends `done` clears it.
#[test]
fn the_first_fault_cause_is_kept_and_done_clears_it() {
    let prefix = unique_prefix("hostile_cause");
    let walkd = start_walkd("armar4", &prefix, "realtime", 500.0).unwrap();
    let robot = robot("armar4");
    let feeder = Feeder::start(&prefix, standing_sample(&robot), PERIOD).unwrap();
    let client = walk_tests::connect(&prefix).unwrap();
    wait_for_status(&client, "a fresh link", START, |s| {
        s.link == LinkState::Fresh
    })
    .unwrap();
    let (json, _) = walk_json("armar4", 0.3).unwrap();
    client.submit_json(&json).unwrap();
    std::thread::sleep(Duration::from_millis(100));
    // One NaN sample, then the adapter goes silent.
    feeder.edit(|raw| raw.put(offset_of!(SensorSample, q), f64::NAN));
    std::thread::sleep(PERIOD * 2);
    drop(feeder);
    let status = wait_for_status(&client, "the fault", Duration::from_millis(500), |s| {
        s.state == DaemonState::Fault
    })
    .unwrap_or_else(|e| panic!("{e}\n{}", walkd.log()));
    assert!(
        status.fault.as_str().contains("invalid measurement"),
        "{status:?}"
    );
    let status = wait_for_status(&client, "a stale link", REPLY, |s| {
        s.link == LinkState::Stale
    })
    .unwrap();
    assert!(
        status.fault.as_str().starts_with("invalid measurement"),
        "the first cause was replaced: {status:?}"
    );
    assert!(status.fault.as_str().contains("stale"), "{status:?}");

    let _sim = start_sim("armar4", &prefix, "realtime", 500.0).unwrap();
    wait_for_status(&client, "a fresh link", START, |s| {
        s.link == LinkState::Fresh
    })
    .unwrap();
    client.control(shm_types::ControlCommand::Hold).unwrap();
    let id = client.submit_json(&json).unwrap();
    let done = client
        .wait_for_sequence(id, Duration::from_secs(120), |_| {})
        .unwrap();
    assert_eq!(done.state, DaemonState::Done, "{done:?}\n{}", walkd.log());
    assert!(
        done.fault.is_empty(),
        "an old fault stays beside done: {done:?}"
    );
}

/// Item 8: one process holding many ports cannot lock monitoring out, and a second publisher
/// on `sensors` is reported (as an intruder: walkd follows the real adapter) while the real
/// adapter still connects.
#[test]
fn a_greedy_process_cannot_lock_out_monitoring_or_the_adapter() {
    let prefix = unique_prefix("hostile_hog");
    let walkd = start_walkd("armar4", &prefix, "realtime", 500.0).unwrap();
    walk_tests::wait_until("walkd's services", START, || {
        walk_tests::connect(&prefix).ok()
    })
    .unwrap();
    // As many control clients and status subscribers as the services had before they were
    // sized for this, and a second publisher on sensors.
    let hog = wait_until("walkd's services", START, || {
        PortHog::take(&prefix, 8, 1).ok()
    })
    .unwrap();
    assert_eq!(hog.taken, (8, 8, 1), "{:?}", hog.taken);
    let _sim = start_sim("armar4", &prefix, "realtime", 500.0).unwrap();
    let status = walk_tests::run_walkctl(&["status", "--service-prefix", &prefix])
        .unwrap_or_else(|e| panic!("walkctl status: {e}\n{}", walkd.log()));
    assert!(status.contains("state"), "{status}");
    wait_until("walk-sim connected", START, || {
        let client = walk_tests::connect(&prefix).ok()?;
        (client.status().ok()?.link == LinkState::Fresh).then_some(())
    })
    .unwrap_or_else(|e| panic!("{e}\n{}", walkd.log()));
    let client = walk_tests::connect(&prefix).unwrap();
    let status = client.status().unwrap();
    assert!(
        status.fault.as_str().contains("intruder on sensors"),
        "{status:?}"
    );
}

/// Item 9, the smaller defects: a refused submission uses up no sequence id; walkctl says at
/// once that no walkd runs; an adapter sent a flood of bad commands logs a few lines, not one
/// per command.
#[test]
fn refusals_use_no_id_a_dead_walkd_is_named_at_once_and_bad_commands_do_not_flood_the_log() {
    let prefix = unique_prefix("hostile_small");
    let (walkd, sim, client) = start_connected("armar4", &prefix, "realtime").unwrap();
    let (json, _) = walk_json("armar4", 0.3).unwrap();
    assert!(client.submit_json("{ not json").is_err());
    assert_eq!(
        client.submit_json(&json).unwrap(),
        1,
        "a refusal used up an id"
    );
    drop(client);
    walkd.signal(libc::SIGKILL);
    walkd.wait_exit(Duration::from_secs(5)).unwrap();
    let started = Instant::now();
    let error = walk_tests::run_walkctl(&["status", "--service-prefix", &prefix]).unwrap_err();
    assert!(error.to_string().contains("no walkd serves"), "{error}");
    assert!(
        started.elapsed() < Duration::from_secs(3),
        "{:?}",
        started.elapsed()
    );

    let mut daemon = RawDaemon::open(&prefix).unwrap();
    let robot = robot("armar4");
    let mut command = shm_types::JointCommand::ZERO;
    command.joint_count = robot.model.dof() as u32;
    command.q_des[..robot.model.dof()].copy_from_slice(robot.standing.joints.as_slice());
    for _ in 0..500 {
        daemon.publish(&command, |raw| {
            raw.put(offset_of!(shm_types::JointCommand, mode), 257u32)
        });
        std::thread::sleep(PERIOD);
    }
    let log = sim.log();
    let refusals = log.matches("command refused").count();
    assert!(
        (1..=3).contains(&refusals),
        "{refusals} log lines for 500 bad commands\n{log}"
    );
    assert!(log.contains("mode holds 257"), "{log}");
}

/// The index of ARMAR-4's torso yaw joint: the joint the forgers turn.
fn torso(robot: &Robot) -> usize {
    robot
        .model
        .joint_names()
        .iter()
        .position(|n| n == "torso_yaw_joint")
        .unwrap()
}

/// The largest change of any joint between two consecutive commands (rad).
fn largest_step(commands: &[Raw<JointCommand>], dof: usize) -> f64 {
    commands
        .windows(2)
        .flat_map(|pair| {
            let (a, b) = (command_q(&pair[0], dof), command_q(&pair[1], dof));
            a.into_iter().zip(b).map(|(a, b)| (a - b).abs())
        })
        .fold(0.0, f64::max)
}

/// How a forger's process is named in walkd's reports: the test process is the forger.
fn forger_pid() -> String {
    format!("pid {}", std::process::id())
}

/// A walk of ARMAR-4 under way, its commands tapped, and the posture a forger sends: standing,
/// the torso turned 0.3 rad (inside the limits).
struct ForgeryTarget {
    prefix: String,
    walkd: Process,
    _sim: Process,
    client: DaemonClient,
    robot: Robot,
    tap: Tap<JointCommand>,
    /// Every command since the tap started.
    commands: Vec<Raw<JointCommand>>,
    /// The torso's command before the forgery.
    torso_before: f64,
    forged: SensorSample,
}

impl ForgeryTarget {
    /// Starts walking 1 m on a prefix of `test`'s and taps the commands for half a second.
    fn start(test: &str) -> Self {
        let prefix = unique_prefix(test);
        let (walkd, sim, client) = start_walking("armar4", &prefix, 1.0).unwrap();
        let robot = robot("armar4");
        let tap = Tap::<JointCommand>::start(&prefix, "commands", 128).unwrap();
        std::thread::sleep(Duration::from_millis(500));
        let commands = tap.take();
        let last = commands.last().expect("commands while walking");
        let torso_before = command_q(last, robot.model.dof())[torso(&robot)];
        let mut forged = standing_sample(&robot);
        forged.q[torso(&robot)] += 0.3;
        Self {
            prefix,
            walkd,
            _sim: sim,
            client,
            robot,
            tap,
            commands,
            torso_before,
            forged,
        }
    }

    /// The commands walkd sent since the tap started continue smoothly (no step above 0.01 rad
    /// between two), and none takes the forger's torso posture: every command's torso stays
    /// within 0.05 rad of where it was before the forgery.
    fn assert_commands_ignore_the_forger(&mut self) {
        self.commands.extend(self.tap.take());
        let (commands, log) = (&self.commands, self.walkd.log());
        let dof = self.robot.model.dof();
        assert!(
            commands.len() > 100,
            "only {} commands\n{log}",
            commands.len()
        );
        let step = largest_step(commands, dof);
        assert!(
            step <= 0.01,
            "a command jumped {step:.4} rad from the one before\n{log}"
        );
        let torso = torso(&self.robot);
        let drift = commands
            .iter()
            .map(|c| (command_q(c, dof)[torso] - self.torso_before).abs())
            .fold(0.0, f64::max);
        assert!(
            drift < 0.05,
            "the torso was commanded {drift:.3} rad from its posture before the forgery\n{log}"
        );
    }
}

/// Issue 20, defect 2: another process replays an adapter restart (its sequence starts at 1,
/// the torso turned 0.3 rad, inside the limits) for 5 samples and leaves within 50 ms, during a
/// walk. walkd pins the adapter it linked to: the forged samples are refused and counted, the
/// commands stay continuous and never take the forged posture.
#[test]
fn a_forged_adapter_restart_does_not_move_the_robot() {
    let mut walk = ForgeryTarget::start("hostile_forged_restart");
    {
        let mut forger = RawAdapter::open(&walk.prefix).unwrap();
        let forging = Instant::now();
        for _ in 0..5 {
            forger.publish(&walk.forged, |_| {});
            std::thread::sleep(PERIOD);
        }
        drop(forger);
        assert!(forging.elapsed() < Duration::from_millis(50));
    }
    std::thread::sleep(Duration::from_secs(1));
    walk.assert_commands_ignore_the_forger();
    let (walkd, client) = (&walk.walkd, &walk.client);
    let status = client.status().unwrap();
    assert!(status.rejected_samples >= 5, "{status:?}\n{}", walkd.log());
    assert!(
        status.last_rejection.as_str().contains("publisher"),
        "{status:?}"
    );
    assert_eq!(status.link, LinkState::Fresh, "{status:?}");
}

/// Issue 20, defects 2 and 4: a second process publishes on `sensors` during a walk (its own
/// sequence from 1, another posture). Its samples never reach the controller; the walk is
/// stopped with hold; the status names the intruder's process, also after hold; a new walk is
/// refused naming it; once it is gone walkd walks again.
#[test]
fn a_second_publisher_on_sensors_is_refused_and_named_also_after_hold() {
    let mut walk = ForgeryTarget::start("hostile_second_sensors");
    let forger = Feeder::start(&walk.prefix, walk.forged, PERIOD).unwrap();
    let (walkd, client) = (&walk.walkd, &walk.client);
    let named = |s: &shm_types::DaemonStatus| s.fault.as_str().contains(&forger_pid());
    wait_for_status(client, "the walk held, the intruder named", REPLY, |s| {
        named(s) && s.state == DaemonState::Holding
    })
    .unwrap_or_else(|e| panic!("{e}: {:?}\n{}", client.status().ok(), walkd.log()));
    let held = client.control(ControlCommand::Hold).unwrap();
    std::thread::sleep(Duration::from_millis(200));
    let status = client.status().unwrap();
    assert!(
        named(&held) && named(&status),
        "hold hid the intruder: {held:?} / {status:?}"
    );
    let (json, _) = walk_json("armar4", 0.3).unwrap();
    match client.submit_json(&json) {
        Err(client::daemon_client::SubmitError::Refused(reason)) => {
            assert!(reason.contains(&forger_pid()), "{reason}");
        }
        other => panic!("a walk was not refused while an intruder publishes: {other:?}"),
    }
    walk.assert_commands_ignore_the_forger();

    drop(forger);
    let (walkd, client) = (&walk.walkd, &walk.client);
    let status = wait_for_status(client, "the intruder gone", REPLY, |s| !named(s))
        .unwrap_or_else(|e| panic!("{e}\n{}", walkd.log()));
    assert_eq!(status.link, LinkState::Fresh, "{status:?}");
    client.control(ControlCommand::Hold).unwrap();
    // Refused "just now" samples keep walks off for a moment after the intruder is gone.
    wait_until("a walk accepted again", REPLY, || {
        client.submit_json(&json).ok()
    })
    .unwrap_or_else(|e| panic!("{e}\n{}", walkd.log()));
    assert!(walkd.is_running());
}

/// Issue 20, defect 3: a second process publishes on `telemetry` during a recorded walk, with
/// sequence numbers near `u64::MAX`. The observer pinned walkd's telemetry publisher: it records
/// none of the forged messages (no absurd loss count) and reports the intruder's process.
#[test]
fn a_second_telemetry_publisher_is_not_recorded_and_is_reported() {
    let prefix = unique_prefix("hostile_second_telemetry");
    let (walkd, _sim, _client) = start_walking("armar4", &prefix, 1.0).unwrap();
    let file = std::env::temp_dir().join(format!(
        "walk-e2e-second-telemetry-{}.mcap",
        std::process::id()
    ));
    let recorder = {
        let (prefix, file) = (prefix.clone(), file.display().to_string());
        let config = config("armar4").display().to_string();
        std::thread::spawn(move || {
            walk_tests::run_walkctl(&[
                "record",
                "--config",
                &config,
                "--service-prefix",
                &prefix,
                "-o",
                &file,
                "--duration",
                "3",
                "--json",
            ])
        })
    };
    std::thread::sleep(Duration::from_millis(1000));
    let mut forger = RawPublisher::<Telemetry>::open(&prefix, "telemetry").unwrap();
    for i in 0..50u64 {
        forger.publish(Telemetry::ZERO, |raw| {
            raw.put(offset_of!(Telemetry, seq), u64::MAX - 23_727_245 + i);
            raw.put(offset_of!(Telemetry, stance_count), 999u32);
        });
        std::thread::sleep(PERIOD);
    }
    let output = recorder
        .join()
        .unwrap()
        .unwrap_or_else(|e| panic!("{e}\n{}", walkd.log()));
    let _ = std::fs::remove_file(&file);
    let report: serde_json::Value = serde_json::from_str(&output).unwrap();
    let telemetry = &report["observer"]["telemetry"];
    assert!(
        telemetry["lost"].as_u64().unwrap() < 50,
        "forged telemetry was recorded: {report}"
    );
    assert!(
        telemetry["last_seq"].as_u64().unwrap() < 1 << 32,
        "forged telemetry was recorded: {report}"
    );
    let intruders = report["observer"]["intruders"].to_string();
    assert!(
        intruders.contains("telemetry") && intruders.contains(&forger_pid()),
        "the observer did not report the second telemetry publisher: {report}"
    );
}

/// Issue 20, defect 3: another process created `telemetry` and `status` before walkd and holds
/// every publisher slot. Monitoring cannot stop control: walkd starts, says once that telemetry
/// is off, and walks to the end.
#[test]
fn held_monitoring_slots_do_not_stop_walkd() {
    let prefix = unique_prefix("hostile_monitor_slots");
    let hog = MonitorHog::take(&prefix).unwrap();
    assert_eq!(hog.taken, (MonitorHog::SLOTS, MonitorHog::SLOTS));
    let (walkd, _sim, client) = start_connected("armar4", &prefix, "lockstep")
        .unwrap_or_else(|e| panic!("walkd did not start with the monitoring slots held: {e}"));
    let (json, _) = walk_json("armar4", 0.3).unwrap();
    let id = client.submit_json(&json).unwrap();
    let done = client
        .wait_for_sequence(id, Duration::from_secs(120), |_| {})
        .unwrap_or_else(|e| panic!("{e}\n{}", walkd.log()));
    assert_eq!(done.state, DaemonState::Done, "{done:?}\n{}", walkd.log());
    assert!(done.fault.as_str().contains("telemetry off"), "{done:?}");
    assert_eq!(
        walkd.log().matches("telemetry off").count(),
        1,
        "{}",
        walkd.log()
    );
}

/// Issue 20, deliverable 2: walk-sim pins the walkd it linked to. A second process publishing
/// track commands (the torso turned 0.3 rad) does not move the simulated robot, and walk-sim
/// names it in its log.
#[test]
fn walk_sim_follows_only_the_walkd_it_linked_to() {
    let prefix = unique_prefix("hostile_forged_commands");
    let (walkd, sim, client) = start_connected("armar4", &prefix, "realtime").unwrap();
    let robot = robot("armar4");
    let (dof, torso) = (robot.model.dof(), torso(&robot));
    let samples = Tap::<SensorSample>::start(&prefix, "sensors", 128).unwrap();
    std::thread::sleep(Duration::from_millis(300));
    let q =
        |s: &Raw<SensorSample>| s.get::<[f64; shm_types::MAX_JOINTS]>(offset_of!(SensorSample, q));
    let torso_before = q(samples.take().last().expect("samples"))[torso];
    let mut forger = RawDaemon::open(&prefix).unwrap();
    let mut command = JointCommand::ZERO;
    command.joint_count = dof as u32;
    command.mode = Code::new(CommandMode::Track);
    command.q_des[..dof].copy_from_slice(robot.standing.joints.as_slice());
    command.q_des[torso] += 0.3;
    for _ in 0..150 {
        forger.publish(&command, |_| {});
        std::thread::sleep(PERIOD);
    }
    let moved = samples
        .take()
        .iter()
        .map(|s| (q(s)[torso] - torso_before).abs())
        .fold(0.0, f64::max);
    assert!(
        moved < 0.01,
        "the forged commands turned the simulated torso {moved:.3} rad\n{}",
        sim.log()
    );
    let log = sim.log();
    assert!(
        log.contains("refused") && log.contains(&forger_pid()),
        "walk-sim did not name the second command publisher\n{log}"
    );
    assert_eq!(client.status().unwrap().link, LinkState::Fresh);
    assert!(walkd.is_running());
}
