"""The Python package against the reference results, the `verne` command line (the oracle,
built by scripts/python-test.sh and named by VERNE_BIN), and round trips."""

import numpy as np
import pytest
from oracle import ROOT, cli

import verne


M = verne.Machine.default()


def test_machine_files():
    assert M.name == "VERNE" and M.tool_length == 50.0
    again = verne.Machine.from_toml(M.to_toml())
    assert again.to_toml() == M.to_toml()
    short = verne.Machine.from_toml('base = "verne"\n[tool]\nlength = 120\n')
    assert short.tool_length == 120.0
    with pytest.raises(ValueError, match="L1"):
        verne.Machine.from_toml('base = "verne"\n[module]\nL1 = -5\n')
    with pytest.raises(OSError):
        verne.Machine.from_file("/nonexistent/machine.toml")
    f = verne.Machine.from_file(str(ROOT / "data" / "verne.toml"))
    assert f.to_toml() == M.to_toml()


def test_inverse_kinematics_reference_pose():
    # docs/reference-results.md: P = (-240, -86, 1000) has sixteen real branches, four alphas.
    b, config, working, count, proved = verne.module_ik(M, np.array([[-240.0, -86.0, 1000.0]]))
    assert b.shape == (1, 24, 4) and config.dtype == np.int8 and working.dtype == bool
    assert count[0] == 16 and proved[0]
    alphas = np.unique(np.round(b[0, :16, 3], 6))
    assert np.allclose(alphas, [-2.911159, -0.052205, 0.052205, 2.911159], atol=1e-6)
    assert np.isnan(b[0, 16:]).all()
    w = verne.working(b, working)
    assert np.allclose(w[0], [368.354796, 84.956547, 179.032689, 0.052204524], atol=1e-6)
    assert working[0].sum() == 1


def test_forward_kinematics_table_iii():
    modes, config, working, count, proved = verne.module_fk(M, np.array([[674.0, 685.0, 250.0]]))
    assert count[0] == 4 and proved[0]
    got = modes[0, :4][np.argsort(modes[0, :4, 3])]
    want = np.array(
        [
            [-199.799382, 355.845336, 1242.022753, -0.226839103],
            [298.353956, -297.553100, -120.221391, -0.140850326],
            [-393.585767, 322.872468, 958.203620, 1.812420577],
            [-115.625453, -189.660908, -0.280803, 2.699989141],
        ]
    )
    assert np.allclose(got, want[np.argsort(want[:, 3])], atol=1e-5)
    assert np.allclose(verne.working(modes, working)[0], want[0], atol=1e-5)


def test_module_against_the_cli_and_back():
    rng = np.random.default_rng(7)
    pts = np.column_stack(
        [rng.uniform(-300, 300, 40), rng.uniform(-300, 300, 40), rng.uniform(700, 1300, 40)]
    )
    b, _, working, count, proved = verne.module_ik(M, pts)
    args = []
    for p in pts:
        args += ["--pose=" + ",".join(repr(float(v)) for v in p)]
    rows = cli("ik", "--all", "--radians", *args)
    # The CLI's --all rows, grouped by point in order: the same counts and sliders.
    k = 0
    for i in range(len(pts)):
        n = int(count[i])
        mine = np.sort(b[i, :n, :3], axis=0)
        if n == 0:
            assert rows[k]["status"] in ("unreachable", "uncertified")
            k += 1
            continue
        theirs = np.sort(
            np.array([[float(r["rho1"]), float(r["rho2"]), float(r["rho3"])] for r in rows[k : k + n]]),
            axis=0,
        )
        assert np.allclose(mine, theirs, atol=1e-9), i
        k += n
    assert k == len(rows)
    # The shortcut finds the same working branch as the complete solution.
    w = verne.working(b, working)
    fast, alpha, status = verne.module_ik_working(M, pts)
    same = ~np.isnan(w[:, 0])
    assert (status[same] == verne.OK).all() and (status[~same] != verne.OK).all()
    assert np.allclose(fast[same], w[same, :3], atol=1e-9)
    assert np.allclose(alpha[same], w[same, 3], atol=1e-12)
    # Round trip: the working sliders' forward kinematics give the point back.
    ok = ~np.isnan(w[:, 0])
    assert ok.sum() > 10
    modes, _, mw, _, _ = verne.module_fk(M, w[ok, :3])
    assert np.allclose(verne.working(modes, mw)[:, :3], pts[ok], atol=1e-6)


