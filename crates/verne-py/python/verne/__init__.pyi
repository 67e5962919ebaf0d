"""Type stubs of verne (lengths in mm, angles in radians)."""

from typing import Literal, Optional, Tuple

import numpy as np
import numpy.typing as npt

OK: int
UNREACHABLE: int
NO_WORKING_BRANCH: int
INVALID_INPUT: int

class Machine:
    @staticmethod
    def default() -> "Machine": ...
    @staticmethod
    def from_file(path: str) -> "Machine": ...
    @staticmethod
    def from_toml(text: str) -> "Machine": ...
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
