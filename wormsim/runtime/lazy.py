"""A package's public names imported on first use (PEP 562 module __getattr__), so that importing a light module of
the package does not load the heavy ones behind its names (wormsim, wormsim.sweep)."""

from __future__ import annotations

import importlib
import sys
from collections.abc import Callable


def lazy_getattr(package: str, names: dict[str, str]) -> Callable[[str], object]:
    """The module __getattr__ of `package`: each name in `names` is taken from its module on first use and kept in the
    package's namespace; any other name raises AttributeError."""

    def __getattr__(name: str) -> object:
        module = names.get(name)
        if module is None:
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        value = getattr(importlib.import_module(module), name)
        setattr(sys.modules[package], name, value)
        return value

    return __getattr__
