//! URDF → floating-base model: forward kinematics, frame and CoM Jacobians, inverse kinematics.
