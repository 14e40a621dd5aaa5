"""Forward dynamics and the simulator from Python: the two forward-dynamics routes agree and
conserve the momentum; a run keeps the momentum, equals the command-line tool's run of the same
scenario, and drives a Python controller at a control rate (zero-order hold); errors, shapes,
names and reference counts."""
import gc
import json
import resource
import subprocess
import sys
import tracemalloc

import numpy as np
import pytest

import kdl_space
from conftest import CAPTURE_SCENARIO, on_two_threads

Q = {"joint1": 0.3, "joint2": 0.7, "joint3": -0.4, "joint4": 0.8, "joint5": 0.2, "joint6": -0.6, "joint7": 0.1}
QDOT = {"joint1": 0.05, "joint2": -0.04, "joint4": 0.06, "joint6": 0.03, "joint7": -0.08}
TWIST = [0.002, -0.001, 0.003, 0.01, -0.02, 0.015]


def moving(model, **kw):
    return kdl_space.State(model, q=Q, qdot=QDOT, base_twist=TWIST,
                           base_pose=([0.1, -0.2, 0.3], [0.2, -0.1, 0.4]), **kw)


def skew(w):
    return np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])


def rotation(v):
    """exp([v]) by Rodrigues."""
    a = np.linalg.norm(v)
    if a == 0:
        return np.eye(3)
    K = skew(v / a)
    return np.eye(3) + np.sin(a) * K + (1 - np.cos(a)) * K @ K


# -- forward dynamics ---------------------------------------------------------------------------

def test_forward_dynamics_routes_agree(arm):
    state = moving(arm)
    tau = np.linspace(-3.0, 4.0, arm.nj)
    wrenches = {"link4": [1.0, -2.0, 0.5, 0.1, 0.2, -0.3], "satellite": [0.0, 3.0, 0.0, 0.4, 0.0, 0.0]}
    for kw in ({}, {"gravity": [0, 0, -9.81]}, {"locked": ["joint3", "joint5"]}):
        rec = kdl_space.ForwardDynamicsSolver(arm, **kw)
        dense = kdl_space.DenseForwardDynamicsSolver(arm, **kw)
        a1, qdd1 = rec.accelerations(state, tau=tau, wrenches=wrenches)
        a2, qdd2 = dense.accelerations(state, tau=tau, wrenches=wrenches)
        assert a1.shape == (6,) and qdd1.shape == (arm.nj,)
        scale = max(1.0, np.abs(qdd1).max(), np.abs(a1).max())
        assert np.abs(a1 - a2).max() <= 1e-10 * scale, kw
        assert np.abs(qdd1 - qdd2).max() <= 1e-10 * scale, kw
    locked = kdl_space.ForwardDynamicsSolver(arm, locked=["joint3", "joint5"])
    assert locked.locked == ["joint3", "joint5"]
    _, qdd = locked.accelerations(state, tau=tau)
    assert qdd[2] == 0.0 and qdd[4] == 0.0
    # grounded: the base still, fixed-base dynamics (the base twist must be zero)
    ground = kdl_space.State(arm, q=Q, qdot=QDOT)
    g1 = kdl_space.ForwardDynamicsSolver(arm, grounded=True).accelerations(ground, tau=tau)
    g2 = kdl_space.DenseForwardDynamicsSolver(arm, grounded=True).accelerations(ground, tau=tau)
    assert np.array_equal(g1[0], np.zeros(6))
    assert np.abs(g1[1] - g2[1]).max() <= 1e-10 * max(1.0, np.abs(g2[1]).max())  # relative, as above
    with pytest.raises(kdl_space.ComputeError) as e:
        kdl_space.ForwardDynamicsSolver(arm, grounded=True).accelerations(state)
    assert e.value.code == kdl_space.E_BAD_ARGUMENT


