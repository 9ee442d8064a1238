//! A minimal hardware adapter: what an ARMAR-4 or HRP-4 adapter writes, compiled and run by CI.
//!
//! An adapter maps its robot's joints and sensors onto the model's order ([`RobotIo`]); the
//! shared adapter loop ([`run_adapter`]) does the rest: service names, protocol checks, sequence
//! numbers, time stamps, the command watchdog and holding position. Here the "bus" is a stand-in
//! for a vendor SDK: joints that follow their position targets, foot sensors that read the
//! robot's weight, no IMU.
//!
//! ```text
//! cargo run --release -p sim-adapter --example minimal_adapter -- configs/armar4.toml [PERIODS [PREFIX]]
//! ```
//! It serves `PERIODS` samples (default 100) at the config's rate on the config's service
//! prefix (or `PREFIX`), then exits 0.

use std::cell::Cell;
use std::path::PathBuf;
use std::time::Duration;

use kinematics::ConfigFile;
use kinematics::robot::Robot;
use shm_types::{AdapterPorts, ClockMode, RuntimeConfig, SensorSample, ServiceNames};
use sim_adapter::{AdapterOptions, RobotIo, run_adapter};

/// Stand-in for the robot's bus (EtherCAT, CAN, a vendor SDK): one position-controlled axis per
/// bus slot, and two ankle force-torque sensors.
struct Bus {
    positions: Vec<f64>,
    /// Vertical force on each ankle sensor (N).
    ankle_force: f64,
}

impl Bus {
    fn encoder_position(&self, slot: usize) -> f64 {
        self.positions[slot]
    }

    fn set_position_target(&mut self, slot: usize, target: f64) -> Result<(), String> {
        if !target.is_finite() {
            return Err(format!("slot {slot}: target {target}"));
        }
        self.positions[slot] = target;
        Ok(())
    }

    /// `[fx, fy, fz, tx, ty, tz]` in world-aligned axes (a real bus rotates the sensor reading
    /// with the orientation estimate).
    fn ankle_wrench_world(&self) -> [f64; 6] {
        [0.0, 0.0, self.ankle_force, 0.0, 0.0, 0.0]
    }
}

/// The robot as the adapter loop sees it: model joint `i` is bus slot `bus_slot[i]`.
struct Adapter {
    bus: Bus,
    bus_slot: Vec<usize>,
}

/// Why the bus refused a setpoint.
#[derive(Debug, thiserror::Error)]
#[error("bus: {0}")]
struct BusError(String);

impl RobotIo for Adapter {
    type Error = BusError;

    fn joint_count(&self) -> usize {
        self.bus_slot.len()
    }

    fn read(&mut self, sample: &mut SensorSample) {
        for (i, &slot) in self.bus_slot.iter().enumerate() {
            sample.q[i] = self.bus.encoder_position(slot);
            sample.qd[i] = 0.0;
        }
        sample.wrenches[0] = self.bus.ankle_wrench_world(); // left foot
        sample.wrenches[1] = self.bus.ankle_wrench_world(); // right foot
        sample.wrenches[2] = [0.0; 6]; // no hand sensors
        sample.wrenches[3] = [0.0; 6];
    }

    fn write(&mut self, q_des: &[f64], _qd_des: &[f64], _dt: f64) -> Result<(), BusError> {
        for (i, &slot) in self.bus_slot.iter().enumerate() {
            self.bus
                .set_position_target(slot, q_des[i])
                .map_err(BusError)?;
        }
        Ok(())
    }
}

fn main() -> anyhow::Result<()> {
    let mut args = std::env::args().skip(1);
    let config = PathBuf::from(
        args.next()
            .unwrap_or_else(|| "configs/armar4.toml".to_owned()),
    );
    let periods: u64 = args.next().map_or(Ok(100), |n| n.parse())?;
    let file = ConfigFile::load(&config)?;
    let mut runtime = RuntimeConfig::from_section(file.section("runtime"), &file.origin())?;
    if let Some(prefix) = args.next() {
        runtime.service_prefix = prefix;
    }
    let robot = Robot::from_config(&file, None)?;

    // A real adapter looks each model joint up on its bus by name; the stand-in bus has the
    // model's order and starts in the configured standing posture.
    let joints = robot.model.joint_names().len();
    let bus = Bus {
        positions: robot.standing.joints.iter().copied().collect(),
        ankle_force: robot.model.total_mass() * kinematics::ground::GRAVITY / 2.0,
    };
    let mut adapter = Adapter {
        bus,
        bus_slot: (0..joints).collect(),
    };

    let ports = AdapterPorts::open(
        &ServiceNames::new(&runtime.service_prefix)?,
        "minimal-adapter",
    )?;
    let options = AdapterOptions {
        clock: ClockMode::Realtime, // or Lockstep, publishing once per bus cycle
        rate_hz: runtime.rate_hz,
        watchdog_periods: runtime.watchdog_periods,
        lockstep_timeout: Duration::from_millis(runtime.lockstep_timeout_ms),
        spin: Duration::ZERO, // a bus-clocked adapter waits for its bus instead
    };
    // A long-running adapter stops on SIGTERM (`shm_types::process::termination_requested`);
    // this one after `periods` checks of the stop condition, one per period.
    let served = Cell::new(0u64);
    let should_stop = || {
        served.set(served.get() + 1);
        served.get() > periods
    };
    let report = run_adapter(&ports, &mut adapter, &options, &should_stop)?;
    println!(
        "minimal adapter: {} samples, {} commands, {} watchdog trips",
        report.samples, report.commands, report.watchdog_trips
    );
    Ok(())
}
