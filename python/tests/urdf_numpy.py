"""An independent forward kinematics for the tests: the URDF's XML read with ElementTree and its
joints composed in NumPy (no KDL, no kdl_space), and the URDF's limits as written."""
import math
import xml.etree.ElementTree as ET

import numpy as np


def rpy_matrix(r, p, y):
    """URDF roll-pitch-yaw about fixed axes: Rz(y) Ry(p) Rx(r)."""
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    Rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    Ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    Rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return Rz @ Ry @ Rx


def axis_angle(axis, angle):
    """Rodrigues' rotation about the unit `axis`."""
    k = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K


def homogeneous(R, p):
    T = np.eye(4)
    T[:3, :3], T[:3, 3] = R, p
    return T


def _numbers(text, default):
    return [float(v) for v in text.split()] if text else default


def urdf_fk(path, q_by_name, world_T_base):
    """Every link's world pose {name: 4x4} for joint values by name (others 0; a mimic joint
    follows its leader), composing each joint's <origin> and its motion about <axis>."""
    robot = ET.parse(path).getroot()
    joints = robot.findall("joint")
    children = {j.find("child").get("link") for j in joints}
    root = next(l.get("name") for l in robot.findall("link") if l.get("name") not in children)
    poses = {root: world_T_base}
    pending = list(joints)
    while pending:
        j = next(j for j in pending if j.find("parent").get("link") in poses)
        pending.remove(j)
        origin = j.find("origin")
        xyz = _numbers(origin.get("xyz") if origin is not None else None, [0, 0, 0])
        rpy = _numbers(origin.get("rpy") if origin is not None else None, [0, 0, 0])
        axis = _numbers(j.find("axis").get("xyz") if j.find("axis") is not None else None, [1, 0, 0])
        q = q_by_name.get(j.get("name"), 0.0)
        mimic = j.find("mimic")
        if mimic is not None:
            q = float(mimic.get("multiplier", 1)) * q_by_name.get(mimic.get("joint"), 0.0) + float(mimic.get("offset", 0))
        motion = np.eye(4)
        if j.get("type") in ("revolute", "continuous"):
            motion[:3, :3] = axis_angle(axis, q)
        elif j.get("type") == "prismatic":
            motion[:3, 3] = q * np.asarray(axis) / np.linalg.norm(axis)
        poses[j.find("child").get("link")] = poses[j.find("parent").get("link")] @ homogeneous(rpy_matrix(*rpy), xyz) @ motion
    return poses


def urdf_limits(path):
    """{joint: (lower, upper, velocity)} of the limited joints (revolute, prismatic) of the URDF
    (velocity: inf when not given)."""
    out = {}
    for j in ET.parse(path).getroot().findall("joint"):
        limit = j.find("limit")
        if j.get("type") in ("revolute", "prismatic") and limit is not None:
            out[j.get("name")] = (float(limit.get("lower", 0)), float(limit.get("upper", 0)),
                                  float(limit.get("velocity", "inf")))
    return out
