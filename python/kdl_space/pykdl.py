"""kdl_space and PyKDL (Debian's python3-pykdl).

Every argument of kdl_space that takes an array also takes the PyKDL object of the same meaning:
a ``PyKDL.Vector`` as (3,), a ``Twist`` as (vel; rot) (6,), a ``Wrench`` as (force; torque) (6,),
a ``Rotation`` as (3, 3), a ``Frame`` as its 4x4 homogeneous matrix (e.g. ``base_pose``), a
``JntArray`` as (n,) in the model's joint order. The functions here go the other way: kdl_space's
arrays to PyKDL objects.

    import PyKDL, kdl_space
    from kdl_space.pykdl import to_frame, to_twist
    state = kdl_space.State(model, base_pose=PyKDL.Frame(PyKDL.Rotation.RPY(0, 0, 0.3), PyKDL.Vector(1, 0, 0)))
    pose = to_frame(state.base_pose)        # PyKDL.Frame
"""

import numpy as _np


def _kdl():
    import PyKDL  # python3-pykdl; imported when used, so kdl_space works without it

    return PyKDL


def to_vector(v):
    """A (3,) array as a PyKDL.Vector."""
    v = _np.asarray(v, dtype=float).reshape(3)
    return _kdl().Vector(*v)


def to_rotation(R):
    """A (3, 3) rotation matrix as a PyKDL.Rotation."""
    R = _np.asarray(R, dtype=float).reshape(3, 3)
    return _kdl().Rotation(*R.ravel())


def to_frame(T):
    """A 4x4 homogeneous matrix as a PyKDL.Frame."""
    T = _np.asarray(T, dtype=float).reshape(4, 4)
    return _kdl().Frame(to_rotation(T[:3, :3]), to_vector(T[:3, 3]))


def to_twist(t):
    """A twist (v; w) (6,) as a PyKDL.Twist(vel, rot)."""
    t = _np.asarray(t, dtype=float).reshape(6)
    return _kdl().Twist(to_vector(t[:3]), to_vector(t[3:]))


def to_wrench(w):
    """A wrench (f; n) (6,) as a PyKDL.Wrench(force, torque)."""
    w = _np.asarray(w, dtype=float).reshape(6)
    return _kdl().Wrench(to_vector(w[:3]), to_vector(w[3:]))


def to_jntarray(q):
    """An (n,) array of joint values as a PyKDL.JntArray (same order)."""
    q = _np.asarray(q, dtype=float).reshape(-1)
    a = _kdl().JntArray(len(q))
    for i, x in enumerate(q):
        a[i] = float(x)
    return a