def test_the_path_follower_is_verne_ik():
    rows = cli("ik", "data/example.cl")
    tips = np.array([[float(r[c]) for c in "xyz"] for r in rows])
    axes = np.array([[float(r[c]) for c in "ijk"] for r in rows])
    joints, orientation, status = verne.ik_path(M, tips, axes)
    assert (status == verne.OK).all()
    want = np.array(
        [[float(r[c]) for c in ("rho1", "rho2", "rho3", "theta1", "theta2")] for r in rows]
    )
    want[:, 3:] = np.radians(want[:, 3:])
    assert np.allclose(joints, want, atol=1e-9)
    assert (orientation == np.array([int(r["orientation"]) for r in rows])).all()
    # prefer=orientation2 as --prefer orientation2.
    rows2 = cli("ik", "--prefer", "orientation2", "data/example.cl")
    j2, o2, _ = verne.ik_path(M, tips, axes, prefer="orientation2")
    assert (o2 == np.array([int(r["orientation"]) for r in rows2])).all()
    # Forward kinematics of those joints: the path back.
    t, a, st = verne.machine_fk_working(M, joints)
    assert (st == verne.OK).all()
    assert np.allclose(t, tips, atol=1e-6) and np.allclose(a, axes, atol=1e-9)


def test_bad_rows_are_answers_and_bad_shapes_errors():
    pts = np.array([[np.nan, 0, 1000], [1e9, 0, 1000], [-240, -86, 1000]], dtype=float)
    b, _, working, count, proved = verne.module_ik(M, pts)
    assert count[0] == 0 and count[1] == 0 and count[2] == 16
    tips = np.array([[0, 0, 100], [np.inf, 0, 0], [1e9, 0, 0], [0, 0, 100]], dtype=float)
    axes = np.array([[0, 0, 1], [0, 0, 1], [0, 0, 1], [0, 0, 0]], dtype=float)
    _, _, status = verne.ik_path(M, tips, axes)
    assert list(status) == [verne.OK, verne.INVALID_INPUT, verne.UNREACHABLE, verne.INVALID_INPUT]
    _, _, st = verne.machine_fk_working(M, np.array([[np.nan, 0, 0, 0, 0], [1e6, 1e6, 1e6, 0, 0]]))
    assert st[0] == verne.INVALID_INPUT and st[1] in (verne.UNREACHABLE, verne.NO_WORKING_BRANCH)
    with pytest.raises(ValueError, match=r"\(N, 3\)"):
        verne.module_ik(M, np.zeros((4, 2)))
    with pytest.raises(ValueError, match="one axis per tip"):
        verne.ik_path(M, np.zeros((3, 3)), np.zeros((2, 3)))
    with pytest.raises(ValueError, match="prefer"):
        verne.ik_path(M, np.zeros((1, 3)), np.array([[0, 0, 1.0]]), prefer="up")
    with pytest.raises(TypeError):
        verne.module_ik(M, [[1, 2, 3]])
    # Empty and one-row arrays.
    b, c, w, n, p = verne.module_ik(M, np.zeros((0, 3)))
    assert b.shape == (0, 24, 4) and n.shape == (0,)
    j, o, s = verne.ik_path(M, np.array([[0, 0, 100.0]]), np.array([[0, 0, 1.0]]))
    assert j.shape == (1, 5) and s[0] == verne.OK


