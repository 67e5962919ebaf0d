"""verify and workspace from Python against `verne verify` and `verne workspace`."""

import math
import re

import numpy as np
import pytest
from oracle import ROOT, csv_rows, run

import verne

M = verne.Machine.default()


def tables(joints_file):
    j = csv_rows(joints_file)
    p = csv_rows("data/verify/path.csv")
    q = np.array([[float(r[c]) for c in ("rho1", "rho2", "rho3", "theta1", "theta2")] for r in j])
    q[:, 3:] = np.radians(q[:, 3:])
    t = np.array([float(r["t"]) for r in j])
    tips = np.array([[float(r[c]) for c in "xyz"] for r in p])
    axes = np.array([[float(r[c]) for c in "ijk"] for r in p])
    return q, t, tips, axes


def test_verify_finds_what_verne_verify_finds(tmp_path):
    q, t, tips, axes = tables("data/verify/joints_defects.csv")
    found, summary = verne.verify(M, q, tips, axes, t=t)
    report = tmp_path / "r.csv"
    run(
        "verify",
        "--joints",
        "data/verify/joints_defects.csv",
        "--path",
        "data/verify/path.csv",
        "--report",
        str(report),
    )
    lines = report.read_text().strip().splitlines()[1:]
    theirs = [(ln.split(",")[0], ln.split(",")[1], float(ln.split(",")[2])) for ln in lines]
    mine = [(f["row"], f["check"], f["value"]) for f in found]
    # The defects injected into the table (docs/verify.md), and the gouges of its jumps.
    assert len(mine) == len(theirs) >= 8
    for (r1, c1, v1), (r2, c2, v2) in zip(mine, theirs):
        assert (r1, c1) == (r2, c2) and math.isclose(v1, v2, rel_tol=1e-6)
    assert not summary["clean"] and summary["rows"] == 3000 and summary["timed"]
    assert summary["checks"]["tip_error"]["count"] == 2
    # The clean table is clean; a tighter threshold turns its chordal error into findings.
    q, t, tips, axes = tables("data/verify/joints.csv")
    found, summary = verne.verify(M, q, tips, axes, t=t)
    assert found == [] and summary["clean"]
    found, _ = verne.verify(M, q, tips, axes, t=t, thresholds={"chord_error_mm": 1e-5})
    assert found and all(f["check"] == "chord_error" for f in found)


def test_verify_bad_input():
    q, t, tips, axes = tables("data/verify/joints.csv")
    q, t, tips, axes = q[:5].copy(), t[:5].copy(), tips[:5], axes[:5]
    t[2] = np.nan
    found, summary = verne.verify(M, q, tips, axes, t=t)
    assert [f["check"] for f in found] == ["input"] and found[0]["row"] == "3"
    with pytest.raises(ValueError, match="one intended pose per joint row"):
        verne.verify(M, q[:4], tips, axes)
    with pytest.raises(ValueError, match="tip_error_mm"):
        verne.verify(M, q, tips, axes, thresholds={"tip_error_mm": -1})
    with pytest.raises(ValueError, match="no_such"):
        verne.verify(M, q, tips, axes, thresholds={"no_such": 1})
    with pytest.raises(ValueError, match="one of them"):
        verne.verify(M, q, tips, axes, t=t, feed=t)


def summary_number(text, pattern):
    return float(re.search(pattern, text).group(1))


def test_workspace_is_verne_workspace():
    w = verne.workspace(M, step=40, points=True)
    _, text = run("workspace", "--step", "40", "-o", "-")
    assert w["method"] == "uniform" and w["points"] == 31050
    assert w["inside"] == summary_number(text, r"\((\d+) points inside")
    assert math.isclose(w["volume_litres"], summary_number(text, r"volume\s+([\d.]+) l"), rel_tol=1e-5)
    assert w["largest_box"]["volume_mm3"] == pytest.approx(
        summary_number(text, r"= ([\d.]+) l\n") * 1e6, rel=1e-5
    )
    # Every point with its outcome: the inside points are the summary's.
    assert w["grid_points"].shape == (31050, 3)
    assert (w["outcome"] == verne.OUTCOMES.index("inside")).sum() == w["inside"]
    assert sum(w["binding"].values()) == w["points"]
    # Adaptive: the bracket holds the uniform estimate at the same step, as the CLI's.
    a = verne.workspace(M, step=20, adaptive=True)
    text, _ = run("workspace", "--step", "20", "--adaptive")
    u = verne.workspace(M, step=20, adaptive=False)
    assert a["volume_lo_mm3"] <= u["volume_mm3"] <= a["volume_hi_mm3"]
    assert a["inside"] == u["inside"]
    assert str(a["classified"]) in text.replace(",", "")
    # The largest box: at 20 mm searched exhaustively, the uniform grid's, its bound itself.
    assert a["box_exact"]
    for key in ("largest_box", "largest_cube"):
        assert a[key]["volume_mm3"] == pytest.approx(u[key]["volume_mm3"], rel=1e-12)
        assert a[key]["min"] == pytest.approx(u[key]["min"]) and a[key]["max"] == pytest.approx(u[key]["max"])
        assert a[key]["upper_bound_mm3"] == a[key]["volume_mm3"]
    cube = u["largest_cube"]["volume_mm3"]
    edges = [hi - lo for lo, hi in zip(u["largest_cube"]["min"], u["largest_cube"]["max"])]
    assert max(edges) - min(edges) < 1e-9 and cube == pytest.approx(edges[0] ** 3)
    assert math.isclose(
        a["largest_box"]["volume_mm3"] * 1e-6, summary_number(text, r"largest box .* mm = ([\d.]+) l"), abs_tol=1e-3
    )
    # The boundary sample: the CLI's estimate, inside the bracket.
    assert a["volume_lo_mm3"] <= a["volume_sampled_mm3"] <= a["volume_hi_mm3"]
    assert 0 < a["sampled_cells"] <= a["boundary_cells"]
    assert math.isclose(
        a["volume_sampled_mm3"] * 1e-6, summary_number(text, r"boundary sampled\s+([\d.]+) l"), abs_tol=1e-4
    )
    with pytest.raises(ValueError, match="adaptive=False"):
        verne.workspace(M, step=2, points=True)
    with pytest.raises(ValueError, match="of="):
        verne.workspace(M, of="table")
    with pytest.raises(ValueError, match="step"):
        verne.workspace(M, step=-10)
    t = verne.workspace(M, of="tool", step=40, tool_length=0)
    assert t["inside"] == w["inside"]  # a tool of length 0 is the platform point
    assert ROOT.exists()
