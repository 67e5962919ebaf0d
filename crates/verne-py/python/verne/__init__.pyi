"""Type stubs of verne (lengths in mm, angles in radians)."""

from typing import Any, Dict, List, Literal, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

OK: int
UNREACHABLE: int
NO_WORKING_BRANCH: int
INVALID_INPUT: int
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

Branches = Tuple[
    npt.NDArray[np.float64],  # [N, K, 4]
    npt.NDArray[np.int8],  # [N, K, 3] configuration indices
    npt.NDArray[np.bool_],  # [N, K] working
    npt.NDArray[np.int64],  # [N] count
    npt.NDArray[np.bool_],  # [N] proved complete
]

def module_ik(machine: Machine, points: npt.NDArray[np.float64]) -> Branches: ...
def module_ik_working(
    machine: Machine, points: npt.NDArray[np.float64]
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.int8]]: ...
def module_fk(machine: Machine, sliders: npt.NDArray[np.float64]) -> Branches: ...
Compact = Tuple[
    npt.NDArray[np.float64],  # [M, 4] one row per real branch
    npt.NDArray[np.int8],  # [M, 3]
    npt.NDArray[np.bool_],  # [M] working
    npt.NDArray[np.int64],  # [M] point index
    npt.NDArray[np.int64],  # [N + 1] offsets
    npt.NDArray[np.bool_],  # [N] proved complete
]

def module_ik_compact(machine: Machine, points: npt.NDArray[np.float64]) -> Compact: ...
def module_fk_compact(machine: Machine, sliders: npt.NDArray[np.float64]) -> Compact: ...
def working(
    branches: npt.NDArray[np.float64], working_mask: npt.NDArray[np.bool_]
) -> npt.NDArray[np.float64]: ...
def ik_path(
    machine: Machine,
    tips: npt.NDArray[np.float64],
    axes: npt.NDArray[np.float64],
    tool_length: Optional[float] = None,
    prefer: Literal["smallest-theta1", "orientation1", "orientation2"] = "smallest-theta1",
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.int8], npt.NDArray[np.int8]]: ...
def machine_fk_working(
    machine: Machine,
    joints: npt.NDArray[np.float64],
    tool_length: Optional[float] = None,
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.int8]]: ...

PoseBranches = Tuple[
    npt.NDArray[np.float64],  # [N, 48, 5] joints
    npt.NDArray[np.int8],  # [N, 48] orientation solution 1 or 2
    npt.NDArray[np.int8],  # [N, 48, 3] configuration indices
    npt.NDArray[np.bool_],  # [N, 48] working
    npt.NDArray[np.int64],  # [N] count
    npt.NDArray[np.bool_],  # [N] proved complete
]

def machine_ik(
    machine: Machine,
    tips: npt.NDArray[np.float64],
    axes: npt.NDArray[np.float64],
    tool_length: Optional[float] = None,
) -> PoseBranches: ...
def machine_fk(
    machine: Machine,
    joints: npt.NDArray[np.float64],
    tool_length: Optional[float] = None,
) -> Tuple[
    npt.NDArray[np.float64],  # [N, 16, 3] tips
    npt.NDArray[np.float64],  # [N, 16, 3] axes
    npt.NDArray[np.int8],  # [N, 16, 3] configuration indices
    npt.NDArray[np.bool_],  # [N, 16] working
    npt.NDArray[np.int64],  # [N] count
    npt.NDArray[np.bool_],  # [N] proved complete
]: ...
def jacobian(
    machine: Machine, poses: npt.NDArray[np.float64], sliders: npt.NDArray[np.float64]
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
def kinetostatics(
    machine: Machine, poses: npt.NDArray[np.float64], sliders: npt.NDArray[np.float64]
) -> Dict[str, npt.NDArray[np.float64]]: ...
def verify(
    machine: Machine,
    joints: npt.NDArray[np.float64],
    tips: npt.NDArray[np.float64],
    axes: npt.NDArray[np.float64],
    t: Optional[npt.NDArray[np.float64]] = None,
    feed: Optional[npt.NDArray[np.float64]] = None,
    thresholds: Optional[Dict[str, float]] = None,
    tool_length: Optional[float] = None,
) -> Tuple[List[Dict[str, Any]], Dict[str, Any]]: ...
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

GliderSolutions = Tuple[
    npt.NDArray[np.float64],  # [N, K, 2] joints (ik) or points (fk)
    npt.NDArray[np.int8],  # [N, K, 2] working mode: strut signs
    npt.NDArray[np.int8],  # [N, K] assembly mode: sign of det A
    npt.NDArray[np.bool_],  # [N, K] a pose of the machine
    npt.NDArray[np.int64],  # [N] count
]

def glider_ik(glider: Glider, points: npt.NDArray[np.float64]) -> GliderSolutions: ...
def glider_fk(
    glider: Glider, rho: npt.NDArray[np.float64]
) -> Tuple[GliderSolutions, npt.NDArray[np.bool_]]: ...
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
