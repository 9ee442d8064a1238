#!/usr/bin/env python3
"""Reference kinematics from Pinocchio for the Rust tests (kinematics/tests/pinocchio.rs).

Usage:  pip install pin==4.1.0 && python3 tools/pinocchio/make_fixtures.py
Writes kinematics/tests/fixtures/<robot>.json for armar4 and jvrc1: seeded random configurations
(joints uniform within limits, random base poses) with every link pose, the four end-effector
frame poses, the CoM, the frame Jacobians and the CoM Jacobian, all in the crate's convention:

  nu = (v, w, qdot), v = linear velocity of the base origin in the WORLD frame, w = base angular
  velocity in the WORLD frame. Pinocchio's free-flyer velocity is in the base LOCAL frame
  (v_local = R^T v, w_local = R^T w), so its base columns are multiplied by R^T. The output side is
  Pinocchio's LOCAL_WORLD_ALIGNED (frame-origin velocity and angular velocity in world axes).

Joint columns are written in Pinocchio's joint order, named in "joint_names"; the test maps them
to the crate's order by name. Rotations are quaternions [x, y, z, w].
"""

import hashlib
import json
import sys
from pathlib import Path

import numpy as np
import pinocchio as pin

sys.path.insert(0, str(Path(__file__).resolve().parent))
import robot_model  # noqa: E402

SAMPLES = 120
SEEDS = {"armar4": 4, "jvrc1": 1}
OUT = robot_model.REPO / "kinematics" / "tests" / "fixtures"


def pose(placement: pin.SE3) -> list[float]:
    """[tx, ty, tz, qx, qy, qz, qw]."""
    return [*placement.translation.tolist(), *pin.Quaternion(placement.rotation).coeffs().tolist()]


def random_configuration(model: pin.Model, rng: np.random.Generator) -> np.ndarray:
    q = pin.neutral(model)
    q[:3] = rng.uniform(-1.0, 1.0, 3)
    quaternion = rng.normal(size=4)
    q[3:7] = quaternion / np.linalg.norm(quaternion)
    for jid in range(2, model.njoints):
        joint = model.joints[jid]
        lower = model.lowerPositionLimit[joint.idx_q]
        upper = model.upperPositionLimit[joint.idx_q]
        q[joint.idx_q] = rng.uniform(lower, upper)
    return q


def to_world_base(jacobian: np.ndarray, rotation: np.ndarray) -> np.ndarray:
    """Re-express the free-flyer columns for a world-frame base twist."""
    out = jacobian.copy()
    out[:, 0:3] = jacobian[:, 0:3] @ rotation.T
    out[:, 3:6] = jacobian[:, 3:6] @ rotation.T
    return out


def fixture(robot: str) -> dict:
    model, urdf, frames, mimic = robot_model.load(robot)
    data = model.createData()
    links = robot_model.link_names(urdf)
    link_frames = [model.getFrameId(name, pin.FrameType.BODY) for name in links]
    ee_frames = [model.getFrameId(f["name"]) for f in frames]
    joint_names = [model.names[jid] for jid in range(2, model.njoints)]
    assert all(model.joints[jid].nv == 1 for jid in range(2, model.njoints)), "1-dof joints only"
    rng = np.random.default_rng(SEEDS[robot])
    samples = []
    for _ in range(SAMPLES):
        q = random_configuration(model, rng)
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        com = pin.centerOfMass(model, data, q, False)
        com_jacobian = pin.jacobianCenterOfMass(model, data, q, False)
        base_rotation = data.oMi[1].rotation
        jacobians = []
        for fid in ee_frames:
            jacobian = pin.getFrameJacobian(model, data, fid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
            jacobians.append(to_world_base(jacobian, base_rotation).tolist())
        samples.append(
            {
                "base": pose(data.oMi[1]),
                "joints": q[7:].tolist(),
                "link_poses": [pose(data.oMf[fid]) for fid in link_frames],
                "frame_poses": [pose(data.oMf[fid]) for fid in ee_frames],
                "com": com.tolist(),
                "frame_jacobians": jacobians,
                "com_jacobian": to_world_base(com_jacobian, base_rotation).tolist(),
            }
        )
    return {
        "robot": robot,
        "urdf": str(urdf.relative_to(robot_model.REPO)),
        "urdf_sha256": hashlib.sha256(urdf.read_bytes()).hexdigest(),
        "generator": f"tools/pinocchio/make_fixtures.py, pinocchio {pin.__version__}",
        "seed": SEEDS[robot],
        "total_mass": float(sum(inertia.mass for inertia in model.inertias)),
        "mimic_joints_locked": mimic,
        "joint_names": joint_names,
        "frames": frames,
        "links": links,
        "samples": samples,
    }


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    for robot in SEEDS:
        path = OUT / f"{robot}.json"
        path.write_text(json.dumps(fixture(robot), separators=(",", ":")) + "\n")
        print(f"{path}: {path.stat().st_size / 1e6:.2f} MB")


if __name__ == "__main__":
    main()