def advance(model, state, accelerations, dt):
    """The state dt later to second order in dt (positions) and first order (velocities)."""
    a, qdd = accelerations
    T = state.base_pose
    v, w = state.base_twist[:3], state.base_twist[3:]
    pose = np.eye(4)
    pose[:3, 3] = T[:3, 3] + v * dt + 0.5 * a[:3] * dt * dt
    pose[:3, :3] = rotation(w * dt + 0.5 * a[3:] * dt * dt) @ T[:3, :3]
    return kdl_space.State(model, q=state.q + state.qdot * dt + 0.5 * qdd * dt * dt, base_pose=pose,
                           base_twist=state.base_twist + a * dt, qdot=state.qdot + qdd * dt)


@pytest.mark.parametrize("solver_class", ["ForwardDynamicsSolver", "DenseForwardDynamicsSolver"])
def test_accelerations_reproduce_the_momentum_balance(arm, solver_class):
    """The accelerations from joint torques keep (P; L) still; a wrench changes it at its own rate."""
    fd = getattr(kdl_space, solver_class)(arm)
    sim = kdl_space.Simulator(arm)
    state = moving(arm)
    tau = np.array([3.0, -2.0, 1.5, 1.0, 0.3, -0.2, 0.05])  # moderate accelerations: a small truncation error
    f = np.array([2.0, -1.0, 0.5, 0.3, -0.2, 0.1])

    def rate(acc, dt=1e-5):
        hp = sim.energy_and_momentum(advance(arm, state, acc, dt))[1]
        hm = sim.energy_and_momentum(advance(arm, state, acc, -dt))[1]
        return (hp - hm) / (2 * dt)

    acc = fd.accelerations(state, tau=tau)
    wrong = (np.zeros(6), acc[1])  # the joints' motion with the base held: the momentum would change
    assert np.linalg.norm(rate(acc)) < 1e-6 * np.linalg.norm(rate(wrong))
    # a wrench on the base (moment about its frame's origin) changes (P; L about O) by (f; p_b x f + n)
    acc = fd.accelerations(state, tau=tau, wrenches={arm.link_names[0]: f})
    p_b = state.base_pose[:3, 3]
    expected = np.concatenate([f[:3], np.cross(p_b, f[:3]) + f[3:]])
    assert np.abs(rate(acc) - expected).max() < 1e-6 * np.abs(expected).max()
    assert np.abs(rate((acc[0] * 1.001, acc[1])) - expected).max() > 1e-4 * np.abs(expected).max()  # it can tell


def test_forward_dynamics_errors(arm):
    fd = kdl_space.ForwardDynamicsSolver(arm)
    with pytest.raises(ValueError, match=r"tau: expected shape \(7,\), got \(3,\)"):
        fd.accelerations(moving(arm), tau=[1, 2, 3])
    with pytest.raises(kdl_space.ComputeError) as e:
        fd.accelerations(kdl_space.State(arm, q=np.full(arm.nj, np.nan)))
    assert e.value.code == kdl_space.E_NOT_FINITE
    with pytest.raises(kdl_space.ModelError, match="no link named 'nowhere'"):
        fd.accelerations(moving(arm), wrenches={"nowhere": np.zeros(6)})
    with pytest.raises(kdl_space.ModelError, match="no joint named 'jointX'"):
        kdl_space.DenseForwardDynamicsSolver(arm, locked=["jointX"])
    with pytest.raises(kdl_space.ModelError, match=r"setGravity: the gravity \(0, nan, 0\) m/s\^2 is not finite"):
        fd.gravity = [0, np.nan, 0]
    assert np.array_equal(fd.gravity, [0, 0, 0])  # a set-up call: refused, nothing changed
    fd.gravity = [0, 0, -1.62]
    assert np.array_equal(fd.gravity, [0, 0, -1.62])
    assert "ForwardDynamicsSolver" in repr(fd) and "7 joints" in repr(fd)


# -- the simulator ------------------------------------------------------------------------------

