//! The `[runtime]` section of a robot config: what the daemon and its adapters must agree on
//! (service prefix, rate, watchdogs), the daemon's real-time options and its submission limits.
//! The file itself is read once by `kinematics::ConfigFile`, which hands this crate the section.

use serde::Deserialize;

/// `[runtime]` of `configs/<robot>.toml`. Unknown keys are errors.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RuntimeConfig {
    /// Prefix of the robot's services, e.g. `walk/armar4`.
    pub service_prefix: String,
    /// Control rate of the daemon and sample rate of the adapter.
    #[serde(default = "default_rate_hz")]
    pub rate_hz: f64,
    /// Periods without a fresh sample (daemon) or command (adapter) before holding.
    #[serde(default = "default_watchdog_periods")]
    pub watchdog_periods: u32,
    /// Lockstep clock: wall time without a sample (daemon) or command (adapter) before holding.
    #[serde(default = "default_lockstep_timeout_ms")]
    pub lockstep_timeout_ms: u64,
    /// Rate of `status` publications.
    #[serde(default = "default_status_rate_hz")]
    pub status_rate_hz: f64,
    /// SCHED_FIFO priority of the daemon's control thread (1..=99); none: normal scheduling.
    #[serde(default)]
    pub fifo_priority: Option<i32>,
    /// CPU the daemon's control thread is pinned to; none: no pinning.
    #[serde(default)]
    pub cpu: Option<usize>,
    /// Lock the daemon's memory (`mlockall`) so page faults cannot stall the control loop.
    #[serde(default)]
    pub lock_memory: bool,
    /// The daemon busy-polls for each sample from this long (µs) before to this long after its
    /// expected time instead of sleeping through it (0: sleep and wait for the sample event;
    /// half a period or more: never sleep, which takes a core of its own).
    #[serde(default)]
    pub spin_us: u32,
    /// Largest submission (JSON bytes) walkd reads; a larger one is refused before parsing.
    #[serde(default = "default_max_submission_bytes")]
    pub max_submission_bytes: usize,
    /// Most stances a submitted sequence may have; counted before the sequence is built.
    #[serde(default = "default_max_stances")]
    pub max_stances: usize,
}

/// The longest a watchdog may wait before holding, `watchdog_periods / rate_hz` (s).
pub const WATCHDOG_MAX_S: f64 = 2.0;

fn default_rate_hz() -> f64 {
    500.0
}
fn default_watchdog_periods() -> u32 {
    10
}
fn default_lockstep_timeout_ms() -> u64 {
    500
}
fn default_status_rate_hz() -> f64 {
    20.0
}
fn default_max_submission_bytes() -> usize {
    crate::MAX_SEQUENCE_BYTES
}
/// About 15 km of the slowest generated walk (26 stances per metre).
fn default_max_stances() -> usize {
    10_000
}

/// Why `[runtime]` could not be read; names the file and the key.
#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    /// The `[runtime]` section is missing.
    #[error("{origin}: missing section [runtime]")]
    MissingSection {
        /// The config file.
        origin: String,
    },
    /// A key of `[runtime]` is unknown, missing, of the wrong type or out of range.
    #[error("{origin}: [runtime]: {message}")]
    Invalid {
        /// The config file.
        origin: String,
        /// What is wrong, naming the key.
        message: String,
    },
    /// A command-line value that replaces a `[runtime]` key is out of range (or makes another
    /// key so).
    #[error("{flags}: [runtime]: {message}")]
    Override {
        /// The overriding flags and their values (`--rate-hz 1000000000000`).
        flags: String,
        /// What is wrong, naming the key.
        message: String,
    },
}

/// Command-line values that replace `[runtime]` keys: the flags of walkd and walk-sim named
/// after them (`--rate-hz`, `--service-prefix`, `--fifo-priority`, `--cpu`, `--spin-us`). They
/// are checked like the file's values, the error naming the flags.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RuntimeOverrides {
    /// `--rate-hz`.
    pub rate_hz: Option<f64>,
    /// `--service-prefix`.
    pub service_prefix: Option<String>,
    /// `--fifo-priority`.
    pub fifo_priority: Option<i32>,
    /// `--cpu`.
    pub cpu: Option<usize>,
    /// `--spin-us`.
    pub spin_us: Option<u32>,
}

