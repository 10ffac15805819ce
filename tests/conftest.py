"""Shared test fixtures and paths: ROOT (the repository), SCENARIOS (its scenarios/ folder)."""

from __future__ import annotations

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SCENARIOS = ROOT / "scenarios"


@pytest.fixture
def scenario_dir() -> Path:
    """The seed scenarios (scenarios/)."""
    return SCENARIOS