def test_free_run_keeps_the_momentum_and_shapes(arm):
    sim = kdl_space.Simulator(arm, integrator="dopri5")
    run = sim.run(moving(arm), t_end=2.0, output_dt=0.1)
    k, n = 21, arm.nj
    assert len(run) == k and run.joint_names == arm.joint_names
    shapes = {"t": (k,), "base_position": (k, 3), "base_quaternion": (k, 4), "base_twist": (k, 6), "q": (k, n),
              "qdot": (k, n), "tau": (k, n), "base_wrench": (k, 6), "momentum": (k, 6), "energy": (k,),
              "impulse": (k, 6)}
    for name, shape in shapes.items():
        a = getattr(run, name)
        assert a.shape == shape and a.dtype == np.float64, name
    assert sorted(run.work) == sorted(["controller", "friction", "limits", "base_control", "wrenches", "gravity"])
    assert all(w.shape == (k,) for w in run.work.values())
    assert np.allclose(run.t, np.linspace(0, 2, k), rtol=0, atol=1e-12) and run.final_t == 2.0
    assert np.allclose(np.linalg.norm(run.base_quaternion, axis=1), 1.0, atol=1e-14)
    h0 = run.momentum[0]
    assert np.abs(run.momentum - h0).max() <= 1e-9 * np.abs(h0).max()
    assert np.array_equal(run.final_state.q, run.q[-1]) and np.array_equal(run.final_state.qdot, run.qdot[-1])
    assert run.stats.accepted_steps > 0 and sorted(run.stats.joints) == sorted(arm.joint_names)
    assert "21 samples" in repr(run) and "q (21, 7)" in repr(run)
    assert "Simulator" in repr(sim) and "dopri5" in repr(sim)
    # the energy is kept too without friction or controls (the arm's joints have no damping)
    assert np.abs(run.energy - run.energy[0]).max() <= 1e-8 * run.energy[0]


def test_options_controls_and_queries(arm):
    sim = kdl_space.Simulator(arm, integrator=kdl_space.Integrator.RK4, step=2e-3, gravity=[0, 0, -1.0])
    assert sim.options["integrator"] == "rk4" and sim.options["step"] == 2e-3
    assert np.array_equal(sim.options["gravity"], [0, 0, -1.0])
    sim.set_joint_control("joint2", "pd", kp=40.0, kd=10.0, set_point=0.5)
    sim.set_joint_control(0, "locked")
    sim.set_joint_control("joint3", "hold", kp=5.0, kd=1.0)
    c = sim.joint_controls
    assert c["joint2"] == {"mode": "pd", "kp": 40.0, "kd": 10.0, "set_point": 0.5}
    assert c["joint1"]["mode"] == "locked" and c["joint3"]["mode"] == "hold" and c["joint7"]["mode"] == "free"
    sim.set_limit_mode("joint4", "stop")
    assert sim.limit_modes["joint4"] == "stop" and sim.limit_modes["joint1"] == "warn"
    state = sim.engage_brakes(moving(arm))
    assert state.qdot[0] == 0.0
    T, h = sim.energy_and_momentum(state)
    assert T > 0 and h.shape == (6,)
    st = sim.stiffness(state)
    assert st.fastest_joint in ("joint2", "joint3") and st.fastest_rate > 0 and st.explicit_step > 0
    assert sim.apparent_inertia(state, "joint2") > 0
    with pytest.raises(kdl_space.ComputeError):
        sim.apparent_inertia(state, "joint1")  # braked
    sim.set_base_control(attitude={"kp": 10.0, "kd": 20.0, "hold": True, "torque_limit": [1, 1, 1]})
    with pytest.raises(ValueError, match="unknown key 'kq'"):
        sim.set_base_control(position={"kq": 1.0})
    with pytest.raises(kdl_space.ModelError):
        sim.set_joint_control("joint2", "pd", kp=-1.0)
    with pytest.raises(kdl_space.ModelError, match="no joint named 'elbow'"):
        sim.set_joint_control("elbow", "free")
    with pytest.raises(IndexError):
        sim.set_limit_mode(7, "warn")
    with pytest.raises(ValueError, match="mode: expected"):
        sim.set_joint_control("joint2", "servo")
    with pytest.raises(ValueError, match="integrator: 'euler' is not one of rk4, dopri5, rosenbrock"):
        kdl_space.Simulator(arm, integrator="euler")
    with pytest.raises(kdl_space.ModelError):
        kdl_space.Simulator(arm, step=-1.0)
    run = sim.run(state, t_end=0.2, output_dt=0.05)
    assert np.all(run.qdot[:, 0] == 0.0)  # braked all along
    assert np.abs(run.base_wrench).max() > 0  # the attitude control acts
    assert sim.friction_velocities.shape == (arm.nj,)


