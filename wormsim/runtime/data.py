"""Where models/ (the MJCF template) and scenarios/ (the seed scenarios) are: the package data wormsim.models and
wormsim.scenarios of an installed wormsim, else the folders of those names at the top of the source tree, so that
a source checkout runs without installing (`PYTHONPATH=. python -m wormsim ...`)."""

from __future__ import annotations

from importlib.resources import files
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from importlib.resources.abc import Traversable

SOURCE_ROOT = Path(__file__).resolve().parents[2]  # the repository, when this file is in a source checkout


def data_dir(name: str) -> Traversable:
    """The package data folder `name` ("models" or "scenarios")."""
    try:
        return files(f"wormsim.{name}")
    except ModuleNotFoundError:  # not installed: the package-dir mapping of pyproject.toml exists only on install
        return SOURCE_ROOT / name