impl RuntimeOverrides {
    /// `runtime` with the given values in place, checked.
    pub fn apply(&self, mut runtime: RuntimeConfig) -> Result<RuntimeConfig, ConfigError> {
        let mut flags = Vec::new();
        if let Some(rate) = self.rate_hz {
            runtime.rate_hz = rate;
            flags.push(format!("--rate-hz {rate}"));
        }
        if let Some(prefix) = &self.service_prefix {
            runtime.service_prefix.clone_from(prefix);
            flags.push(format!("--service-prefix {prefix}"));
        }
        if let Some(priority) = self.fifo_priority {
            runtime.fifo_priority = Some(priority);
            flags.push(format!("--fifo-priority {priority}"));
        }
        if let Some(cpu) = self.cpu {
            runtime.cpu = Some(cpu);
            flags.push(format!("--cpu {cpu}"));
        }
        if let Some(spin_us) = self.spin_us {
            runtime.spin_us = spin_us;
            flags.push(format!("--spin-us {spin_us}"));
        }
        runtime.check().map_err(|message| ConfigError::Override {
            flags: flags.join(" "),
            message,
        })?;
        Ok(runtime)
    }
}

impl RuntimeConfig {
    /// The range of `rate_hz` (Hz), also of every `--rate-hz`.
    pub const RATE_HZ: std::ops::RangeInclusive<f64> = 10.0..=10_000.0;

    /// Reads the `[runtime]` section (`None`: the file has none); `origin` names the file.
    pub fn from_section(section: Option<&toml::Value>, origin: &str) -> Result<Self, ConfigError> {
        let section = section.ok_or_else(|| ConfigError::MissingSection {
            origin: origin.to_owned(),
        })?;
        let invalid = |message: String| ConfigError::Invalid {
            origin: origin.to_owned(),
            message,
        };
        let config: Self = section
            .clone()
            .try_into()
            // The error's text names the key of a badly typed value; its message alone does not.
            .map_err(|e: toml::de::Error| invalid(e.to_string().trim_end().replace('\n', " ")))?;
        config.check().map_err(invalid)?;
        Ok(config)
    }

    /// Checks every value against its documented range (docs/ipc.md, "[runtime]") and the
    /// watchdogs against [`WATCHDOG_MAX_S`]; the error names the key. Run at load
    /// and again after command-line overrides ([`RuntimeOverrides::apply`]).
    pub fn check(&self) -> Result<(), String> {
        for bound in self.bounds() {
            if let Some(value) = bound.value
                && !(bound.min <= value && value <= bound.max)
            {
                // Integers as written; others (NaN, 1e-300) as Rust reads them.
                let shown = if value.fract() == 0.0 && value.abs() < 1e16 {
                    format!("{value:.0}")
                } else {
                    format!("{value:?}")
                };
                return Err(format!(
                    "{} = {shown}: must be in [{}, {}]",
                    bound.key, bound.min, bound.max
                ));
            }
        }
        let watchdog_s = f64::from(self.watchdog_periods) / self.rate_hz;
        if watchdog_s > WATCHDOG_MAX_S {
            return Err(format!(
                "watchdog_periods = {} at rate_hz = {} holds only after {watchdog_s} s without a \
                 sample: must be at most {WATCHDOG_MAX_S} s",
                self.watchdog_periods, self.rate_hz,
            ));
        }
        crate::ServiceNames::new(&self.service_prefix)
            .map_err(|e| format!("service_prefix: {e}"))?;
        Ok(())
    }