def test_a_wrench_changes_the_momentum_by_its_impulse(arm):
    sim = kdl_space.Simulator(arm)
    f = np.array([3.0, 0.0, -1.0, 0.0, 0.5, 0.0])
    sim.add_wrench("link3", f, point=[0.0, 0.0, 0.1], start=0.1, end=0.3)
    run = sim.run(moving(arm), t_end=0.5, output_dt=0.05)
    assert np.abs(run.momentum - run.momentum[0] - run.impulse).max() <= 1e-9 * np.abs(run.momentum).max()
    assert np.allclose(run.impulse[-1, :3], 0.2 * f[:3], rtol=1e-12, atol=1e-12)


def test_run_matches_the_tool(cli, source_dir):
    out = subprocess.run([cli, "simulate", str(CAPTURE_SCENARIO), "--duration", "2", "--json"], check=True,
                         capture_output=True, text=True, cwd=source_dir)
    j = json.loads(out.stdout)["simulation"]
    scenario = kdl_space.load_scenario(str(CAPTURE_SCENARIO))
    result = kdl_space.solve_capture(scenario)
    model = kdl_space.attach_target(scenario, result)
    assert model.joint_names == j["joint_names"]
    before = scenario.problem.state
    start = kdl_space.State(model, q=before.q, base_pose=before.base_pose, base_twist=result.robot.base_twist_after,
                            qdot=result.robot.qdot_after)
    sim = kdl_space.Simulator.from_scenario(scenario, model)
    assert sim.joint_controls["joint2"] == {"mode": "pd", "kp": 400.0, "kd": 300.0, "set_point": 0.7}
    run = sim.run(sim.engage_brakes(start), t_end=2.0, output_dt=scenario.output_step)
    final = j["final"]
    for key, actual in (("t", run.final_t), ("base_position", run.base_position[-1]),
                        ("base_quaternion", run.base_quaternion[-1]), ("base_twist", run.base_twist[-1]),
                        ("q", run.q[-1]), ("qdot", run.qdot[-1])):
        expected = np.asarray(final[key], dtype=float)
        assert np.abs(np.asarray(actual) - expected).max() <= 1e-12 * max(1.0, np.abs(expected).max()), key
    assert run.stats.accepted_steps == j["accepted_steps"] and run.stats.rejected_steps == j["rejected_steps"]



TWO_LINKS = """<robot name="two"><link name="base"><inertial><mass value="10"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>
<link name="arm"><inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1" ixy="0" ixz="0" iyz="0"/></inertial></link>
<joint name="elbow" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
<limit lower="-3" upper="3" effort="10" velocity="1"/></joint></robot>"""


def test_from_scenario_refuses_a_model_without_the_scenarios_joints(tmp_path):
    # makeSimulator finds the scenario's joints in the model by name: a model without them is
    # refused in the scenario's terms before any is looked up (the first one its section controls).
    urdf = tmp_path / "two.urdf"
    urdf.write_text(TWO_LINKS)
    scenario = kdl_space.load_scenario(str(CAPTURE_SCENARIO))
    with pytest.raises(ValueError, match=r"^model: has no joint 'joint1' of the scenario's robot$"):
        kdl_space.Simulator.from_scenario(scenario, kdl_space.load_urdf(str(urdf)))

