"""Type stubs of kdl_space (the extension kdl_space._kdl_space, re-exported)."""

import enum
from types import ModuleType
import os
from typing import Any, Callable, Literal, Mapping, Optional, Sequence, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

ArrayLike = npt.ArrayLike
Array = npt.NDArray[np.float64]
# Every call that takes a scenario takes a loaded Scenario or the path of its file.
ScenarioLike = Union["Scenario", str, os.PathLike[str]]
JointValues = Union[ArrayLike, Mapping[str, float]]
Pose = Union[ArrayLike, Tuple[ArrayLike, ArrayLike]]

E_NOERROR: int
E_SIZE_MISMATCH: int
E_NOT_COMPUTED: int
E_NOT_FINITE: int
E_NOT_POSITIVE_DEFINITE: int
E_BAD_CONTACT: int
E_MAX_STEPS: int
E_BAD_ARGUMENT: int
E_STEP_UNDERFLOW: int
E_CANCELLED: int
codes: ModuleType

class Error(RuntimeError): ...  # the C++ kdl_space::Error
class ModelError(Error): ...
class InputError(Error): ...
class ComputeError(Error):
    code: int

def str_error(code: int) -> str: ...

class Severity(enum.Enum):
    Error = ...
    Warning = ...
    Note = ...

class ElementType(enum.Enum):
    File = ...
    Robot = ...
    Link = ...
    Joint = ...
    Tip = ...

class Finding:
    severity: Severity
    kind: str
    element_type: ElementType
    element: str
    message: str
    def describe(self) -> str: ...

class Diagnostic:
    element: str
    message: str
    kind: str
    severity: Severity

class Contact:
    link: str
    body: int
    offset: Array

class Model:
    source: str
    joint_names: list[str]
    link_names: list[str]
    nj: int
    total_mass: float
    diagnostics: list[Diagnostic]
    fixed_joints: list[Tuple[str, str]]
    def contact(self, link: str, offset: Optional[ArrayLike] = None) -> Contact: ...
    def state(self, q: Optional[JointValues] = None, base_pose: Optional[Pose] = None,
              base_twist: Optional[ArrayLike] = None, qdot: Optional[JointValues] = None) -> State: ...
    # World pose of a link: (position (3,), rotation world_R_link (3, 3)); a State, or q (base at the identity).
    def link_pose(self, state: Union[State, JointValues], link: str) -> Tuple[Array, Array]: ...

class State:
    def __init__(self, model: Model, *, q: Optional[JointValues] = None, base_pose: Optional[Pose] = None,
                 base_twist: Optional[ArrayLike] = None, qdot: Optional[JointValues] = None) -> None: ...
    joint_names: list[str]
    q: Array
    qdot: Array
    base_pose: Array
    base_twist: Array

def load_urdf(path: str) -> Model: ...
def check_urdf(path: str, tips: Sequence[str] = ...) -> list[Finding]: ...

# sigma_min / sigma_max of J* below which a configuration is "near a singularity" (1e-3).
NEAR_SINGULAR_RATIO: float
# The contact frame's pose (position, rotation, quaternion (x, y, z, w), rpy), J_star_singular_values,
# J_star_condition_number, J_star_manipulability, J_manipulability, joint_margins (name -> float or
# None), warnings (list of {kind, element, message}).
def inspect_contact(state: State, contact: Contact) -> dict[str, Any]: ...

class FreeFloatingSolver:
    def __init__(self, model: Model) -> None: ...
    joint_names: list[str]
    def compute(self, state: State) -> None: ...
    w: float
    r_g: Array
    I_g: Array
    M_a: Array
    A_m: Array
    H: Array
    H_star: Array
    def contact_point(self, contact: Contact) -> Array: ...
    def J(self, contact: Contact) -> Array: ...
    def J_star(self, contact: Contact) -> Array: ...
    @overload
    def G_star(self, contact: Contact) -> Array: ...
    @overload
    def G_star(self, contacts: Sequence[Contact]) -> Array: ...
    def G_grounded(self, contact: Contact) -> Array: ...
    def G_locked(self, contact: Contact) -> Array: ...
    def momentum(self, state: State) -> Array: ...

