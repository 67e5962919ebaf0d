"""The 5-axis machine, machine files as dicts and the kinetostatics, against the `verne` command
line, round trips and finite differences."""

import re

import numpy as np
import pytest
from oracle import cli

import verne

M = verne.Machine.default()


def test_machine_from_dict_and_back():
    m = verne.Machine.from_dict({"base": "verne", "tool": {"length": 120}})
    assert m.tool_length == 120.0
    # The whole machine as a dict and back, NumPy scalars accepted as numbers.
    d = M.to_dict()
    assert d["tool"]["length"] == 50.0
    assert verne.Machine.from_dict(d).to_toml() == M.to_toml()
    d["tool"]["length"] = np.float64(75.0)
    assert verne.Machine.from_dict(d).tool_length == 75.0
    # Every problem by key, no line numbers of a file the caller never wrote.
    with pytest.raises(ValueError) as e:
        verne.Machine.from_dict({"base": "verne", "module": {"L1": -5, "R9": 1.0}})
    text = str(e.value)
    assert "2 problems" in text and "module.L1" in text and "module.R9" in text
    assert not re.search(r"<dict>:\d", text)
    with pytest.raises(TypeError, match=r"tool\.length"):
        verne.Machine.from_dict({"base": "verne", "tool": {"length": object()}})
    with pytest.raises(TypeError, match="keys must be strings"):
        verne.Machine.from_dict({1: 2})


def poses():
    """Tool poses: tilted both ways, vertical (inside the rotary-singularity cone), one out of
    reach."""
    tips = np.array([[80, 0, 30], [15.68, 0, 49.18], [0, 0, 100], [-40, 30, 20], [1e9, 0, 0]], float)
    axes = np.array(
        [[0.342020, 0, 0.939693], [0.1045285, 0, 0.9945219], [0, 0, 1], [-0.2, 0.3, 0.9], [0, 0, 1]],
        float,
    )
    return tips, axes / np.linalg.norm(axes, axis=1)[:, None]


def test_machine_ik_is_verne_ik_all():
    tips, axes = poses()
    q, orientation, config, working, count, proved = verne.machine_ik(M, tips, axes)
    assert q.shape == (5, 48, 5) and orientation.dtype == np.int8 and working.dtype == bool
    text = "x,y,z,i,j,k\n" + "".join(
        ",".join(repr(float(v)) for v in np.r_[t, a]) + "\n" for t, a in zip(tips, axes)
    )
    rows = [r for r in cli("ik", "--all", "--radians", stdin=text) if r["rho1"] != ""]
    k = 0
    for i in range(len(tips)):
        n = int(count[i])
        mine = sorted(
            tuple(np.round(np.r_[q[i, s], orientation[i, s], working[i, s]], 7)) for s in range(n)
        )
        cols = ("rho1", "rho2", "rho3", "theta1", "theta2")
        theirs = sorted(
            tuple(
                np.round(
                    [float(r[c]) for c in cols]
                    + [int(r["orientation"]), r["working"] == "true"],
                    7,
                )
            )
            for r in rows[k : k + n]
        )
        assert mine == theirs, i
        k += n
    assert k == len(rows)
    assert count[4] == 0 and proved[4]  # out of reach, proved
    assert (working[:4].sum(axis=1) >= 1).all()
    # Every branch's forward kinematics in its own configuration gives the pose back.
    for i in range(4):
        n = int(count[i])
        t, a, c, _, fn, _ = verne.machine_fk(M, q[i, :n])
        for s in range(n):
            mode = [m for m in range(fn[s]) if (c[s, m] == config[i, s]).all()]
            assert any(
                np.allclose(t[s, m], tips[i], atol=1e-6) and np.allclose(a[s, m], axes[i], atol=1e-9)
                for m in mode
            ), (i, s)


