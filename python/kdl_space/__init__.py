"""kdl_space: free-floating space manipulator dynamics (Yoshida et al.) from Python.

The C++ library's models, solvers (J*, H*, G*), impact laws, captures, forward dynamics, the
simulator (with a Python controller at a control rate) and capture studies (on this machine's
threads or a Dask cluster), NumPy in and out:
every vector and matrix in the world frame, twists (v; w), wrenches (f; n); 6x6 matrices as
(6, 6) float64 arrays, vectors as (n,) arrays; joint-indexed values in ``joint_names`` order.

    import kdl_space
    model = kdl_space.load_urdf("urdf/space_arm7.urdf")
    solver = kdl_space.FreeFloatingSolver(model)
    solver.compute(kdl_space.State(model, q={"joint2": 0.7}))
    G = solver.G_star(model.contact("end_effector"))
    sim = kdl_space.Simulator(model, integrator="dopri5")
    run = sim.run(kdl_space.State(model), t_end=2.0, output_dt=0.01,
                  controller=lambda t, q, qdot, pose, twist: -5.0 * qdot, control_rate=100)
    run.q, run.momentum                                        # (k, nj), (k, 6) arrays
    result = kdl_space.study("scenarios/study_grasp_configuration.yaml")  # or engine="dask"
    result["base_rate"], result.summary["probabilities"]      # a column, the summary

Errors: Error (the C++ library's kdl_space::Error) and its subclasses ModelError and InputError
(the library's message), ComputeError (``.code``, the return code of a compute call: E_NOT_FINITE
for NaN inputs, ...), ValueError for an argument of the wrong shape (naming it and the shape
expected).
"""

from ._kdl_space import (  # noqa: F401  (re-exported)
    CaptureProblem,
    CapturePlan,
    CaptureResult,
    ComputeError,
    Contact,
    DenseForwardDynamicsSolver,
    Diagnostic,
    ElementType,
    Error,
    Finding,
    ForwardDynamicsSolver,
    FreeFloatingSolver,
    ImpactLaw,
    Impulse,
    InputError,
    Integrator,
    JointRecord,
    Model,
    ModelError,
    OperationResult,
    RecursiveExIITSolver,
    RigidTarget,
    Scenario,
    Severity,
    SideResult,
    SimulationResult,
    SimulationStats,
    Simulator,
    State,
    Stiffness,
    Study,
    attach_target,
    check_urdf,
    inverse_kinematics,
    codes,
    inspect_contact,
    load_scenario,
    load_study,
    load_urdf,
    mjcf_text,
    spacedyn_files,
    urdf_document,
    plan_capture,
    run_operation,
    self_motion,
    solve_capture,
    solve_compliant_capture,
    solve_impact,
    str_error,
    virtual_mass,
    E_NOERROR,
    E_SIZE_MISMATCH,
    E_NOT_COMPUTED,
    E_NOT_FINITE,
    E_NOT_POSITIVE_DEFINITE,
    E_BAD_CONTACT,
    E_MAX_STEPS,
    E_BAD_ARGUMENT,
    E_STEP_UNDERFLOW,
    E_CANCELLED,
    NEAR_SINGULAR_RATIO,
)
from .study import StudyResult, study, study_to_table  # noqa: F401  (the engines: threads, Dask)

ik = inverse_kinematics  # the short name (as the command `kdl_space ik`)

__all__ = [
    "CaptureProblem", "CapturePlan", "CaptureResult", "ComputeError", "Contact", "DenseForwardDynamicsSolver",
    "Diagnostic", "ElementType", "Error", "Finding", "ForwardDynamicsSolver", "FreeFloatingSolver",
    "ImpactLaw", "Impulse", "InputError", "Integrator", "JointRecord", "Model", "ModelError", "OperationResult",
    "RecursiveExIITSolver", "RigidTarget", "Scenario", "Severity", "SideResult", "SimulationResult",
    "SimulationStats", "Simulator", "State", "Stiffness", "Study", "StudyResult", "attach_target",
    "check_urdf", "codes", "ik", "inverse_kinematics",
    "load_scenario", "load_study", "load_urdf", "mjcf_text", "spacedyn_files", "urdf_document", "plan_capture", "run_operation", "self_motion", "solve_capture",
    "solve_compliant_capture", "solve_impact",
    "str_error", "study", "study_to_table", "virtual_mass",
    "E_NOERROR", "E_SIZE_MISMATCH", "E_NOT_COMPUTED", "E_NOT_FINITE", "E_NOT_POSITIVE_DEFINITE",
    "E_BAD_CONTACT", "E_MAX_STEPS", "E_BAD_ARGUMENT", "E_STEP_UNDERFLOW", "E_CANCELLED",
]
