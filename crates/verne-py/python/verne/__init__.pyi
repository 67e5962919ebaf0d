"""Type stubs of verne (lengths in mm, angles in radians)."""

import enum
from typing import Any, Dict, List, Literal, NamedTuple, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

class Status(enum.IntEnum):
    """A row's outcome in the `status` arrays (equal to the plain integers it names)."""

    OK = 0
    """Solved."""
    UNREACHABLE = 1
    """No real branch (proved)."""
    NO_WORKING_BRANCH = 2
    """Real branches exist, none within the limits, or the list is not proved complete."""
    INVALID_INPUT = 3
    """NaN, an infinite value or a zero axis."""

OK: Status
UNREACHABLE: Status
NO_WORKING_BRANCH: Status
INVALID_INPUT: Status
OUTCOMES: List[str]
GLIDER_NODE_CLASSES: List[str]

class Machine:
    @staticmethod
    def default() -> "Machine": ...
    @staticmethod
    def from_file(path: str) -> "Machine": ...
    @staticmethod
    def from_toml(text: str) -> "Machine": ...
    @staticmethod
    def from_dict(d: Dict[str, Any]) -> "Machine": ...
    def to_dict(self) -> Dict[str, Any]: ...
    def to_toml(self) -> str: ...
    @property
    def name(self) -> str: ...
    @property
    def tool_length(self) -> float: ...

class ModuleBranches(NamedTuple):
    """Every branch of the parallel module for each row (`module_ik`, `module_fk`), padded."""

    branches: npt.NDArray[np.float64]
    """[N, K, 4]: rho1, rho2, rho3, alpha (`module_ik`) or xp, yp, zp, alpha (`module_fk`)."""
    config: npt.NDArray[np.int8]
    """[N, K, 3]: the configuration indices (s1, s2, s3)."""
    working: npt.NDArray[np.bool_]
    """[N, K]: the machine can be in this branch."""
    count: npt.NDArray[np.int64]
    """[N]: the number of real branches of the row (the rest is NaN padding)."""
    proved: npt.NDArray[np.bool_]
    """[N]: the list is proved complete."""
    def working_branch(self) -> npt.NDArray[np.float64]:
        """[N, 4]: the machine's branch of each row, NaN where it has none."""
        ...

def module_ik(machine: Machine, points: npt.NDArray[np.float64]) -> ModuleBranches: ...
class ModuleWorking(NamedTuple):
    """The machine's branch of the parallel module for each platform point."""

    sliders: npt.NDArray[np.float64]
    """[N, 3] (mm), NaN where there is none."""
    alpha: npt.NDArray[np.float64]
    """[N] (rad)."""
    status: npt.NDArray[np.int8]
    """[N]: a `Status`."""

def module_ik_working(machine: Machine, points: npt.NDArray[np.float64]) -> ModuleWorking: ...
def module_fk(machine: Machine, sliders: npt.NDArray[np.float64]) -> ModuleBranches: ...
class CompactBranches(NamedTuple):
    """Every real branch, one row each (`module_ik_compact`, `module_fk_compact`)."""

    branches: npt.NDArray[np.float64]
    """[M, 4]: as in `ModuleBranches.branches`."""
    config: npt.NDArray[np.int8]
    """[M, 3]."""
    working: npt.NDArray[np.bool_]
    """[M]."""
    point: npt.NDArray[np.int64]
    """[M]: the input row of each branch."""
    offsets: npt.NDArray[np.int64]
    """[N + 1]: the branches of input row i are offsets[i]:offsets[i + 1]."""
    proved: npt.NDArray[np.bool_]
    """[N]: the list is proved complete."""