def test_machine_fk_is_verne_fk_all():
    joints = np.array([[500, 600, 400, 0.2, 0.3], [367.6, 320.9, 307.6, -0.355, -1.5708]], float)
    tips, axes, config, working, count, proved = verne.machine_fk(M, joints)
    assert tips.shape == (2, 16, 3) and proved.all()
    text = "rho1,rho2,rho3,theta1,theta2\n" + "".join(
        ",".join(repr(float(v)) for v in j) + "\n" for j in joints
    )
    rows = cli("fk", "--all", "--radians", stdin=text)
    k = 0
    for i in range(len(joints)):
        n = int(count[i])
        mine = sorted(tuple(np.round(np.r_[tips[i, s], axes[i, s]], 6)) for s in range(n))
        theirs = sorted(
            tuple(np.round([float(r[c]) for c in "xyzijk"], 6)) for r in rows[k : k + n]
        )
        assert mine == theirs
        assert sum(r["working"] == "true" for r in rows[k : k + n]) == working[i].sum()
        k += n
    assert k == len(rows)
    # The working mode alone is machine_fk_working's.
    t, a, st = verne.machine_fk_working(M, joints)
    for i in range(len(joints)):
        w = np.nonzero(working[i])[0]
        assert len(w) == 1 and np.allclose(tips[i, w[0]], t[i]) and np.allclose(axes[i, w[0]], a[i])


def test_bad_machine_rows_are_answers():
    q, _, _, _, count, proved = verne.machine_ik(
        M, np.array([[np.nan, 0, 0], [0, 0, 100.0]]), np.array([[0, 0, 1.0], [0, 0, 0.0]])
    )
    assert list(count) == [0, 0] and not proved.any() and np.isnan(q).all()
    with pytest.raises(ValueError, match="one axis per tip"):
        verne.machine_ik(M, np.zeros((2, 3)), np.zeros((3, 3)))
    t, _, _, _, count, proved = verne.machine_fk(M, np.array([[np.nan, 0, 0, 0, 0]]))
    assert count[0] == 0 and not proved[0]
    with pytest.raises(ValueError, match=r"\(N, 5\)"):
        verne.machine_fk(M, np.zeros((1, 3)))
    assert verne.machine_ik(M, np.zeros((0, 3)), np.zeros((0, 3)))[0].shape == (0, 48, 5)


def test_kinetostatics_against_finite_differences():
    # Points of the workspace, their working branch, the Jacobians there.
    pts = np.array([[-240.0, -86.0, 1000.0], [0.0, 0.0, 1200.0], [100.0, 150.0, 1100.0]])
    b, _, w, _, _ = verne.module_ik(M, pts)
    br = verne.working(b, w)
    sliders = br[:, :3]
    posed = np.column_stack([pts, br[:, 3]])
    A, B = verne.jacobian(M, posed, sliders)
    assert A.shape == (3, 4, 4) and B.shape == (3, 4, 3)
    k = verne.kinetostatics(M, posed, sliders)
    h = 1e-4
    for i in range(len(pts)):
        # d rho / d P by central differences of the working branch (an independent route).
        d_rho = np.zeros((3, 3))
        for c in range(3):
            e = np.zeros(3)
            e[c] = h
            plus = verne.module_ik_working(M, (pts[i] + e)[None])[0][0]
            minus = verne.module_ik_working(M, (pts[i] - e)[None])[0][0]
            d_rho[:, c] = (plus - minus) / (2 * h)
        # The map from slider rates to the velocity of P: first three rows of -A^-1 B.
        J = -np.linalg.solve(A[i], B[i])
        assert np.allclose(J[:3] @ d_rho, np.eye(3), atol=1e-5)
        assert np.allclose(k["amplification"][i], np.linalg.svd(J[:3], compute_uv=False), rtol=1e-9)
        assert np.allclose(k["rotation_rate"][i], J[3], rtol=1e-9, atol=1e-15)
        assert 0 < k["parallel_margin"][i] <= 1 and 0 < k["serial_margin"][i] <= 1
    # Table III's first mode is far from singular; det A changes sign only across a singularity.
    assert (np.abs(k["det_a"]) > 0).all()
    with pytest.raises(ValueError, match="one slider triple per pose"):
        verne.kinetostatics(M, posed, sliders[:2])