class RecursiveExIITSolver:
    def __init__(self, model: Model) -> None: ...
    def compute(self, state: State) -> None: ...
    def G_star(self, contact: Contact) -> Array: ...

class ImpactLaw:
    def __init__(self, kind: str = "capture", normal: Optional[ArrayLike] = None, restitution: float = 0.0,
                 friction: float = 0.0) -> None: ...
    kind: str
    normal: Optional[Array]
    restitution: float
    friction: float

class Impulse:
    F: Array
    separating: bool
    sticking: bool
    max_dissipation_completion: bool

def solve_impact(G_A: ArrayLike, G_B: ArrayLike, t_A: ArrayLike, t_B: ArrayLike, law: ImpactLaw) -> Impulse: ...
def virtual_mass(G: ArrayLike, n: ArrayLike) -> float: ...

class RigidTarget:
    def __init__(self, mass: float, inertia: ArrayLike, pose: Optional[Pose] = None, com: Optional[ArrayLike] = None,
                 twist: Optional[ArrayLike] = None) -> None: ...
    mass: float
    inertia: Array
    pose: Array
    com: Array
    twist: Array

class CaptureProblem:
    state: State
    def __init__(self, state: State, contact: Contact, target: RigidTarget, law: ImpactLaw,
                 response: str = "free", method: str = "recursive") -> None: ...
    joint_names: list[str]
    law: ImpactLaw
    floating_target: bool

class Scenario:
    file: str
    robot_urdf: str
    target_urdf: str
    impact: bool
    robot: Model
    problem: CaptureProblem
    duration: float
    output_step: float

class SideResult:
    joint_names: list[str]
    base_twist_before: Array
    base_twist_after: Array
    qdot_before: Array
    qdot_after: Array
    contact_twist_before: Array
    contact_twist_after: Array
    centroid_twist_before: Array
    centroid_twist_after: Array

class CaptureResult:
    impulse: Impulse
    robot: SideResult
    floating_target: Optional[SideResult]
    contact_point: Array
    target_twist_before: Array
    target_twist_after: Array
    G_robot: Array
    G_target: Array
    momentum_before: Array
    momentum_after: Array
    energy_before: float
    energy_after: float
    energy_lost: float
    virtual_mass: Optional[float]
    contact_body_pose: Array
    warnings: list[dict[str, str]]  # the robot's configuration at the capture: {kind, element, message}
    def to_html(self, path: str, mesh_path: Union[None, str, os.PathLike[str], Sequence[Union[str, os.PathLike[str]]]] = None) -> None: ...  # the instant as `kdl_space capture --html` draws it; mesh_path: --mesh-path's folders

class OperationResult(dict[str, Any]):  # run_operation's dict (`simulate --json`'s keys, 'samples')
    def to_html(self, path: str, mesh_path: Union[None, str, os.PathLike[str], Sequence[Union[str, os.PathLike[str]]]] = None) -> None: ...  # the run as `kdl_space simulate --html` draws it; mesh_path: --mesh-path's folders

def load_scenario(path: str) -> Scenario: ...
def run_operation(scenario: ScenarioLike, *, duration: Optional[float] = None, output_step: Optional[float] = None,
                  approach: bool = True, motion: bool = True,
                  observer: Optional[Callable[[float, str, Array, Array], None]] = None,
                  controller: Optional["Controller"] = None, control_rate: Optional[float] = None,
                  max_output_rows: int = 10_000_000, check_gains: bool = True) -> OperationResult: ...
def solve_capture(scenario_or_problem: Union[ScenarioLike, CaptureProblem]) -> CaptureResult: ...
@overload
def inverse_kinematics(state: State, contact: Contact, goal: Union[ArrayLike, Tuple[ArrayLike, ArrayLike]], *,
                       preferred: Union[None, ArrayLike, Mapping[str, float]] = None,
                       position_tolerance: float = 1e-10, orientation_tolerance: float = 1e-10,
                       restarts: int = 16, max_iterations: int = 500) -> dict[str, Any]: ...
@overload
def inverse_kinematics(scenario: ScenarioLike, goal: Union[ArrayLike, Tuple[ArrayLike, ArrayLike]], *,
                       preferred: Union[None, ArrayLike, Mapping[str, float]] = None,
                       position_tolerance: float = 1e-10, orientation_tolerance: float = 1e-10,
                       restarts: int = 16, max_iterations: int = 500) -> dict[str, Any]: ...
