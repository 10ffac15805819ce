"""wormsim.runtime.lazy: a package's names imported on first use."""

from __future__ import annotations

import subprocess
import sys

import pytest

import wormsim
import wormsim.sweep
from wormsim.runtime.lazy import lazy_getattr


def test_unknown_names_raise_attribute_error_naming_the_package():
    with pytest.raises(AttributeError, match="module 'wormsim' has no attribute 'nothing'"):
        wormsim.nothing  # noqa: B018
    with pytest.raises(AttributeError, match="module 'wormsim.sweep' has no attribute 'nothing'"):
        wormsim.sweep.nothing  # noqa: B018


def test_a_name_is_its_modules_object_and_is_kept_after_first_use():
    from wormsim.sweep.spec import load_sweep

    assert wormsim.sweep.load_sweep is load_sweep
    assert vars(wormsim.sweep)["load_sweep"] is load_sweep


def test_importing_the_package_loads_no_name_behind_it():
    code = (
        "import sys, wormsim, wormsim.sweep; print('wormsim.run' in sys.modules, 'wormsim.sweep.runner' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.split() == ["False", "False"], out


def test_lazy_getattr_takes_each_name_from_its_module():
    get = lazy_getattr("wormsim", {"LEVELS": "wormsim.run"})
    from wormsim.run import LEVELS

    assert get("LEVELS") is LEVELS
    with pytest.raises(AttributeError):
        get("simulate")  # not in its names
