"""The Examples sections of the package's docstrings run as written."""

import doctest
import importlib
import pkgutil

import pytest

import mechdyn

MODULES = sorted(m.name for m in pkgutil.walk_packages(mechdyn.__path__, "mechdyn."))


@pytest.mark.parametrize("name", MODULES)
def test_docstring_examples(name):
    module = importlib.import_module(name)
    failures, _ = doctest.testmod(module, optionflags=doctest.ELLIPSIS)
    assert failures == 0
