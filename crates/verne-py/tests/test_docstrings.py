"""Every public function of the package has a runnable example in its docstring, and the
examples give what they say (run with `m = verne.Machine.default()` and NumPy as `np`)."""

import doctest

import numpy as np
import pytest

import verne

FUNCTIONS = [
    name
    for name in verne.__all__
    if callable(getattr(verne, name)) and not isinstance(getattr(verne, name), type)
]


@pytest.mark.parametrize("name", FUNCTIONS)
def test_the_docstring_example_runs(name):
    doc = getattr(verne, name).__doc__ or ""
    assert ">>>" in doc, f"verne.{name} has no example in its docstring"
    globs = {"np": np, "verne": verne, "m": verne.Machine.default()}
    test = doctest.DocTestParser().get_doctest(doc, globs, f"verne.{name}", None, 0)
    runner = doctest.DocTestRunner(optionflags=doctest.NORMALIZE_WHITESPACE)
    runner.run(test)
    result = runner.summarize(verbose=False)
    assert result.failed == 0, f"verne.{name}: {result.failed} of {result.attempted} examples failed"


def test_the_classes_examples_run():
    for cls in (verne.Machine, verne.Glider):
        for attr in dir(cls):
            doc = getattr(getattr(cls, attr), "__doc__", None) or ""
            if ">>>" not in doc or attr.startswith("__"):
                continue
            globs = {"np": np, "verne": verne, "m": verne.Machine.default()}
            test = doctest.DocTestParser().get_doctest(doc, globs, f"{cls.__name__}.{attr}", None, 0)
            runner = doctest.DocTestRunner()
            runner.run(test)
            assert runner.summarize(verbose=False).failed == 0, f"{cls.__name__}.{attr}"
