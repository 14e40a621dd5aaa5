"""kdl_space: free-floating space manipulator dynamics (Yoshida et al.) from Python.

The C++ library's models, solvers (J*, H*, G*), impact laws and captures, NumPy in and out:
every vector and matrix in the world frame, twists (v; w), wrenches (f; n); 6x6 matrices as
(6, 6) float64 arrays, vectors as (n,) arrays; joint-indexed values in ``joint_names`` order.

    import kdl_space
    model = kdl_space.load_urdf("urdf/space_arm7.urdf")
    solver = kdl_space.FreeFloatingSolver(model)
    solver.compute(kdl_space.State(model, q={"joint2": 0.7}))
    G = solver.G_star(model.contact("end_effector"))

Errors: ModelError and InputError (the library's message), ComputeError (``.code``, the
return code of a compute call: E_NOT_FINITE for NaN inputs, ...), ValueError for an argument of
the wrong shape (naming it and the shape expected).
"""

from ._kdl_space import (  # noqa: F401  (re-exported)
    CaptureProblem,
    CaptureResult,
    ComputeError,
    Contact,
    Diagnostic,
    ElementType,
    Error,
    Finding,
    FreeFloatingSolver,
    ImpactLaw,
    Impulse,
    InputError,
    Model,
    ModelError,
    RecursiveExIITSolver,
    RigidTarget,
    Scenario,
    Severity,
    SideResult,
    State,
    check_urdf,
    codes,
    load_scenario,
    load_urdf,
    solve_capture,
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
)

__all__ = [
    "CaptureProblem", "CaptureResult", "ComputeError", "Contact", "Diagnostic", "ElementType", "Error",
    "Finding", "FreeFloatingSolver", "ImpactLaw", "Impulse", "InputError", "Model", "ModelError",
    "RecursiveExIITSolver", "RigidTarget", "Scenario", "Severity", "SideResult", "State", "check_urdf",
    "codes", "load_scenario", "load_urdf", "solve_capture", "solve_impact", "str_error", "virtual_mass",
    "E_NOERROR", "E_SIZE_MISMATCH", "E_NOT_COMPUTED", "E_NOT_FINITE", "E_NOT_POSITIVE_DEFINITE",
    "E_BAD_CONTACT", "E_MAX_STEPS", "E_BAD_ARGUMENT", "E_STEP_UNDERFLOW",
]