def pd(kp, kd, target, calls=None):
    def controller(t, q, qdot, base_pose, base_twist):
        assert q.shape == qdot.shape == target.shape and base_pose.shape == (4, 4) and base_twist.shape == (6,)
        if calls is not None:
            calls.append((t, q.copy(), qdot.copy()))
        return kp * (target - q) - kd * qdot
    return controller


def test_controller_at_a_control_rate_is_a_zero_order_hold(arm):
    sim = kdl_space.Simulator(arm, joint_friction=False, effort_limits=False)
    target = np.linspace(0.2, -0.2, arm.nj)
    # gains for a 5 rad/s loop of each joint's own inertia: stable at 100 Hz (kd T / m = 0.07)
    m = np.array([sim.apparent_inertia(moving(arm), j) for j in range(arm.nj)])
    kp, kd = 25.0 * m, 7.0 * m
    calls = []
    rate, t0, t_end = 100.0, 0.25, 0.75
    run = sim.run(moving(arm), t_end=t_end, output_dt=0.0025, controller=pd(kp, kd, target, calls),
                  control_rate=rate, t0=t0, check_gains=False)  # the run's calls alone, not the gains' probe
    # called at t0 + k / rate exactly, with the state there (the samples at those instants)
    times = np.array([c[0] for c in calls])
    assert np.allclose(times, t0 + np.arange(51) / rate, rtol=0, atol=1e-12)
    assert len(run) == 201
    for t, q, qdot in calls:
        i = int(round((t - t0) / 0.0025))
        assert abs(run.t[i] - t) <= 1e-12 and np.array_equal(run.q[i], q) and np.array_equal(run.qdot[i], qdot)
    # the torque of every sample is the command of the last control instant (hand check of the PD law)
    for i, t in enumerate(run.t):
        k = int(np.floor((t - t0) * rate + 1e-9))
        _, q, qdot = calls[k]
        assert np.array_equal(run.tau[i], kp * (target - q) - kd * qdot), i
    # piecewise constant: 4 equal samples per period, a change at each control instant
    blocks = run.tau[:200].reshape(50, 4, arm.nj)
    assert np.all(blocks == blocks[:, :1, :])
    assert np.all(np.abs(np.diff(blocks[:, 0, :], axis=0)).max(axis=1) > 0)
    # the momentum is kept (internal torques), the controller's work is the energy gained
    assert np.abs(run.momentum - run.momentum[0]).max() <= 1e-9 * np.abs(run.momentum[0]).max()
    assert np.allclose(run.energy - run.energy[0], run.work["controller"], rtol=0, atol=1e-8)
    # output_dt coarser than the period: the samples are every 5th control instant
    coarse = sim.run(moving(arm), t_end=t_end, output_dt=0.05, controller=pd(kp, kd, target), control_rate=rate,
                     t0=t0)
    assert len(coarse) == 11 and np.allclose(coarse.t, run.t[::20], rtol=0, atol=1e-12)
    assert np.abs(coarse.q - run.q[::20]).max() <= 1e-9  # the same motion, stepped on another output grid


def test_continuous_controller_equals_the_joint_servo(arm):
    """control_rate=None: called at every evaluation, the same as the C++ PD of the same gains."""
    target = np.linspace(0.2, -0.2, arm.nj)
    a = kdl_space.Simulator(arm)
    b = kdl_space.Simulator(arm)
    for j, name in enumerate(arm.joint_names):
        b.set_joint_control(name, "pd", kp=30.0, kd=8.0, set_point=target[j])
    ra = a.run(moving(arm), 0.5, 0.05, controller=pd(30.0, 8.0, target))
    rb = b.run(moving(arm), 0.5, 0.05)
    assert np.abs(ra.q - rb.q).max() <= 1e-10 and np.abs(ra.tau - rb.tau).max() <= 1e-9
    # a controller may return a dict by joint name (the others: zero)
    rc = a.run(moving(arm), 0.1, 0.05, controller=lambda t, q, qdot, pose, twist: {"joint2": 1.0})
    assert np.all(rc.tau[:, 1] == 1.0) and np.all(rc.tau[:, 0] == 0.0)