ik = inverse_kinematics

class CapturePlan:
    scenario: str
    joint_names: list[str]
    q: Array
    q_by_name: dict[str, float]
    qdot_before: Array
    base_twist_before: Array
    qdot_after: Array
    parameters: dict[str, float]
    searched: list[str]
    objective: float
    optimum: dict[str, Any]
    nominal_objective: float
    nominal: dict[str, Any]
    nominal_q_by_name: dict[str, float]
    evaluations: int
def plan_capture(scenario: ScenarioLike, *, objective: str = "base_rate", weights: Optional[Mapping[str, float]] = None,
                 self_motion: Optional[Tuple[float, float]] = None, wrist_roll: Optional[Tuple[float, float]] = None,
                 timing: Optional[Tuple[float, float]] = None, closing_speed: Optional[Tuple[float, float]] = None,
                 scan: int = 21, polish_starts: int = 5) -> CapturePlan: ...
@overload
def attach_target(scenario_or_problem: ScenarioLike, result: CaptureResult) -> Model: ...
@overload
def attach_target(scenario_or_problem: CaptureProblem, result: CaptureResult) -> Model: ...

Wrenches = Union[ArrayLike, Mapping[Union[str, int], ArrayLike]]

class ForwardDynamicsSolver:
    def __init__(self, model: Model, *, gravity: Optional[ArrayLike] = None, grounded: bool = False,
                 locked: Optional[Sequence[Union[str, int, bool]]] = None) -> None: ...
    joint_names: list[str]
    gravity: Array
    grounded: bool
    locked: list[str]
    def accelerations(self, state: State, tau: Optional[JointValues] = None,
                      wrenches: Optional[Wrenches] = None) -> Tuple[Array, Array]: ...

class DenseForwardDynamicsSolver:
    def __init__(self, model: Model, *, gravity: Optional[ArrayLike] = None, grounded: bool = False,
                 locked: Optional[Sequence[Union[str, int, bool]]] = None) -> None: ...
    joint_names: list[str]
    gravity: Array
    grounded: bool
    locked: list[str]
    def accelerations(self, state: State, tau: Optional[JointValues] = None,
                      wrenches: Optional[Wrenches] = None) -> Tuple[Array, Array]: ...

class Integrator(enum.Enum):
    RK4 = ...
    DormandPrince54 = ...
    Rosenbrock = ...

class JointRecord:
    limit_first_time: float
    limit_worst: float
    stops: int
    saturation_first_time: float
    saturation_time: float

class SimulationStats:
    accepted_steps: int
    rejected_steps: int
    min_step: float
    max_step: float
    base_saturation_time: float
    joints: dict[str, JointRecord]

class Stiffness:
    fastest_rate: float
    fastest_joint: Optional[str]
    explicit_step: float

class SimulationResult:
    joint_names: list[str]
    t: Array
    base_position: Array
    base_quaternion: Array
    base_twist: Array
    q: Array
    qdot: Array
    tau: Array
    base_wrench: Array
    momentum: Array
    energy: Array
    work: dict[str, Array]
    warnings: list[dict[str, str]]  # a sampled controller's gains: {kind, element, message}
    impulse: Array
    final_state: State
    final_t: float
    stats: SimulationStats
    def __len__(self) -> int: ...

# controller(t, q, qdot, base_pose (4, 4), base_twist (6,)) -> tau (nj,) or {joint name: torque}
Controller = Callable[[float, Array, Array, Array, Array], JointValues]

