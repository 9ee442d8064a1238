#!/usr/bin/env python3
"""Time Pinocchio on the work of the crate's criterion benchmark (kinematics/benches/kinematics.rs).

One iteration: forward kinematics of all joints and link frames, the CoM, the four end-effector
frame Jacobians (LOCAL_WORLD_ALIGNED) and the CoM Jacobian. Call sequence (the cheapest correct
one): computeJointJacobians (includes forward kinematics) -> updateFramePlacements ->
jacobianCenterOfMass(model, data) (reuses the joint Jacobians, also yields the CoM) ->
getFrameJacobian x4.

Two numbers are printed per robot:
- python: the sequence called from Python (includes ~8 Python->C++ call overheads);
- c++: the same sequence compiled from bench.cpp against the wheel's headers, if a C++ compiler
  and the Eigen headers (PyPI `cmeel-eigen`) are available. This is the number to compare with.

Usage:  pip install pin==4.1.0 cmeel-eigen && python3 tools/pinocchio/bench.py
"""

import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import pinocchio as pin

sys.path.insert(0, str(Path(__file__).resolve().parent))
import robot_model  # noqa: E402

HERE = Path(__file__).resolve().parent
ROBOTS = ["armar4", "jvrc1"]


def configuration(model: pin.Model) -> np.ndarray:
    rng = np.random.default_rng(7)
    q = pin.randomConfiguration(model, model.lowerPositionLimit.clip(-3, 3), model.upperPositionLimit.clip(-3, 3))
    q[3:7] = rng.normal(size=4)
    q[3:7] /= np.linalg.norm(q[3:7])
    return q


def time_python(model: pin.Model, frames: list[int], q: np.ndarray, repetitions: int = 50_000) -> float:
    data = model.createData()
    lwa = pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
    best = float("inf")
    for _ in range(5):
        start = time.perf_counter()
        for _ in range(repetitions):
            pin.computeJointJacobians(model, data, q)
            pin.updateFramePlacements(model, data)
            pin.jacobianCenterOfMass(model, data, False)
            for fid in frames:
                pin.getFrameJacobian(model, data, fid, lwa)
        best = min(best, (time.perf_counter() - start) / repetitions)
    return best


def build_cpp(workdir: Path) -> Path | None:
    prefix = Path(pin.__file__).resolve()
    while prefix.name != "cmeel.prefix" and prefix != prefix.parent:
        prefix = prefix.parent
    if not (prefix / "include" / "eigen3").exists():
        print("c++: skipped (no Eigen headers; pip install cmeel-eigen)")
        return None
    binary = workdir / "pinocchio_bench"
    command = [
        "c++", "-O3", "-DNDEBUG", "-std=c++17",
        # The definitions pinocchio's CMake config exports to its users.
        "-DBOOST_MPL_LIMIT_LIST_SIZE=30", "-DBOOST_MPL_LIMIT_VECTOR_SIZE=30",
        "-DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS", "-DBOOST_FUSION_INVOKE_MAX_ARITY=12", str(HERE / "bench.cpp"), "-o", str(binary),
        f"-I{prefix / 'include'}", f"-I{prefix / 'include' / 'eigen3'}",
        f"-L{prefix / 'lib'}", "-lpinocchio_default", "-lboost_serialization", f"-Wl,-rpath,{prefix / 'lib'}",
    ]
    subprocess.run(command, check=True)
    return binary


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        binary = build_cpp(Path(tmp))
        for robot in ROBOTS:
            model, urdf, frames, mimic = robot_model.load(robot)
            frame_ids = [model.getFrameId(f["name"]) for f in frames]
            q = configuration(model)
            print(f"{robot}: python {time_python(model, frame_ids, q) * 1e6:.2f} us/iteration (pinocchio {pin.__version__})")
            if binary is not None:
                saved = Path(tmp) / f"{robot}.bin"
                model.saveToBinary(str(saved))
                args = [str(binary), str(saved), *(f["name"] for f in frames)]
                print(f"{robot}: " + subprocess.run(args, check=True, capture_output=True, text=True).stdout.strip())


if __name__ == "__main__":
    main()