    /// The section's table: every numeric key, its value and its range, one line a key.
    pub fn bounds(&self) -> Vec<RuntimeBound> {
        let bound = |key, value: Option<f64>, min, max| RuntimeBound {
            key,
            value,
            min,
            max,
        };
        let (rate_min, rate_max) = (*Self::RATE_HZ.start(), *Self::RATE_HZ.end());
        vec![
            bound("rate_hz", Some(self.rate_hz), rate_min, rate_max),
            bound("status_rate_hz", Some(self.status_rate_hz), 1.0, 1000.0),
            bound(
                "watchdog_periods",
                Some(self.watchdog_periods.into()),
                1.0,
                1000.0,
            ),
            bound(
                "lockstep_timeout_ms",
                Some(self.lockstep_timeout_ms as f64),
                1.0,
                5000.0,
            ),
            bound(
                "fifo_priority",
                self.fifo_priority.map(f64::from),
                1.0,
                99.0,
            ),
            // A CPU the affinity mask can name (CPU_SETSIZE).
            bound("cpu", self.cpu.map(|cpu| cpu as f64), 0.0, 1023.0),
            bound("spin_us", Some(self.spin_us.into()), 0.0, 10_000.0),
            bound(
                "max_submission_bytes",
                Some(self.max_submission_bytes as f64),
                1024.0,
                (1u64 << 30) as f64,
            ),
            bound("max_stances", Some(self.max_stances as f64), 1.0, 1e6),
        ]
    }
}

/// One numeric key of `[runtime]`: its value (`None`: an optional key left out) and its range.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RuntimeBound {
    /// The key.
    pub key: &'static str,
    /// Its value.
    pub value: Option<f64>,
    /// The smallest value allowed.
    pub min: f64,
    /// The largest value allowed.
    pub max: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<RuntimeConfig, ConfigError> {
        let table: toml::Table = text.parse().unwrap();
        RuntimeConfig::from_section(table.get("runtime"), "robot.toml")
    }

    #[test]
    fn defaults_fill_optional_keys() {
        let config = parse("[robot]\nx = 1\n[runtime]\nservice_prefix = \"walk/r\"\n").unwrap();
        assert_eq!(config.rate_hz, 500.0);
        assert_eq!(config.watchdog_periods, 10);
        assert_eq!(config.fifo_priority, None);
    }

    #[test]
    fn errors_name_file_and_key() {
        let error =
            parse("[runtime]\nservice_prefix = \"walk/r\"\nrate_hz_typo = 3\n").unwrap_err();
        let text = error.to_string();
        assert!(
            text.contains("robot.toml") && text.contains("rate_hz_typo"),
            "{text}"
        );
        let error = parse("[runtime]\nservice_prefix = \"walk/r\"\nrate_hz = -1.0\n").unwrap_err();
        assert!(error.to_string().contains("rate_hz"), "{error}");
        assert!(matches!(
            parse("[robot]\n"),
            Err(ConfigError::MissingSection { .. })
        ));
    }

    #[test]
    fn values_outside_their_ranges_are_refused_naming_the_key() {
        for (key, value) in [
            ("status_rate_hz", "1e-300"),
            ("status_rate_hz", "1e300"),
            ("rate_hz", "1e-3"),
            ("watchdog_periods", "4294967295"),
            ("lockstep_timeout_ms", "18446744073709"),
            ("spin_us", "4294967295"),
            ("max_stances", "9223372036854775807"),
            ("max_submission_bytes", "9223372036854775807"),
            ("cpu", "100000"),
            ("watchdog_periods", "-1"),
            ("lockstep_timeout_ms", "1.5"),
            ("fifo_priority", "1e10"),
            ("rate_hz", "nan"),
        ] {
            let text = format!("[runtime]\nservice_prefix = \"walk/r\"\n{key} = {value}\n");
            let error = parse(&text).expect_err(&text).to_string();
            assert!(
                error.contains("robot.toml") && error.contains(key),
                "{key} = {value}: {error}"
            );
        }
    }

    #[test]
    fn overrides_are_checked_like_the_file_and_name_their_flags() {
        let runtime =
            parse("[runtime]\nservice_prefix = \"walk/r\"\nwatchdog_periods = 100\n").unwrap();
        let overrides = |rate_hz| RuntimeOverrides {
            rate_hz: Some(rate_hz),
            ..RuntimeOverrides::default()
        };
        assert_eq!(
            overrides(1000.0).apply(runtime.clone()).unwrap().rate_hz,
            1000.0
        );
        for (rate, named) in [
            (1e12, "rate_hz"),
            (f64::NAN, "rate_hz"),
            (20.0, "watchdog_periods"),
        ] {
            let error = overrides(rate)
                .apply(runtime.clone())
                .unwrap_err()
                .to_string();
            assert!(
                error.starts_with(&format!("--rate-hz {rate}: [runtime]: {named} =")),
                "{error}"
            );
        }
    }
}