def test_controller_errors_propagate(arm):
    sim = kdl_space.Simulator(arm)

    class Boom(Exception):
        pass

    def bad(t, q, qdot, pose, twist):
        if t > 0.05:
            raise Boom("at %g" % t)
        return np.zeros(arm.nj)

    for rate in (None, 100.0):
        with pytest.raises(Boom):
            sim.run(moving(arm), 0.2, 0.01, controller=bad, control_rate=rate)
        with pytest.raises(ValueError, match=r"controller: tau: expected shape \(7,\), got \(3,\)"):
            sim.run(moving(arm), 0.2, 0.01, controller=lambda *a: np.zeros(3), control_rate=rate)
        with pytest.raises(TypeError, match="controller: tau: expected an array"):  # a wrong type
            sim.run(moving(arm), 0.2, 0.01, controller=lambda *a: None, control_rate=rate)
        with pytest.raises(ValueError, match="not finite"):
            sim.run(moving(arm), 0.2, 0.01, controller=lambda *a: np.full(arm.nj, np.nan), control_rate=rate)
    # the simulator is left usable, without the controller
    assert len(sim.run(moving(arm), 0.1, 0.05)) == 3

    def reentrant(t, q, qdot, pose, twist):
        sim.energy_and_momentum(moving(arm))
        return np.zeros(arm.nj)

    with pytest.raises(RuntimeError, match="its own controller"):
        sim.run(moving(arm), 0.1, 0.05, controller=reentrant)
    with pytest.raises(TypeError):
        sim.run(moving(arm), 0.1, 0.05, controller=42)
    with pytest.raises(ValueError, match="control_rate: given without a controller"):
        sim.run(moving(arm), 0.1, 0.05, control_rate=10.0)
    with pytest.raises(ValueError, match="control_rate: expected a finite rate"):
        sim.run(moving(arm), 0.1, 0.05, controller=lambda *a: np.zeros(arm.nj), control_rate=0.0)
    with pytest.raises(ValueError, match="not commensurate"):
        sim.run(moving(arm), 0.1, 0.05, controller=lambda *a: np.zeros(arm.nj), control_rate=1 / np.pi)


def test_run_errors(arm):
    sim = kdl_space.Simulator(arm)
    with pytest.raises(kdl_space.ComputeError) as e:
        sim.run(kdl_space.State(arm, q=np.full(arm.nj, np.nan)), 1.0, 0.1)
    assert e.value.code == kdl_space.E_NOT_FINITE and e.value.t == 0.0
    with pytest.raises(kdl_space.ComputeError) as e:
        sim.run(moving(arm), 1.0, 0.1, t0=2.0)
    assert e.value.code == kdl_space.E_BAD_ARGUMENT
    with pytest.raises(kdl_space.ComputeError) as e:
        sim.run(moving(arm), 1.0, 0.0)
    assert e.value.code == kdl_space.E_BAD_ARGUMENT
    with pytest.raises(kdl_space.ComputeError) as e:
        sim.run(moving(arm), np.nan, 0.1)
    assert e.value.code == kdl_space.E_NOT_FINITE
    other = kdl_space.load_urdf(str(CAPTURE_SCENARIO.parent.parent / "urdf" / "spacedyn_twolink.urdf"))
    with pytest.raises(ValueError, match="a state of another model"):
        sim.run(kdl_space.State(other), 1.0, 0.1)
    # the step budget: how far the run got, and its samples so far
    short = kdl_space.Simulator(arm, max_steps=30, max_step=0.01)
    with pytest.raises(kdl_space.ComputeError) as e:
        short.run(moving(arm), 5.0, 0.05)
    assert e.value.code == kdl_space.E_MAX_STEPS and 0 < e.value.t < 5.0
    assert "step budget" in str(e.value) and "at t = " in str(e.value)
    partial = e.value.result
    assert isinstance(partial, kdl_space.SimulationResult) and 0 < len(partial) and partial.t[-1] <= e.value.t


