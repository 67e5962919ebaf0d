"""Exact, all-branch kinematics of the VERNE parallel kinematic machine tool, from NumPy.

Lengths are in mm, angles in radians. Every function takes float64 arrays of shape (N, k) and
returns arrays of N rows; a row that cannot be solved is an answer in its status or count
(NaN where there is no value), never an exception. Wrong shapes raise ValueError.

>>> import numpy as np, verne
>>> m = verne.Machine.default()
>>> ik = verne.module_ik(m, np.array([[-240.0, -86.0, 1000.0]]))
>>> int(ik.count[0]), bool(ik.proved[0])
(16, True)
>>> w = ik.working_branch()                     # the machine's branch: rho1, rho2, rho3, alpha
>>> fk = verne.module_fk(m, w[:, :3])
>>> bool(np.allclose(fk.working_branch()[0, :3], [-240.0, -86.0, 1000.0]))
True

Results are named tuples (`ModuleBranches`, `PathJoints`, ...): by name (`ik.count`) or
unpacked in order. Statuses are `Status` values, equal to the integers they name.
"""

import enum as _enum
import functools as _functools
from typing import NamedTuple as _NamedTuple

import numpy as _np

from . import _verne
from ._verne import (  # noqa: F401
    GLIDER_NODE_CLASSES,
    OUTCOMES,
    Glider,
    Machine,
    design_tables,
    glider_workspace,
    kinetostatics,
    workspace,
)


class Status(_enum.IntEnum):
    """A row's outcome in the `status` arrays (equal to the plain integers it names)."""

    OK = _verne.OK
    """Solved."""
    UNREACHABLE = _verne.UNREACHABLE
    """No real branch (proved)."""
    NO_WORKING_BRANCH = _verne.NO_WORKING_BRANCH
    """Real branches exist, none within the limits, or the list is not proved complete."""
    INVALID_INPUT = _verne.INVALID_INPUT
    """NaN, an infinite value or a zero axis."""


OK = Status.OK
UNREACHABLE = Status.UNREACHABLE
NO_WORKING_BRANCH = Status.NO_WORKING_BRANCH
INVALID_INPUT = Status.INVALID_INPUT


class ModuleBranches(_NamedTuple):
    """Every branch of the parallel module for each row (`module_ik`, `module_fk`), padded."""

    branches: _np.ndarray
    """[N, K, 4]: rho1, rho2, rho3, alpha (`module_ik`) or xp, yp, zp, alpha (`module_fk`)."""
    config: _np.ndarray
    """[N, K, 3] int8: the configuration indices (s1, s2, s3)."""
    working: _np.ndarray
    """[N, K] bool: the machine can be in this branch."""
    count: _np.ndarray
    """[N]: the number of real branches of the row (the rest is NaN padding)."""
    proved: _np.ndarray
    """[N] bool: the list is proved complete."""

    def working_branch(self) -> _np.ndarray:
        """[N, 4]: the machine's branch of each row, NaN where it has none (`working`)."""
        return working(self.branches, self.working)


class CompactBranches(_NamedTuple):
    """Every real branch, one row each (`module_ik_compact`, `module_fk_compact`)."""

    branches: _np.ndarray
    """[M, 4]: as in `ModuleBranches.branches`."""
    config: _np.ndarray
    """[M, 3] int8."""
    working: _np.ndarray
    """[M] bool."""
    point: _np.ndarray
    """[M]: the input row of each branch."""
    offsets: _np.ndarray
    """[N + 1]: the branches of input row i are offsets[i]:offsets[i + 1]."""
    proved: _np.ndarray
    """[N] bool: the list is proved complete."""


class ModuleWorking(_NamedTuple):
    """The machine's branch of the parallel module for each platform point."""

    sliders: _np.ndarray
    """[N, 3] (mm), NaN where there is none."""
    alpha: _np.ndarray
    """[N] (rad)."""
    status: _np.ndarray
    """[N] int8: a `Status`."""


class PathJoints(_NamedTuple):
    """The 5-axis machine along a toolpath (`ik_path`)."""

    joints: _np.ndarray
    """[N, 5]: rho1, rho2, rho3 (mm), theta1, theta2 (rad), NaN where the row has none."""
    orientation: _np.ndarray
    """[N] int8: the orientation solution, 1 or 2 (0 where none)."""
    status: _np.ndarray
    """[N] int8: a `Status`."""


class ToolPoses(_NamedTuple):
    """The tool pose of each row of joints on the working mode (`machine_fk_working`)."""

    tips: _np.ndarray
    """[N, 3]: the tool tip (mm), workpiece frame."""
    axes: _np.ndarray
    """[N, 3]: the tool axis, tip towards spindle."""
    status: _np.ndarray
    """[N] int8: a `Status`."""


class MachineBranches(_NamedTuple):
    """Every branch of the 5-axis machine for each tool pose (`machine_ik`), padded."""

    joints: _np.ndarray
    """[N, 48, 5]: rho1, rho2, rho3 (mm), theta1, theta2 (rad)."""
    orientation: _np.ndarray
    """[N, 48] int8: the orientation solution, 1 or 2."""
    config: _np.ndarray
    """[N, 48, 3] int8: the module's configuration indices."""
    working: _np.ndarray
    """[N, 48] bool."""
    count: _np.ndarray
    """[N]: the number of real branches."""
    proved: _np.ndarray
    """[N] bool: the list is proved complete."""

    def working_branch(self) -> _np.ndarray:
        """[N, 5]: the first working branch of each row, NaN where it has none."""
        return working(self.joints, self.working)