class Simulator:
    def __init__(self, model: Model, *, integrator: Union[str, Integrator] = "dopri5", step: float = 1e-3,
                 rtol: float = 1e-10, atol: float = 1e-12, max_step: float = 0.05, max_steps: int = 1000000,
                 gravity: Optional[ArrayLike] = None, grounded: bool = False, effort_limits: bool = True,
                 joint_friction: bool = True, friction_velocity: float = 1e-3, friction_rate: float = 1e3) -> None: ...
    @staticmethod
    def from_scenario(scenario: ScenarioLike, model: Optional[Model] = None) -> Simulator: ...
    model: Model
    joint_names: list[str]
    options: dict[str, object]
    joint_controls: dict[str, dict[str, object]]
    limit_modes: dict[str, str]
    friction_velocities: Array
    def set_joint_control(self, joint: Union[str, int], mode: str, *, kp: float = 0.0, kd: float = 0.0,
                          set_point: float = 0.0) -> None: ...
    def set_limit_mode(self, joint: Union[str, int], mode: str) -> None: ...
    def set_base_control(self, *, attitude: Optional[Mapping[str, object]] = None,
                         position: Optional[Mapping[str, object]] = None) -> None: ...
    def add_wrench(self, link: Union[str, int], wrench: ArrayLike, *, point: Optional[ArrayLike] = None,
                   body_axes: bool = False, start: float = 0.0, end: float = ...) -> None: ...
    def engage_brakes(self, state: State) -> State: ...
    def energy_and_momentum(self, state: State) -> Tuple[float, Array]: ...
    def stiffness(self, state: State) -> Stiffness: ...
    def apparent_inertia(self, state: State, joint: Union[str, int]) -> float: ...
    def run(self, state: State, t_end: float, output_dt: float, *, controller: Optional[Controller] = None,
            control_rate: Optional[float] = None, t0: float = 0.0,
            max_output_rows: int = 10_000_000, check_gains: bool = True) -> SimulationResult: ...

class Study:
    file: str
    fingerprint: int
    samples: int
    seed: int
    latin_hypercube: bool
    inputs: list[str]
    distributions: dict[str, dict[str, Union[str, float, int]]]
    columns: list[str]
    objective: str
    scenario: Scenario
    motion_duration: float
    heat_map: Optional[Tuple[str, str, str]]
    heat_map_statistic: Optional[str]
    objective_statistic: Optional[str]
    default_chunk_size: int
    def chunks(self, chunk_size: int = 0, begin: int = 0, end: Optional[int] = None) -> list[Tuple[int, int]]: ...
    def rows(self, begin: int, end: int, threads: int = 1) -> Array: ...
    def draws(self, i: int) -> Array: ...
    @property
    def input_columns(self) -> list[str]: ...
    def rows_drawn(self, draws: ArrayLike) -> tuple[Array, dict[int, str]]: ...
    def summary(self, rows: ArrayLike) -> dict[str, Any]: ...
    def write_table(self, table: ArrayLike, path: str) -> None: ...
    def to_table(self, table: str, threads: int = 0, shard: Optional[Tuple[int, int]] = None,
                 merge: Sequence[str] = (), chunk_size: int = 0) -> dict[str, Any]: ...

def load_study(path: str) -> Study: ...
def self_motion(scenario: ScenarioLike, s: float) -> dict[str, float]: ...

class StudyResult:
    study: Study
    columns: list[str]
    table: Array
    def __init__(self, study: Study, table: ArrayLike, failures: Optional[dict[int, str]] = None) -> None: ...
    def __len__(self) -> int: ...
    def __getitem__(self, name: str) -> Array: ...
    @property
    def summary(self) -> dict[str, Any]: ...
    @property
    def grid_points(self) -> list[dict[str, Any]]: ...
    @property
    def failed(self) -> int: ...
    def to_csv(self, path: Union[str, os.PathLike[str]]) -> None: ...
    def to_npz(self, path: Union[str, os.PathLike[str]]) -> None: ...

def study(study: Union[str, os.PathLike[str], Study], *, engine: Literal["threads", "dask"] = "threads",
          threads: int = 0, client: Optional[Any] = None, scheduler: Optional[str] = None,
          chunk_size: Optional[int] = None, timeout: float = 10.0,
          sampler: Optional[Callable[[Any, int], dict[str, float]]] = None) -> StudyResult: ...
def study_to_table(study: Union[str, os.PathLike[str], Study], table: Union[str, os.PathLike[str]], *,
                   threads: int = 0, shard: Optional[Tuple[int, int]] = None,
                   merge: Sequence[Union[str, os.PathLike[str]]] = (), chunk_size: Optional[int] = None
                   ) -> dict[str, Any]: ...