def module_ik_compact(machine: Machine, points: npt.NDArray[np.float64]) -> CompactBranches: ...
def module_fk_compact(machine: Machine, sliders: npt.NDArray[np.float64]) -> CompactBranches: ...
def working(
    branches: npt.NDArray[np.float64], working_mask: npt.NDArray[np.bool_]
) -> npt.NDArray[np.float64]: ...
class PathJoints(NamedTuple):
    """The 5-axis machine along a toolpath (`ik_path`)."""

    joints: npt.NDArray[np.float64]
    """[N, 5]: rho1, rho2, rho3 (mm), theta1, theta2 (rad), NaN where the row has none."""
    orientation: npt.NDArray[np.int8]
    """[N]: the orientation solution, 1 or 2 (0 where none)."""
    status: npt.NDArray[np.int8]
    """[N]: a `Status`."""

class ToolPoses(NamedTuple):
    """The tool pose of each row of joints on the working mode (`machine_fk_working`)."""

    tips: npt.NDArray[np.float64]
    """[N, 3]: the tool tip (mm), workpiece frame."""
    axes: npt.NDArray[np.float64]
    """[N, 3]: the tool axis, tip towards spindle."""
    status: npt.NDArray[np.int8]
    """[N]: a `Status`."""

def ik_path(
    machine: Machine,
    tips: npt.NDArray[np.float64],
    axes: npt.NDArray[np.float64],
    tool_length: Optional[float] = None,
    prefer: Literal["smallest-theta1", "orientation1", "orientation2"] = "smallest-theta1",
) -> PathJoints: ...
def machine_fk_working(
    machine: Machine,
    joints: npt.NDArray[np.float64],
    tool_length: Optional[float] = None,
) -> ToolPoses: ...

class MachineBranches(NamedTuple):
    """Every branch of the 5-axis machine for each tool pose (`machine_ik`), padded."""

    joints: npt.NDArray[np.float64]
    """[N, 48, 5]: rho1, rho2, rho3 (mm), theta1, theta2 (rad)."""
    orientation: npt.NDArray[np.int8]
    """[N, 48]: the orientation solution, 1 or 2."""
    config: npt.NDArray[np.int8]
    """[N, 48, 3]: the module's configuration indices."""
    working: npt.NDArray[np.bool_]
    """[N, 48]."""
    count: npt.NDArray[np.int64]
    """[N]: the number of real branches."""
    proved: npt.NDArray[np.bool_]
    """[N]: the list is proved complete."""
    def working_branch(self) -> npt.NDArray[np.float64]:
        """[N, 5]: the first working branch of each row, NaN where it has none."""
        ...

def machine_ik(
    machine: Machine,
    tips: npt.NDArray[np.float64],
    axes: npt.NDArray[np.float64],
    tool_length: Optional[float] = None,
) -> MachineBranches: ...
class MachineModes(NamedTuple):
    """Every assembly mode of the 5-axis machine for each row of joints (`machine_fk`)."""

    tips: npt.NDArray[np.float64]
    """[N, 16, 3]: the tool tip (mm)."""
    axes: npt.NDArray[np.float64]
    """[N, 16, 3]: the tool axis."""
    config: npt.NDArray[np.int8]
    """[N, 16, 3]."""
    working: npt.NDArray[np.bool_]
    """[N, 16]."""
    count: npt.NDArray[np.int64]
    """[N]."""
    proved: npt.NDArray[np.bool_]
    """[N]."""

def machine_fk(
    machine: Machine,
    joints: npt.NDArray[np.float64],
    tool_length: Optional[float] = None,
) -> MachineModes: ...
class Jacobians(NamedTuple):
    """A dX + B drho = 0 at each configuration (`jacobian`)."""

    a: npt.NDArray[np.float64]
    """[N, 4, 4]: d/dX of each constraint, X = (xp, yp, zp, alpha)."""
    b: npt.NDArray[np.float64]
    """[N, 4, 3]: d/drho of each constraint."""