# Every array function: an empty batch gives empty results of the documented shapes, one row
# gives one row.
CASES = [
    ("module_ik", lambda n: (M, np.zeros((n, 3)) + [-240.0, -86.0, 1000.0])),
    ("module_ik_compact", lambda n: (M, np.zeros((n, 3)) + [-240.0, -86.0, 1000.0])),
    ("module_ik_working", lambda n: (M, np.zeros((n, 3)) + [-240.0, -86.0, 1000.0])),
    ("module_fk", lambda n: (M, np.zeros((n, 3)) + [674.0, 685.0, 250.0])),
    ("module_fk_compact", lambda n: (M, np.zeros((n, 3)) + [674.0, 685.0, 250.0])),
    ("ik_path", lambda n: (M, np.zeros((n, 3)) + [80.0, 0, 30], np.zeros((n, 3)) + [0, 0, 1.0])),
    ("machine_ik", lambda n: (M, np.zeros((n, 3)) + [80.0, 0, 30], np.zeros((n, 3)) + [0, 0, 1.0])),
    ("machine_fk", lambda n: (M, np.zeros((n, 5)) + [500.0, 600, 400, 0.2, 0.3])),
    ("machine_fk_working", lambda n: (M, np.zeros((n, 5)) + [500.0, 600, 400, 0.2, 0.3])),
    ("jacobian", lambda n: (M, np.zeros((n, 4)) + [0, 0, 1200.0, 0], np.zeros((n, 3)) + 500.0)),
    ("glider_ik", lambda n: (verne.Glider.preset("orthoglide"), np.zeros((n, 2)) + [0.9, 1.2])),
    ("glider_fk", lambda n: (verne.Glider.preset("orthoglide"), np.zeros((n, 2)) + [0.5, 0.6])),
]


def first_array(result):
    while isinstance(result, tuple):
        result = result[0]
    return result


@pytest.mark.parametrize("name,args", CASES)
def test_empty_and_one_row_batches(name, args):
    f = getattr(verne, name)
    empty = first_array(f(*args(0)))
    one = first_array(f(*args(1)))
    assert empty.shape[0] == 0 and one.shape[0] >= 1, (empty.shape, one.shape)
    assert empty.shape[1:] == one.shape[1:] or name.endswith("_compact")
    k = verne.kinetostatics(M, *args(0)[1:]) if name == "jacobian" else None
    if k is not None:
        assert all(v.shape[0] == 0 for v in k.values())


def test_kinetostatics_is_verne_modes():
    # Table III's four assembly modes: det A, the extreme amplification factors and the margins
    # of `verne modes --csv`, mode for mode.
    modes, _, _, count, _ = verne.module_fk(M, np.array([[674.0, 685.0, 250.0]]))
    n = int(count[0])
    poses = modes[0, :n]
    k = verne.kinetostatics(M, poses, np.tile([674.0, 685.0, 250.0], (n, 1)))
    rows = cli("modes", "--joints", "674,685,250", "--csv", "--radians")
    assert len(rows) == n
    for r in rows:
        i = int(np.argmin(np.abs(poses[:, 0] - float(r["xp"])) + np.abs(poses[:, 2] - float(r["zp"]))))
        assert k["det_a"][i] == pytest.approx(float(r["det_a"]), rel=1e-9)
        assert k["amplification"][i].min() == pytest.approx(float(r["lambda_min"]), rel=1e-9)
        assert k["amplification"][i].max() == pytest.approx(float(r["lambda_max"]), rel=1e-9)
        assert k["parallel_margin"][i] == pytest.approx(float(r["parallel_margin"]), rel=1e-9)
        assert k["serial_margin"][i] == pytest.approx(float(r["serial_margin"]), rel=1e-9)
