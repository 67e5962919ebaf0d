"""The glider mechanisms from Python against `verne ik/fk/workspace -m GLIDER` and round
trips."""

import math
import re

import numpy as np
import pytest
from oracle import cli, run

import verne


def test_presets_and_files():
    g = verne.Glider.preset("orthoglide")
    assert g.name == "orthoglide"
    assert verne.Glider.from_toml(g.to_toml()).to_toml() == g.to_toml()
    with pytest.raises(ValueError, match="biglide1, biglide2, orthoglide"):
        verne.Glider.preset("triglide")
    # The design rule of section 3.2 gives the presets back (they are dimensioned by it).
    for name in ("biglide1", "biglide2", "orthoglide"):
        d = verne.Glider.design(name)
        assert np.allclose(d.joint_ranges, verne.Glider.preset(name).joint_ranges, atol=1e-6)
    assert verne.Glider.design("orthoglide", l=2.0).joint_ranges[0][1] == pytest.approx(
        2 * verne.Glider.design("orthoglide").joint_ranges[0][1]
    )


@pytest.mark.parametrize("name", ["biglide1", "biglide2", "orthoglide"])
def test_glider_fk_and_ik_are_the_cli(name):
    g = verne.Glider.preset(name)
    (lo1, hi1), (lo2, hi2) = g.joint_ranges
    rho = np.array([[lo1 + f * (hi1 - lo1), lo2 + e * (hi2 - lo2)] for f in (0.2, 0.5, 0.8) for e in (0.3, 0.6)])
    (pts, mode, assembly, ok, count), structural = verne.glider_fk(g, rho)
    args = [f"--joints={float(r[0])!r},{float(r[1])!r}" for r in rho]
    rows = [r for r in cli("fk", "-m", name, "--all", *args) if r["x"] != ""]
    k = 0
    for i in range(len(rho)):
        n = int(count[i])
        mine = sorted((round(pts[i, s, 0], 7), round(pts[i, s, 1], 7), bool(ok[i, s])) for s in range(n))
        theirs = sorted(
            (round(float(r["x"]), 7), round(float(r["y"]), 7), r["status"] == "ok") for r in rows[k : k + n]
        )
        assert mine == theirs
        k += n
    assert k == len(rows) and not structural.any()
    # IK of the machine's FK solutions: the joints back, in the ok solution.
    sel = ok.any(axis=1)
    p = np.array([pts[i, np.argmax(ok[i])] for i in np.nonzero(sel)[0]])
    r, m, a, iok, icount = verne.glider_ik(g, p)
    for i, row in enumerate(np.nonzero(sel)[0]):
        good = [s for s in range(icount[i]) if iok[i, s]]
        assert len(good) == 1 and np.allclose(r[i, good[0]], rho[row], atol=1e-9)
        assert list(m[i, good[0]]) == [1, 1] and a[i, good[0]] == 1
    rows = [x for x in cli("ik", "-m", name, "--all", *[f"--pose={float(q[0])!r},{float(q[1])!r}" for q in p])]
    assert len(rows) == icount.sum()


def test_glider_workspace_is_the_cli():
    g = verne.Glider.preset("orthoglide")
    w = verne.glider_workspace(g)
    _, text = run("workspace", "-m", "orthoglide")
    area = float(re.search(r"t-connected region of .*: area ([\d.]+)", text).group(1))
    square = float(re.search(r"largest square: [\d.]+ x [\d.]+ = ([\d.]+)", text).group(1))
    assert math.isclose(w["region_area"], area, rel_tol=1e-6)
    assert math.isclose(w["largest_square"]["area"], square, rel_tol=1e-6)
    assert w["largest_square"]["angle"] == pytest.approx(math.pi / 4)
    assert w["class"].shape == w["region"].shape == w["x"].shape
    admissible = verne.GLIDER_NODE_CLASSES.index("admissible")
    assert (w["region"] <= (w["class"] == admissible)).all()
    assert w["region"].sum() * w["step"] ** 2 == pytest.approx(w["region_area"])
    # Without the kinetostatic bound the region can only grow.
    free = verne.glider_workspace(g, lambda_bounds=False)
    assert free["region_area"] >= w["region_area"]
    with pytest.raises(ValueError, match="mode"):
        verne.glider_workspace(g, mode="+0")
    with pytest.raises(ValueError, match="nodes"):
        verne.glider_workspace(g, nodes=1)
    with pytest.raises(ValueError, match="sampling"):
        verne.glider_workspace(g, sampling="sparse")


def test_glider_workspace_adaptive_is_the_uniform_grid():
    for name in ("biglide1", "biglide2", "orthoglide"):
        g = verne.Glider.preset(name)
        u = verne.glider_workspace(g, nodes=601, sampling="uniform")
        a = verne.glider_workspace(g, nodes=601, sampling="adaptive")
        assert (u["class"] == a["class"]).all() and (u["region"] == a["region"]).all()
        assert u["largest_rectangle"] == a["largest_rectangle"]
        assert u["region_area_sampled"] == a["region_area_sampled"]
        assert u["coarse_step"] is None and a["coarse_step"] == pytest.approx(8 * a["step"])
        assert a["classified"] * 3 < u["classified"]
        lo, hi = a["region_area_bounds"]
        assert lo <= a["region_area"] <= hi
        assert abs(a["region_area_sampled"] - a["region_area"]) <= hi - lo
    # The default grid (801 nodes) is adaptive, and reports the CLI's count of points.
    w = verne.glider_workspace(verne.Glider.preset("orthoglide"))
    _, text = run("workspace", "-m", "orthoglide")
    classified = int(re.search(r"(\d+) points classified", text).group(1))
    assert w["coarse_step"] is not None and w["classified"] == classified


def test_glider_bad_rows():
    g = verne.Glider.preset("biglide1")
    (r, _, _, _, count) = verne.glider_ik(g, np.array([[np.nan, 0.0], [1e6, 1e6]]))
    assert list(count) == [0, 0] and np.isnan(r).all()
    with pytest.raises(ValueError, match=r"\(N, 2\)"):
        verne.glider_ik(g, np.zeros((2, 3)))


def test_design_tables_are_verne_design():
    mine = verne.design_tables(nodes=301)
    stdout, _ = run("design", "--csv", "--nodes", "301")
    rows = [line.split(",") for line in stdout.strip().splitlines()[1:]]
    header = stdout.splitlines()[0].split(",")
    assert header[:6] == ["table", "mechanism", "target", "quantity", "unit", "computed"]
    t1 = {r["mechanism"]: r for r in mine["table1"]}
    t2 = {(r["mechanism"], r["target"]): r for r in mine["table2"]}
    checked = 0
    for table, mech, target, quantity, _, computed, *_ in rows:
        row = t1[mech] if table == "1" else t2[(mech, target)]
        if quantity in row:
            assert row[quantity] == pytest.approx(float(computed), rel=1e-12), (table, mech, quantity)
            checked += 1
    assert len(mine["table1"]) == 3 and len(mine["table2"]) == 6 and checked >= 30
    # Table 1 against the paper (printed to three or four digits): L0 and delta-rho within 0.5 %.
    assert all(abs(r["l0_rel_diff"]) < 5e-3 for r in mine["table1"])
    assert all(abs(r["delta_rho_rel_diff"]) < 5e-3 for r in mine["table1"])
    with pytest.raises(ValueError, match="nodes"):
        verne.design_tables(nodes=1)
