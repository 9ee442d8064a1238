//! The adapter loop against an in-test daemon: commands are applied, stale commands make the
//! adapter hold, fresh ones make it follow again.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use shm_types::{ClockMode, CommandMode, DaemonLoopPorts, SensorSample, ServiceNames};
use sim_adapter::{AdapterOptions, RobotIo, run_adapter};

/// A robot whose joints jump to the setpoint (an ideal servo), recording nothing else.
struct IdealServo {
    q: Vec<f64>,
}

impl RobotIo for IdealServo {
    type Error = std::convert::Infallible;

    fn joint_count(&self) -> usize {
        self.q.len()
    }

    fn read(&mut self, sample: &mut SensorSample) {
        sample.q[..self.q.len()].copy_from_slice(&self.q);
    }

    fn write(&mut self, q_des: &[f64], _qd_des: &[f64], _dt: f64) -> Result<(), Self::Error> {
        self.q.copy_from_slice(q_des);
        Ok(())
    }
}

/// Starts an adapter thread on `prefix` at `rate_hz`; returns its stop flag and handle.
fn start_adapter(
    prefix: &str,
    clock: ClockMode,
    rate_hz: f64,
) -> (
    Arc<AtomicBool>,
    std::thread::JoinHandle<sim_adapter::AdapterReport>,
) {
    let stop = Arc::new(AtomicBool::new(false));
    let names = ServiceNames::new(prefix).unwrap();
    let flag = Arc::clone(&stop);
    let handle = std::thread::spawn(move || {
        let ports = shm_types::AdapterPorts::open(&names, "adapter").unwrap();
        let mut robot = IdealServo {
            q: vec![0.1, 0.2, 0.3],
        };
        let options = AdapterOptions {
            clock,
            rate_hz,
            watchdog_periods: 5,
            lockstep_timeout: Duration::from_millis(50),
            spin: Duration::ZERO,
        };
        run_adapter(&ports, &mut robot, &options, &|| {
            flag.load(Ordering::Relaxed)
        })
        .unwrap()
    });
    (stop, handle)
}

/// Receives the next sample (panics after 2 s).
fn next_sample(daemon: &DaemonLoopPorts, sample: &mut SensorSample) {
    for _ in 0..100 {
        daemon.wait_for_sample(Duration::from_millis(20)).unwrap();
        if daemon.take_latest_sample(sample).unwrap() {
            return;
        }
    }
    panic!("no sample within 2 s");
}

fn answer(daemon: &DaemonLoopPorts, sample: &SensorSample, q0: f64) {
    daemon
        .send_command(|command| {
            command.answers_seq = sample.seq;
            command.joint_count = 3;
            command.mode = CommandMode::Track.into();
            command.q_des[..3].copy_from_slice(&[q0, 0.0, 0.0]);
        })
        .unwrap();
}

fn check(clock: ClockMode, test: &str) {
    let prefix = format!("walk-test/sim-adapter/{test}/{}", std::process::id());
    let daemon = DaemonLoopPorts::open(&ServiceNames::new(&prefix).unwrap(), "daemon").unwrap();
    let (stop, adapter) = start_adapter(&prefix, clock, 500.0);
    let mut sample = SensorSample::ZERO;

    next_sample(&daemon, &mut sample);
    assert!(
        sample.adapter_holding.is_set(),
        "holds until the first command"
    );
    assert_eq!(sample.q(), &[0.1, 0.2, 0.3]);
    for i in 1..=20 {
        answer(&daemon, &sample, i as f64);
        next_sample(&daemon, &mut sample);
    }
    // The last samples reflect the commands.
    assert!(!sample.adapter_holding.is_set());
    assert!(sample.q[0] >= 19.0, "{:?}", sample.q());

    // Stop answering: the adapter holds the last posture.
    let mut held = None;
    for _ in 0..200 {
        next_sample(&daemon, &mut sample);
        if sample.adapter_holding.is_set() {
            held = Some(sample);
            break;
        }
    }
    let held = held.expect("the adapter never held");
    next_sample(&daemon, &mut sample);
    assert!(sample.adapter_holding.is_set());
    assert_eq!(sample.q(), held.q(), "the hold posture moved");

    // Answer again: it follows.
    answer(&daemon, &sample, 42.0);
    for _ in 0..20 {
        next_sample(&daemon, &mut sample);
        if !sample.adapter_holding.is_set() {
            break;
        }
    }
    assert!(!sample.adapter_holding.is_set());
    assert_eq!(sample.q[0], 42.0);

    stop.store(true, Ordering::Relaxed);
    let report = adapter.join().unwrap();
    assert_eq!(report.watchdog_trips, 1);
    assert_eq!(report.commands, 21);
}

#[test]
fn lockstep_adapter_follows_holds_when_stale_and_resumes() {
    check(ClockMode::Lockstep, "lockstep");
}

#[test]
fn realtime_adapter_follows_holds_when_stale_and_resumes() {
    check(ClockMode::Realtime, "realtime");
}

/// A stop request ends the loop within its longest single wait, whatever the period: a period
/// of 1000 s (1 mHz) is not slept through.
#[test]
fn a_slow_realtime_adapter_stops_when_asked_not_at_its_next_period() {
    let prefix = format!("walk-test/sim-adapter/slow/{}", std::process::id());
    let daemon = DaemonLoopPorts::open(&ServiceNames::new(&prefix).unwrap(), "daemon").unwrap();
    let (stop, adapter) = start_adapter(&prefix, ClockMode::Realtime, 1e-3);
    let mut sample = SensorSample::ZERO;
    next_sample(&daemon, &mut sample);
    stop.store(true, Ordering::Relaxed);
    let (done, ended) = std::sync::mpsc::channel();
    std::thread::spawn(move || done.send(adapter.join()).unwrap());
    let report = ended
        .recv_timeout(Duration::from_secs(2))
        .expect("the adapter still sleeps 2 s after the stop request")
        .unwrap();
    assert_eq!(report.samples, 1);
}
