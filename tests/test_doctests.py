"""Every example in the package's docstrings runs and prints what it shows (the README's own
examples are run by tests/test_readme.py)."""

from __future__ import annotations

import doctest
import importlib
import pkgutil
import warnings

import pytest

import tunnelkit

MODULES = sorted(m.name for m in pkgutil.walk_packages(tunnelkit.__path__, "tunnelkit."))


def _examples(name: str) -> list[doctest.DocTest]:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        module = importlib.import_module(name)
    return [t for t in doctest.DocTestFinder().find(module) if t.examples]


WITH_EXAMPLES = [n for n in MODULES if _examples(n)]


def test_the_package_has_docstring_examples():
    assert len(WITH_EXAMPLES) >= 10, WITH_EXAMPLES


@pytest.mark.parametrize("name", WITH_EXAMPLES)
def test_docstring_examples_run(name):
    runner = doctest.DocTestRunner(optionflags=doctest.ELLIPSIS | doctest.NORMALIZE_WHITESPACE)
    for test in _examples(name):
        runner.run(test)
    result = runner.summarize(verbose=False)
    assert result.failed == 0, f"{name}: {result.failed} of {result.attempted} examples failed"
