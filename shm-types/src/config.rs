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
}

impl RuntimeConfig {
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
            .map_err(|e: toml::de::Error| invalid(e.message().to_owned()))?;
        config.validate().map_err(invalid)?;
        Ok(config)
    }

    fn validate(&self) -> Result<(), String> {
        if !(self.rate_hz.is_finite() && self.rate_hz > 0.0 && self.rate_hz <= 10_000.0) {
            return Err(format!("rate_hz = {} must be in (0, 10000]", self.rate_hz));
        }
        if !(self.status_rate_hz.is_finite() && self.status_rate_hz > 0.0) {
            return Err(format!(
                "status_rate_hz = {} must be positive",
                self.status_rate_hz
            ));
        }
        if self.watchdog_periods == 0 {
            return Err("watchdog_periods must be at least 1".to_owned());
        }
        if self.lockstep_timeout_ms == 0 {
            return Err("lockstep_timeout_ms must be at least 1".to_owned());
        }
        if let Some(priority) = self.fifo_priority
            && !(1..=99).contains(&priority)
        {
            return Err(format!("fifo_priority = {priority} must be in 1..=99"));
        }
        if self.max_submission_bytes == 0 || self.max_stances == 0 {
            return Err("max_submission_bytes and max_stances must be at least 1".to_owned());
        }
        crate::ServiceNames::new(&self.service_prefix)
            .map_err(|e| format!("service_prefix: {e}"))?;
        Ok(())
    }
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
}
