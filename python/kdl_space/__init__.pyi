"""Type stubs of kdl_space (the extension kdl_space._kdl_space, re-exported)."""

import enum
from types import ModuleType
from typing import Mapping, Optional, Sequence, Tuple, Union, overload

import numpy as np
import numpy.typing as npt

ArrayLike = npt.ArrayLike
Array = npt.NDArray[np.float64]
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
codes: ModuleType

class Error(RuntimeError): ...
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

def load_scenario(path: str) -> Scenario: ...
def solve_capture(scenario_or_problem: Union[Scenario, CaptureProblem]) -> CaptureResult: ...
