"""The studies (studies/*.py, the scripts behind docs/data's records) import: their imports of wormsim and of the
tests' settings follow the packages as they move. Each study's own run is its record's command."""

from __future__ import annotations

import importlib
from pathlib import Path

import pytest

STUDIES = sorted(p.stem for p in (Path(__file__).resolve().parents[1] / "studies").glob("*.py") if p.stem != "__init__")


@pytest.mark.parametrize("name", STUDIES)
def test_study_imports(name):
    importlib.import_module(f"studies.{name}")
