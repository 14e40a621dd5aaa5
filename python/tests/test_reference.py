"""Every case of tests/data/reference (values of an independent rigid-body engine, no KDL):
mass, CoM, I_g, the contact point, J*, H*, G*, grounded and locked G, the capture and the point
impact, to 1e-9 relative (1e-12 absolute), joint-indexed values compared through their names."""
import json

import numpy as np
import pytest

import kdl_space
from conftest import REFERENCE_DIR

CASES = sorted(p.stem for p in REFERENCE_DIR.glob("*.json") if "expected" in json.loads(p.read_text()))
REL, ABS = 1e-9, 1e-12


def near(actual, expected, what):
    actual, expected = np.asarray(actual), np.asarray(expected, dtype=float)
    assert actual.shape == expected.shape, what
    assert np.allclose(actual, expected, rtol=REL, atol=ABS), f"{what}: {actual} vs {expected}"


def load(name):
    case = json.loads((REFERENCE_DIR / f"{name}.json").read_text())
    i = case["inputs"]
    model = kdl_space.load_urdf(str(REFERENCE_DIR / i["urdf"]))
    state = kdl_space.State(model, q=i["q"], base_pose=(i["base_position"], i["base_rpy"]),
                            base_twist=i["base_twist"], qdot=i["joint_rates"])
    contact = model.contact(i["contact_link"], i["contact_offset"])
    return case, model, state, contact


def order(model, names):
    """Columns of the model's joint order for the reference's names."""
    return [model.joint_names.index(n) for n in names]


def test_there_are_cases():
    assert len(CASES) >= 6


@pytest.mark.parametrize("name", CASES)
def test_free_floating_quantities(name):
    case, model, state, contact = load(name)
    e = case["expected"]
    idx = order(model, e["joint_names"])
    solver = kdl_space.FreeFloatingSolver(model)
    solver.compute(state)
    near(solver.w, e["mass"], "mass")
    near(model.total_mass, e["mass"], "total_mass")
    near(solver.r_g, e["com"], "com")
    near(solver.I_g, e["I_g"], "I_g")
    near(solver.contact_point(contact), e["hand_position"], "hand_position")
    near(solver.J_star(contact)[:, idx], e["J_star"], "J_star")
    near(solver.H_star[np.ix_(idx, idx)], e["H_star"], "H_star")
    near(solver.G_star(contact), e["G_star"], "G_star")
    near(solver.G_grounded(contact), e["G_grounded"], "G_grounded")
    near(solver.G_locked(contact), e["G_locked"], "G_locked")
    recursive = kdl_space.RecursiveExIITSolver(model)
    recursive.compute(state)
    near(recursive.G_star(contact), e["G_star"], "recursive G_star")


def problem(case, state, contact, law, method="recursive"):
    t = case["inputs"]["target"]
    target = kdl_space.RigidTarget(t["mass"], t["inertia_about_com_world"], com=t["com"], twist=t["twist_at_com"])
    return kdl_space.CaptureProblem(state, contact, target, law, method=method)


@pytest.mark.parametrize("method", ["recursive", "dense"])
@pytest.mark.parametrize("name", CASES)
def test_capture(name, method):
    case, model, state, contact = load(name)
    c = case["capture"]
    idx = order(model, case["expected"]["joint_names"])
    r = kdl_space.solve_capture(problem(case, state, contact, kdl_space.ImpactLaw("capture"), method))
    near(r.impulse.F, c["impulse_on_robot"], "impulse")
    near(r.robot.contact_twist_before, c["contact_twist_before"], "contact_twist_before")
    near(r.robot.contact_twist_after, c["contact_twist_after"], "contact_twist_after")
    near(r.target_twist_after, c["target_twist_after"], "target_twist_after")
    near(r.robot.base_twist_after, c["base_twist_after"], "base_twist_after")
    near(r.robot.qdot_after[idx], c["qdot_after"], "qdot_after")
    assert r.robot.joint_names == model.joint_names
    near(r.energy_before, c["energy_before"], "energy_before")
    near(r.energy_after, c["energy_after"], "energy_after")
    for m in (r.momentum_before, r.momentum_after):
        near(m[:3], c["linear_momentum"], "linear momentum")
        near(m[3:], c["angular_momentum_about_origin"], "angular momentum")


@pytest.mark.parametrize("name", CASES)
def test_point_impact(name):
    case, model, state, contact = load(name)
    pi = case["point_impact"]
    law = kdl_space.ImpactLaw("point", normal=pi["normal"], restitution=pi["restitution"])
    r = kdl_space.solve_capture(problem(case, state, contact, law))
    F = np.zeros(6)
    F[:3] = -pi["impulse_magnitude_on_target"] * np.asarray(pi["normal"])
    near(r.impulse.F, F, "impulse")
    near(r.robot.contact_twist_after, pi["contact_twist_after"], "contact_twist_after")
    near(r.target_twist_after, pi["target_twist_after"], "target_twist_after")
    near(r.robot.base_twist_after, pi["base_twist_after"], "base_twist_after")
    near(r.robot.qdot_after[order(model, case["expected"]["joint_names"])], pi["qdot_after"], "qdot_after")
    near(r.energy_after, pi["energy_after"], "energy_after")


@pytest.mark.parametrize("name", CASES)
def test_solve_impact_from_the_solver(name):
    """solve_impact from the bound G* and the reference's contact twist: the capture's impulse."""
    case, model, state, contact = load(name)
    t = case["inputs"]["target"]
    solver = kdl_space.FreeFloatingSolver(model)
    solver.compute(state)
    p_h = solver.contact_point(contact)
    r = p_h - np.asarray(t["com"])
    skew = np.array([[0, -r[2], r[1]], [r[2], 0, -r[0]], [-r[1], r[0], 0]])
    # the target's G_B at the contact point and its material point's twist there
    m, I = t["mass"], np.asarray(t["inertia_about_com_world"])
    Iinv = np.linalg.inv(I)
    G_B = np.block([[np.eye(3) / m - skew @ Iinv @ skew, -skew @ Iinv], [Iinv @ skew, Iinv]])
    v, w = np.asarray(t["twist_at_com"][:3]), np.asarray(t["twist_at_com"][3:])
    t_B = np.concatenate([v + np.cross(w, r), w])
    impulse = kdl_space.solve_impact(solver.G_star(contact), G_B, case["capture"]["contact_twist_before"], t_B,
                                     kdl_space.ImpactLaw())
    assert np.allclose(impulse.F, case["capture"]["impulse_on_robot"], rtol=1e-8, atol=1e-10)
