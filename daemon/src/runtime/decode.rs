//! A sensor sample, as another process wrote it, turned into the controller's [`Measurement`]
//! or into the reason it cannot be one. Every bit pattern of a sample is a valid value of its
//! type (the contract holds no enum or bool), so this only has to check what the bits mean.

use nalgebra::{Quaternion, UnitQuaternion};
use shm_types::SensorSample;

use crate::controller::{Measurement, MeasurementFault};

/// The measurement in `sample` for a robot of `dof` joints; its values are checked by the
/// controller, its framing (joint count, flags) here.
pub fn measurement(sample: &SensorSample, dof: usize) -> Result<Measurement<'_>, MeasurementFault> {
    if sample.joint_count as usize != dof {
        return Err(MeasurementFault::JointCount(sample.joint_count));
    }
    let imu = sample.imu().map_err(|_| MeasurementFault::BadFlag {
        field: "has_imu",
        value: sample.has_imu.raw(),
    })?;
    sample.holding().map_err(|_| MeasurementFault::BadFlag {
        field: "adapter_holding",
        value: sample.adapter_holding.raw(),
    })?;
    Ok(Measurement {
        q: &sample.q[..dof],
        qd: &sample.qd[..dof],
        wrenches: &sample.wrenches,
        imu_orientation: imu
            .map(|[x, y, z, w]| UnitQuaternion::from_quaternion(Quaternion::new(w, x, y, z))),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use shm_types::Flag;

    #[test]
    fn framing_errors_are_named() {
        let mut sample = SensorSample {
            joint_count: 3,
            ..SensorSample::ZERO
        };
        assert!(measurement(&sample, 3).is_ok());
        assert_eq!(
            measurement(&sample, 4).unwrap_err(),
            MeasurementFault::JointCount(3)
        );
        // A flag byte another process could write.
        sample.has_imu = Flag::from_raw(2);
        assert_eq!(
            measurement(&sample, 3).unwrap_err(),
            MeasurementFault::BadFlag {
                field: "has_imu",
                value: 2
            }
        );
    }
}
