"""The `verne` command line as the tests' oracle: built by scripts/python-test.sh and named by
VERNE_BIN."""

import os
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
BIN = os.environ.get("VERNE_BIN", str(ROOT / "target" / "release" / "verne"))


def run(*args, stdin=None):
    """stdout and stderr of `verne ARGS`, which must exit 0 or 1 (some rows not ok)."""
    out = subprocess.run([BIN, *args], input=stdin, capture_output=True, text=True, cwd=ROOT)
    assert out.returncode in (0, 1), out.stderr
    return out.stdout, out.stderr


def cli(*args, stdin=None):
    """The CSV rows `verne ARGS` writes on stdout, as dicts."""
    stdout, _ = run(*args, stdin=stdin)
    lines = stdout.strip().splitlines()
    header = lines[0].split(",")
    return [dict(zip(header, line.split(","))) for line in lines[1:]]


def csv_rows(path):
    """A CSV file of the repository as dicts of strings."""
    lines = (ROOT / path).read_text().strip().splitlines()
    header = lines[0].split(",")
    return [dict(zip(header, line.split(","))) for line in lines[1:]]