def test_threads_run_controllers_side_by_side(arm):
    def work(k):
        sim = kdl_space.Simulator(arm)
        target = np.full(arm.nj, 0.1)
        return sim.run(moving(arm), 0.5, 0.05, controller=pd(20.0, 5.0, target), control_rate=50.0).q

    first, second = on_two_threads(work)
    assert np.array_equal(first, second)


def test_no_reference_leaks(arm):
    sim = kdl_space.Simulator(arm)
    fd = kdl_space.ForwardDynamicsSolver(arm)
    state = moving(arm)
    target = np.zeros(arm.nj)
    controller = pd(10.0, 2.0, target)

    def loop(n):
        for i in range(n):
            run = sim.run(state, 0.01, 0.005, controller=controller, control_rate=200.0)
            run.q, run.work, run.final_state, run.stats.joints
            fd.accelerations(state, tau=target)
            try:
                sim.run(state, 0.01, 0.005, controller=lambda *a: np.zeros(2))
            except ValueError:
                pass

    loop(200)  # warm-up
    gc.collect()
    refs = sys.getrefcount(arm), sys.getrefcount(controller), sys.getrefcount(state)
    tracemalloc.start()
    first = tracemalloc.get_traced_memory()[0]
    loop(3000)
    gc.collect()
    grown = tracemalloc.get_traced_memory()[0] - first
    tracemalloc.stop()
    assert grown < 100_000, grown
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss  # and the C++ allocations: kB
    loop(3000)
    assert resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - peak < 8 * 1024
    assert (sys.getrefcount(arm), sys.getrefcount(controller), sys.getrefcount(state)) == refs


def test_ctrl_c_ends_a_run_at_the_next_output_sample(arm):
    """SIGINT during a long run without a controller (and during run_operation) raises
    KeyboardInterrupt at the next output sample, not at the end of the run."""
    import os
    import signal
    import threading
    import time

    sim = kdl_space.Simulator(arm, integrator="rk4", step=1e-3, max_steps=10**9)
    state = kdl_space.State(arm, qdot=np.full(arm.nj, 0.1))
    scenario = kdl_space.load_scenario(str(CAPTURE_SCENARIO))
    for run in (lambda: sim.run(state, t_end=1e4, output_dt=0.01),  # some 40 s of CPU if not interrupted
                lambda: kdl_space.run_operation(scenario, duration=4e4)):  # within its step budget
        timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
        start = time.monotonic()
        timer.start()
        with pytest.raises(KeyboardInterrupt):
            run()
        timer.join()
        assert time.monotonic() - start < 10.0  # (a KeyboardInterrupt after the run would come too late)
    assert len(sim.run(state, t_end=0.02, output_dt=0.01)) == 3  # usable after it


def interrupt_after(seconds, run):
    """Runs `run()` with SIGINT sent to this process after `seconds`; the seconds from the signal
    to the KeyboardInterrupt."""
    import os
    import signal
    import threading
    import time

    sent = []
    timer = threading.Timer(seconds, lambda: (sent.append(time.monotonic()), os.kill(os.getpid(), signal.SIGINT)))
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            run()
    finally:
        timer.cancel()
        timer.join()
    assert sent, "the run ended before the signal"
    return time.monotonic() - sent[0]


