"""PyKDL objects in, and kdl_space's arrays out to PyKDL: the same numbers as NumPy's."""
import numpy as np
import PyKDL  # python3-pykdl (tools/deps.sh installs it)
import pytest

import kdl_space
from kdl_space.pykdl import to_frame, to_jntarray, to_rotation, to_twist, to_vector, to_wrench


def test_a_state_from_pykdl_objects_is_the_state_from_arrays(arm):
    model = arm
    frame = PyKDL.Frame(PyKDL.Rotation.RPY(0.1, -0.2, 0.3), PyKDL.Vector(1.0, 2.0, -0.5))
    twist = PyKDL.Twist(PyKDL.Vector(0.01, 0.0, -0.02), PyKDL.Vector(0.0, 0.003, 0.001))
    q = PyKDL.JntArray(model.nj)
    for i in range(model.nj):
        q[i] = 0.1 * (i + 1)
    a = kdl_space.State(model, base_pose=frame, base_twist=twist, q=q, qdot=q)
    T = np.eye(4)
    T[:3, :3] = [[frame.M[i, j] for j in range(3)] for i in range(3)]
    T[:3, 3] = [frame.p[i] for i in range(3)]
    b = kdl_space.State(model, base_pose=T, base_twist=[0.01, 0.0, -0.02, 0.0, 0.003, 0.001],
                        q=0.1 * np.arange(1, model.nj + 1), qdot=0.1 * np.arange(1, model.nj + 1))
    assert np.array_equal(a.base_pose, b.base_pose)
    assert np.array_equal(a.base_twist, b.base_twist)
    assert np.array_equal(a.q, b.q) and np.array_equal(a.qdot, b.qdot)
    solver = kdl_space.FreeFloatingSolver(model)
    solver.compute(a)
    G_a = solver.G_star(model.contact("end_effector", offset=PyKDL.Vector(0, 0, 0.05)))
    solver.compute(b)
    G_b = solver.G_star(model.contact("end_effector", offset=(0, 0, 0.05)))
    assert np.array_equal(G_a, G_b)


def test_arrays_to_pykdl_and_back():
    T = np.eye(4)
    T[:3, :3] = [[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]
    T[:3, 3] = [0.5, -1.0, 2.0]
    f = to_frame(T)
    assert isinstance(f, PyKDL.Frame)
    assert f.p[0] == 0.5 and f.p[2] == 2.0 and f.M[1, 0] == 1.0 and f.M[0, 1] == -1.0
    t = to_twist([1, 2, 3, 4, 5, 6])
    assert [t.vel[i] for i in range(3)] == [1, 2, 3] and [t.rot[i] for i in range(3)] == [4, 5, 6]
    w = to_wrench([1, 2, 3, 4, 5, 6])
    assert [w.force[i] for i in range(3)] == [1, 2, 3] and [w.torque[i] for i in range(3)] == [4, 5, 6]
    q = to_jntarray([0.5, -0.25])
    assert q.rows() == 2 and q[1] == -0.25
    assert to_vector([1, 2, 3])[1] == 2.0
    assert to_rotation(T[:3, :3])[1, 0] == 1.0


def test_a_pykdl_object_of_the_wrong_kind_names_the_argument(arm):
    model = arm
    with pytest.raises(ValueError, match="base_twist: expected shape \\(6,\\), got \\(3,\\)"):
        kdl_space.State(model, base_twist=PyKDL.Vector(1, 2, 3))
    with pytest.raises(ValueError, match="q: expected shape \\(7,\\), got \\(2,\\)"):
        kdl_space.State(model, q=to_jntarray([0.1, 0.2]))