def test_compact_and_padded_forms_agree():
    rng = np.random.default_rng(3)
    pts = np.column_stack(
        [rng.uniform(-300, 300, 200), rng.uniform(-300, 300, 200), rng.uniform(700, 1300, 200)]
    )
    b, c, w, n, p = verne.module_ik(M, pts)
    cb, cc, cw, idx, off, cp = verne.module_ik_compact(M, pts)
    assert off[0] == 0 and off[-1] == len(cb) and (np.diff(off) == n).all()
    assert (cp == p).all()
    for i in range(len(pts)):
        assert (idx[off[i] : off[i + 1]] == i).all()
        assert np.array_equal(cb[off[i] : off[i + 1]], b[i, : n[i]])
        assert np.array_equal(cc[off[i] : off[i + 1]], c[i, : n[i]])
        assert np.array_equal(cw[off[i] : off[i + 1]], w[i, : n[i]])
    sl = verne.working(b, w)[:, :3]
    sl = sl[~np.isnan(sl[:, 0])]
    fb, _, fw, fn, _ = verne.module_fk(M, sl)
    cfb, _, _, _, foff, _ = verne.module_fk_compact(M, sl)
    assert (np.diff(foff) == fn).all() and np.array_equal(cfb, fb[~np.isnan(fb[:, :, 0])])


def test_results_are_named_and_unpack_in_order():
    """Each result names its arrays in the order they unpack; the names are the ones the stubs
    declare; statuses are `Status` values equal to the integers."""
    pts = np.array([[-240.0, -86.0, 1000.0], [1e4, 0.0, 0.0]])
    ik = verne.module_ik(M, pts)
    assert isinstance(ik, verne.ModuleBranches)
    b, c, w, n, p = ik
    assert ik.branches is b and ik.config is c and ik.working is w and ik.count is n and ik.proved is p
    assert n.tolist() == [16, 0]
    assert np.array_equal(ik.working_branch(), verne.working(b, w), equal_nan=True)
    sl, alpha, status = verne.module_ik_working(M, pts)
    assert verne.module_ik_working(M, pts).status.tolist() == status.tolist()
    assert [verne.Status(s) for s in status] == [verne.Status.OK, verne.Status.UNREACHABLE]
    assert verne.OK == 0 and verne.Status.INVALID_INPUT == 3
    tips = np.array([[80.0, 0.0, 30.0]])
    axes = np.array([[0.342020, 0.0, 0.939693]])
    path = verne.ik_path(M, tips, axes)
    back = verne.machine_fk_working(M, path.joints)
    assert np.allclose(back.tips, tips, atol=1e-6) and back.status.tolist() == [verne.Status.OK]
    every = verne.machine_ik(M, tips, axes)
    assert every.count[0] >= 1 and np.isfinite(every.working_branch()).all()
    modes = verne.machine_fk(M, path.joints)
    assert np.allclose(modes.tips[0][modes.working[0]][0], tips[0], atol=1e-6)
    g = verne.Glider.preset("orthoglide")
    fk = verne.glider_fk(g, np.array([[0.5, 0.6]]))
    assert fk.solutions.count.tolist() == [2] and fk.structural.tolist() == [False]
    # The stubs declare the same fields, in the same order.
    import ast
    import pathlib

    stub = pathlib.Path(verne.__file__).with_suffix(".pyi")
    classes = {
        node.name: [f.target.id for f in node.body if isinstance(f, ast.AnnAssign)]
        for node in ast.parse(stub.read_text()).body
        if isinstance(node, ast.ClassDef)
    }
    for name in ["ModuleBranches", "CompactBranches", "ModuleWorking", "PathJoints", "ToolPoses",
                 "MachineBranches", "MachineModes", "Jacobians", "GliderSolutions", "GliderModes",
                 "Verification"]:
        assert classes[name] == list(getattr(verne, name)._fields), name