class MachineModes(_NamedTuple):
    """Every assembly mode of the 5-axis machine for each row of joints (`machine_fk`)."""

    tips: _np.ndarray
    """[N, 16, 3]: the tool tip (mm)."""
    axes: _np.ndarray
    """[N, 16, 3]: the tool axis."""
    config: _np.ndarray
    """[N, 16, 3] int8."""
    working: _np.ndarray
    """[N, 16] bool."""
    count: _np.ndarray
    """[N]."""
    proved: _np.ndarray
    """[N] bool."""


class Jacobians(_NamedTuple):
    """A dX + B drho = 0 at each configuration (`jacobian`)."""

    a: _np.ndarray
    """[N, 4, 4]: d/dX of each constraint, X = (xp, yp, zp, alpha)."""
    b: _np.ndarray
    """[N, 4, 3]: d/drho of each constraint."""


class GliderSolutions(_NamedTuple):
    """Every solution of a glider's kinematics (`glider_ik`, `glider_fk`)."""

    values: _np.ndarray
    """[N, K, 2]: the joints (ik) or the points (fk)."""
    mode: _np.ndarray
    """[N, K, 2] int8: the working mode (strut signs)."""
    assembly: _np.ndarray
    """[N, K] int8: the assembly mode (sign of det A)."""
    ok: _np.ndarray
    """[N, K] bool: a pose of the machine."""
    count: _np.ndarray
    """[N]."""


class GliderModes(_NamedTuple):
    """`glider_fk`: the solutions, and where the joints are on a structural singularity."""

    solutions: GliderSolutions
    structural: _np.ndarray
    """[N] bool: C = D with equal struts (P anywhere on a circle, count 0)."""


class Verification(_NamedTuple):
    """What `verify` found: each finding, and the summary of every check."""

    findings: list
    """One dict per finding: row, check, value, limit, detail, severity."""
    summary: dict
    """`clean`, `rows`, and per check its count and worst value."""


def _named(raw, result):
    """`raw` (a function of the extension) returning `result` (a NamedTuple) for its tuple."""

    @_functools.wraps(raw)
    def call(*args, **kwargs):
        return result(*raw(*args, **kwargs))

    return call


module_ik = _named(_verne.module_ik, ModuleBranches)
module_fk = _named(_verne.module_fk, ModuleBranches)
module_ik_compact = _named(_verne.module_ik_compact, CompactBranches)
module_fk_compact = _named(_verne.module_fk_compact, CompactBranches)
module_ik_working = _named(_verne.module_ik_working, ModuleWorking)
ik_path = _named(_verne.ik_path, PathJoints)
machine_fk_working = _named(_verne.machine_fk_working, ToolPoses)
machine_ik = _named(_verne.machine_ik, MachineBranches)
machine_fk = _named(_verne.machine_fk, MachineModes)
jacobian = _named(_verne.jacobian, Jacobians)
verify = _named(_verne.verify, Verification)
glider_ik = _named(_verne.glider_ik, GliderSolutions)


@_functools.wraps(_verne.glider_fk)
def glider_fk(*args, **kwargs):
    solutions, structural = _verne.glider_fk(*args, **kwargs)
    return GliderModes(GliderSolutions(*solutions), structural)


__all__ = [
    "Machine",
    "Status",
    "ModuleBranches",
    "CompactBranches",
    "ModuleWorking",
    "PathJoints",
    "ToolPoses",
    "MachineBranches",
    "MachineModes",
    "Jacobians",
    "GliderSolutions",
    "GliderModes",
    "Verification",
    "module_ik",
    "module_ik_working",
    "module_fk",
    "module_ik_compact",
    "module_fk_compact",
    "working",
    "ik_path",
    "machine_ik",
    "machine_fk",
    "machine_fk_working",
    "jacobian",
    "kinetostatics",
    "verify",
    "workspace",
    "OUTCOMES",
    "Glider",
    "glider_ik",
    "glider_fk",
    "glider_workspace",
    "design_tables",
    "GLIDER_NODE_CLASSES",
    "OK",
    "UNREACHABLE",
    "NO_WORKING_BRANCH",
    "INVALID_INPUT",
]


def working(branches, working_mask):
    """The machine's branch of each row: `branches[N, K, 4]` and `working[N, K]` from
    `module_ik` or `module_fk` -> `[N, 4]`, the first working branch of each row (there is at
    most one for the VERNE machine's configuration), NaN where the row has none.

    >>> import numpy as np, verne
    >>> b, config, working, count, proved = verne.module_ik(
    ...     verne.Machine.default(), np.array([[-240.0, -86.0, 1000.0], [1e4, 0.0, 0.0]]))
    >>> verne.working(b, working).round(3).tolist()
    [[368.355, 84.957, 179.033, 0.052], [nan, nan, nan, nan]]
    """
    branches = _np.asarray(branches)
    working_mask = _np.asarray(working_mask, dtype=bool)
    if branches.ndim != 3 or working_mask.shape != branches.shape[:2]:
        raise ValueError(
            f"expected branches of shape (N, K, 4) and working of shape (N, K), found "
            f"{branches.shape} and {working_mask.shape}"
        )
    out = _np.full((branches.shape[0], branches.shape[2]), _np.nan)
    has = working_mask.any(axis=1)
    first = working_mask.argmax(axis=1)
    rows = _np.nonzero(has)[0]
    out[rows] = branches[rows, first[rows]]
    return out