def test_ctrl_c_ends_a_run_within_half_a_second_however_rare_its_samples(arm):
    """Samples only at the start and the end of 1e4 s (minutes of CPU): Ctrl-C is seen between them,
    without a controller and with one sampled every 1000 s."""
    sim = kdl_space.Simulator(arm, integrator="rk4", step=1e-3, max_steps=10**9)
    state = kdl_space.State(arm, qdot=np.full(arm.nj, 0.1))
    latency = interrupt_after(1.0, lambda: sim.run(state, t_end=1e4, output_dt=1e4))
    assert latency < 0.5
    latency = interrupt_after(1.0, lambda: sim.run(state, t_end=1e4, output_dt=1e4, controller=lambda *a: np.zeros(arm.nj),
                                                   control_rate=1e-3))
    assert latency < 0.5
    assert len(sim.run(state, t_end=0.02, output_dt=0.01)) == 3  # usable after it


def test_a_run_that_would_keep_more_samples_than_max_output_rows_is_refused(arm):
    """Every sample is kept: t0, every output_dt, t_end (by hand: 1 s at 0.01 s is 101 samples)."""
    sim = kdl_space.Simulator(arm)
    state = kdl_space.State(arm)
    with pytest.raises(ValueError, match=r"up to 101 samples in memory, more than max_output_rows = 100: give a coarser output_dt"):
        sim.run(state, t_end=1.0, output_dt=0.01, max_output_rows=100)
    assert len(sim.run(state, t_end=1.0, output_dt=0.01, max_output_rows=101)) == 101
    # The default (10 million) refuses 1e5 s at 1e-4 s before any step.
    with pytest.raises(ValueError, match=r"up to 1000000001 samples in memory, more than max_output_rows = 10000000"):
        sim.run(state, t_end=1e5, output_dt=1e-4)


def test_sampled_pd_with_a_continuous_servos_gains_is_warned(arm):
    """A PD at 200 Hz with the gains of a continuous servo (kd / m of the wrist some 10^3 1/s) once
    diverged without a word: each joint where kd / (rate m) exceeds 1 (m = 1 / (H*^-1)_jj, from
    NumPy here) is warned about by name before the run, in result.warnings and as a
    RuntimeWarning; at a rate fast enough, nothing; check_gains=False: no probe."""
    sim = kdl_space.Simulator(arm, joint_friction=False, effort_limits=False)
    start = moving(arm)
    solver = kdl_space.FreeFloatingSolver(arm)
    solver.compute(start)
    m = 1.0 / np.diag(np.linalg.inv(solver.H_star))
    kp, kd, rate = 400.0, 300.0, 200.0  # stiff_wrist_servo.yaml's servo gains
    expected = [name for name, mj in zip(arm.joint_names, m) if kd / (rate * mj) > 1.0]
    assert 0 < len(expected) < arm.nj and max(kd / m) > 2000.0  # the wrist: kd / m in the thousands
    target = np.zeros(arm.nj)
    with pytest.warns(RuntimeWarning, match="sampled_gain_unstable") as caught:
        try:
            run = sim.run(start, 0.2, 0.05, controller=pd(kp, kd, target), control_rate=rate)
            warned = run.warnings
        except kdl_space.ComputeError as e:  # it blows up: the warnings came before
            warned = e.result.warnings
    assert [w["element"] for w in warned] == expected
    assert all(w["kind"] == "sampled_gain_unstable" and "200 Hz" in w["message"] for w in warned)
    assert sorted(str(w.message).split(": ")[1] for w in caught if "sampled_gain_unstable" in str(w.message)) == sorted(expected)
    # Fast enough for every joint: quiet, and the probe leaves the motion as it was.
    fast = 1000.0 * np.ceil(max(kd / m) / 1000.0)
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        checked = sim.run(start, 0.02, 0.005, controller=pd(kp, kd, target), control_rate=fast)
    unchecked = sim.run(start, 0.02, 0.005, controller=pd(kp, kd, target), control_rate=fast, check_gains=False)
    assert checked.warnings == [] and np.array_equal(checked.q, unchecked.q)
