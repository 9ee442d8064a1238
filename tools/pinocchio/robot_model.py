"""Load a vendored robot into Pinocchio the way the Rust `kinematics` crate sees it.

Shared by make_fixtures.py and bench.py:
- the URDF root link gets a free-flyer joint;
- mimic joints are locked at their offset (the crate treats them as fixed);
- the four end-effector frames of the config's [robot.frames] table are added as operational frames.
"""

import tomllib
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pinocchio as pin

REPO = Path(__file__).resolve().parents[2]
END_EFFECTORS = ["left_foot", "right_foot", "left_hand", "right_hand"]


def robot_section(robot: str) -> tuple[Path, dict]:
    """The config path and its [robot] table."""
    config = REPO / "configs" / f"{robot}.toml"
    with open(config, "rb") as f:
        return config, tomllib.load(f)["robot"]


def rpy_matrix(rpy) -> np.ndarray:
    """URDF fixed-axis roll-pitch-yaw: Rz(yaw) Ry(pitch) Rx(roll)."""
    return pin.rpy.rpyToMatrix(*rpy)


def load(robot: str):
    """(model, urdf path, frame specs, mimic joint names) for a robot with a URDF in its config."""
    config, section = robot_section(robot)
    urdf = (config.parent / section["urdf"]).resolve()
    full = pin.buildModelFromUrdf(str(urdf), pin.JointModelFreeFlyer())
    mimic = {}
    for joint in ET.parse(urdf).getroot().findall("joint"):
        element = joint.find("mimic")
        if element is not None:
            mimic[joint.get("name")] = float(element.get("offset", "0"))
    reference = pin.neutral(full)
    locked = []
    for name, offset in mimic.items():
        jid = full.getJointId(name)
        reference[full.joints[jid].idx_q] = offset
        locked.append(jid)
    model = pin.buildReducedModel(full, locked, reference) if locked else full
    frames = []
    for name in END_EFFECTORS:
        spec = section["frames"][name]
        translation = spec.get("translation", [0.0, 0.0, 0.0])
        rpy = spec.get("rpy", [0.0, 0.0, 0.0])
        body = model.getFrameId(spec["link"], pin.FrameType.BODY)
        parent = model.frames[body]
        offset = pin.SE3(rpy_matrix(rpy), np.array(translation, dtype=float))
        model.addFrame(
            pin.Frame(name, parent.parentJoint, body, parent.placement * offset, pin.FrameType.OP_FRAME)
        )
        frames.append({"name": name, "link": spec["link"], "translation": translation, "rpy": rpy})
    return model, urdf, frames, sorted(mimic)


def link_names(urdf: Path) -> list[str]:
    """Every <link> of the URDF, in file order."""
    return [link.get("name") for link in ET.parse(urdf).getroot().findall("link")]
