# %% [markdown]
# # The README's capture, and the motion after it
#
# A 50 kg box tumbling at a few degrees per second is grasped rigidly by the default arm's end
# effector (`scenarios/tumbling_box_capture.yaml`, the README's example). We solve the capture,
# attach the box to the hand, and integrate the next seconds with the scenario's joint servos;
# then the same motion with the servos replaced by a digital PD controller in Python, at 50 Hz.
#
# Plain Python with `# %%` cells (VS Code, Jupyter's jupytext, Spyder run them one by one);
# `python3 examples/notebook.py` runs it all. The figures go to `$KDL_SPACE_FIGURES`
# (default: `figures/` here); `$KDL_SPACE_DURATION` is the motion's length [s] (default 10). Needs
# `PYTHONPATH=build/python` (README, "Python").

# %%
import os
import pathlib
import sys

import matplotlib

INTERACTIVE = hasattr(sys, "ps1") or "ipykernel" in sys.modules
if not INTERACTIVE:
    matplotlib.use("Agg")  # a script: files only, no window
import matplotlib.pyplot as plt
import numpy as np

import kdl_space

ROOT = pathlib.Path(__file__).resolve().parents[1] if "__file__" in globals() else pathlib.Path.cwd()
FIGURES = pathlib.Path(os.environ.get("KDL_SPACE_FIGURES", "figures"))
FIGURES.mkdir(parents=True, exist_ok=True)
DURATION = float(os.environ.get("KDL_SPACE_DURATION", "10"))  # [s] of motion after the capture

# %% The capture (the README's example)
scenario = kdl_space.load_scenario(str(ROOT / "scenarios" / "tumbling_box_capture.yaml"))
capture = kdl_space.solve_capture(scenario)
print("impulse (f; n):", capture.impulse.F, " energy lost:", capture.energy_lost, "J")
print(dict(zip(capture.robot.joint_names, capture.robot.qdot_after)))

# %% The motion after it: the box is part of the hand, the scenario's servos hold the arm
model = kdl_space.attach_target(scenario, capture)
before = scenario.problem.state
after = kdl_space.State(model, q=before.q, base_pose=before.base_pose,
                        base_twist=capture.robot.base_twist_after, qdot=capture.robot.qdot_after)
simulator = kdl_space.Simulator.from_scenario(scenario, model)
motion = simulator.run(after, t_end=DURATION, output_dt=scenario.output_step)
print(motion, motion.stats)
print("momentum change over the run:", np.abs(motion.momentum - motion.momentum[0]).max())

# %% The same hold by a digital PD controller in Python, at 50 Hz (zero-order hold)
gains = {name: (c["kp"], c["kd"], c["set_point"]) for name, c in simulator.joint_controls.items()}
kp, kd, set_point = (np.array([gains[n][i] for n in model.joint_names]) for i in range(3))


def digital_pd(t, q, qdot, base_pose, base_twist):
    return kp * (set_point - q) - kd * qdot


free = kdl_space.Simulator(model)  # joints free: the Python controller drives them
digital = free.run(after, t_end=DURATION, output_dt=scenario.output_step, controller=digital_pd, control_rate=50.0)
print(digital)


# %% Plots: the base's attitude rate, the joint rates, the momentum
def plot(run, title, path):
    fig, axes = plt.subplots(3, 1, figsize=(8, 9), sharex=True)
    w = run.base_twist[:, 3:]
    for i, axis in enumerate("xyz"):
        axes[0].plot(run.t, np.degrees(w[:, i]), label=f"$\\omega_{axis}$")
    axes[0].plot(run.t, np.degrees(np.linalg.norm(w, axis=1)), "k--", label="$|\\omega|$")
    axes[0].set_ylabel("base attitude rate [deg/s]")
    for j, name in enumerate(run.joint_names):
        axes[1].plot(run.t, run.qdot[:, j], label=name)
    axes[1].set_ylabel("joint rate [rad/s]")
    labels = ["$P_x$", "$P_y$", "$P_z$", "$L_x$", "$L_y$", "$L_z$"]
    for i in range(6):
        axes[2].plot(run.t, run.momentum[:, i] - run.momentum[0, i], label=labels[i])
    axes[2].set_ylabel("momentum change [N s, N m s]")
    axes[2].set_xlabel("time after the capture [s]")
    for a in axes:
        a.grid(True, alpha=0.3)
        a.legend(fontsize=7, ncol=4, loc="upper right")
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    return fig


plot(motion, "tumbling_box_capture: after the capture (the scenario's servos)", FIGURES / "capture_motion.png")
plot(digital, "the same with a Python PD at 50 Hz", FIGURES / "capture_motion_digital_pd.png")
# the first half second sampled finer than the control period: the torque's steps at k / 50 s
zoom = free.run(after, t_end=0.5, output_dt=0.005, controller=digital_pd, control_rate=50.0)
fig, ax = plt.subplots(figsize=(8, 3))
for j, name in enumerate(zoom.joint_names):
    ax.plot(zoom.t, zoom.tau[:, j], ".-", ms=3, label=name)
ax.set_xlabel("time after the capture [s]")
ax.set_ylabel("joint torque [N m]")
ax.set_title("the digital PD's torques: held between control instants")
ax.legend(fontsize=7, ncol=4)
fig.tight_layout()
fig.savefig(FIGURES / "digital_pd_torques.png", dpi=100)
print("figures in", FIGURES.resolve())
if INTERACTIVE:
    plt.show()
