"""Exact, all-branch kinematics of the VERNE parallel kinematic machine tool, from NumPy.

Lengths are in mm, angles in radians. Every function takes float64 arrays of shape (N, k) and
returns arrays of N rows; a row that cannot be solved is an answer in its status or count
(NaN where there is no value), never an exception. Wrong shapes raise ValueError.

>>> import numpy as np, verne
>>> m = verne.Machine.default()
>>> branches, config, working, count, proved = verne.module_ik(m, np.array([[-240.0, -86.0, 1000.0]]))
>>> int(count[0]), bool(proved[0])
(16, True)
>>> w = verne.working(branches, working)        # the machine's branch: rho1, rho2, rho3, alpha
>>> modes, _, mw, n, _ = verne.module_fk(m, w[:, :3])
>>> bool(np.allclose(verne.working(modes, mw)[0, :3], [-240.0, -86.0, 1000.0]))
True
"""

import numpy as _np

from ._verne import (  # noqa: F401
    GLIDER_NODE_CLASSES,
    INVALID_INPUT,
    NO_WORKING_BRANCH,
    OK,
    OUTCOMES,
    UNREACHABLE,
    Glider,
    Machine,
    design_tables,
    glider_fk,
    glider_ik,
    glider_workspace,
    ik_path,
    jacobian,
    kinetostatics,
    machine_fk,
    machine_fk_working,
    machine_ik,
    module_fk,
    module_fk_compact,
    module_ik,
    module_ik_compact,
    module_ik_working,
    verify,
    workspace,
)

__all__ = [
    "Machine",
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