def jacobian(
    machine: Machine, poses: npt.NDArray[np.float64], sliders: npt.NDArray[np.float64]
) -> Jacobians: ...
def kinetostatics(
    machine: Machine, poses: npt.NDArray[np.float64], sliders: npt.NDArray[np.float64]
) -> Dict[str, npt.NDArray[np.float64]]: ...
class Verification(NamedTuple):
    """What `verify` found: each finding, and the summary of every check."""

    findings: List[Dict[str, Any]]
    """One dict per finding: row, check, value, limit, detail, severity."""
    summary: Dict[str, Any]
    """`clean`, `rows`, and per check its count and worst value."""

def verify(
    machine: Machine,
    joints: npt.NDArray[np.float64],
    tips: npt.NDArray[np.float64],
    axes: npt.NDArray[np.float64],
    t: Optional[npt.NDArray[np.float64]] = None,
    feed: Optional[npt.NDArray[np.float64]] = None,
    thresholds: Optional[Dict[str, float]] = None,
    tool_length: Optional[float] = None,
) -> Verification: ...
def workspace(
    machine: Machine,
    of: Literal["platform", "tool", "manufacturing"] = "platform",
    step: float = 10.0,
    tool_length: Optional[float] = None,
    bounds: Optional[Tuple[float, float, float, float, float, float]] = None,
    lambda_bounds: Optional[Tuple[float, float]] = None,
    adaptive: Optional[bool] = None,
    points: bool = False,
) -> Dict[str, Any]: ...

class Glider:
    @staticmethod
    def preset(name: Literal["biglide1", "biglide2", "orthoglide"]) -> "Glider": ...
    @staticmethod
    def from_file(path: str) -> "Glider": ...
    @staticmethod
    def from_toml(text: str) -> "Glider": ...
    @staticmethod
    def design(
        architecture: Literal["biglide1", "biglide2", "orthoglide"],
        l: float = 1.0,
        lambda_bounds: Optional[Tuple[float, float]] = None,
    ) -> "Glider": ...
    def to_toml(self) -> str: ...
    @property
    def name(self) -> str: ...
    @property
    def joint_ranges(self) -> Tuple[Tuple[float, float], Tuple[float, float]]: ...

class GliderSolutions(NamedTuple):
    """Every solution of a glider's kinematics (`glider_ik`, `glider_fk`)."""

    values: npt.NDArray[np.float64]
    """[N, K, 2]: the joints (ik) or the points (fk)."""
    mode: npt.NDArray[np.int8]
    """[N, K, 2]: the working mode (strut signs)."""
    assembly: npt.NDArray[np.int8]
    """[N, K]: the assembly mode (sign of det A)."""
    ok: npt.NDArray[np.bool_]
    """[N, K]: a pose of the machine."""
    count: npt.NDArray[np.int64]
    """[N]."""

class GliderModes(NamedTuple):
    """`glider_fk`: the solutions, and where the joints are on a structural singularity."""

    solutions: GliderSolutions
    """The solutions, as `glider_ik`'s."""
    structural: npt.NDArray[np.bool_]
    """[N]: C = D with equal struts (P anywhere on a circle, count 0)."""

def glider_ik(glider: Glider, points: npt.NDArray[np.float64]) -> GliderSolutions: ...
def glider_fk(
    glider: Glider, rho: npt.NDArray[np.float64]
) -> GliderModes: ...
def glider_workspace(
    glider: Glider,
    nodes: int = 801,
    mode: Literal["++", "+-", "-+", "--"] = "++",
    assembly: Literal["+", "-"] = "+",
    lambda_bounds: Union[None, bool, Tuple[float, float]] = None,
    shape_angles: Optional[List[float]] = None,
    sampling: Literal["auto", "uniform", "adaptive"] = "auto",
) -> Dict[str, Any]: ...
def design_tables(
    lambda_bounds: Optional[Tuple[float, float]] = None,
    nodes: int = 1201,
    target_area: float = 1.0,
) -> Dict[str, List[Dict[str, Any]]]: ...
