//! `--speed V` as a walk asks it (`walkctl generate | demo | evaluate`): the speed, with the
//! limits within which walkd times the robot's dynamic gait from a sequence (its `[gait.dynamic]`
//! as walkd reads it), so that a paced walk plans no support walkd would change, and is walked at
//! the speed planned.

use daemon::controller::GaitConfig;
use kinematics::ConfigFile;
use stance::{Gait, WalkingSpeed};

/// The walking speed of `--speed` (m/s) for a robot config and gait; `None` without one.
/// Refused for the static gait, which does not time its stances.
pub fn walking_speed(
    speed: Option<f64>,
    file: &ConfigFile,
    gait: Gait,
) -> anyhow::Result<Option<WalkingSpeed>> {
    let Some(m_s) = speed else {
        return Ok(None);
    };
    anyhow::ensure!(
        gait == Gait::Dynamic,
        "--speed needs the dynamic gait (--gait dynamic): the static gait does not time its \
         stances"
    );
    let config = GaitConfig::from_config(file)?;
    let dynamic = config.dynamic()?;
    Ok(Some(WalkingSpeed {
        m_s,
        support_limits_s: [
            dynamic.timed_single_support(),
            dynamic.timed_double_support(),
        ],
    }))
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;

    fn jvrc1() -> ConfigFile {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs/jvrc1.toml");
        ConfigFile::load(&path).unwrap()
    }

    #[test]
    fn a_speed_takes_walkds_timing_limits_and_needs_the_dynamic_gait() {
        let file = jvrc1();
        assert_eq!(walking_speed(None, &file, Gait::Static).unwrap(), None);
        let speed = walking_speed(Some(0.2), &file, Gait::Dynamic)
            .unwrap()
            .unwrap();
        // JVRC-1's config sets no timed limits: from its single (0.55 s) and double (0.25 s)
        // support to 3 × and 4 × them.
        assert_eq!(speed.m_s, 0.2);
        let expected = [[0.55, 3.0 * 0.55], [0.25, 4.0 * 0.25]];
        assert_eq!(speed.support_limits_s, expected);
        let error = walking_speed(Some(0.2), &file, Gait::Static).unwrap_err();
        assert!(error.to_string().contains("dynamic gait"), "{error}");
    }
}
