"""Provenance of a measured record (docs/data/*.json): the command that measured it, the commit it ran on, when, and
on what machine. Every script that writes a record under docs/data/ calls `record(...)`; the docs renderer
(tools.docs_render) reads only such records, and tests/tools/test_docs_render.py checks that each one carries the four
keys."""

from __future__ import annotations

import datetime
import json
import math
import os
import platform
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
DATA = ROOT / "docs" / "data"
KEYS = ("command", "commit", "date", "machine")


def git_commit(root: Path = ROOT) -> str:
    """The commit the working tree is on (short hash), with '-dirty' when tracked files differ from it; 'unknown'
    outside a git checkout."""
    try:
        head = subprocess.run(
            ["git", "-C", str(root), "rev-parse", "--short", "HEAD"], capture_output=True, text=True, check=True
        ).stdout.strip()
        dirty = subprocess.run(
            ["git", "-C", str(root), "status", "--porcelain", "--untracked-files=no"], capture_output=True, text=True
        ).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"
    return head + ("-dirty" if dirty else "")


def machine() -> str:
    """One line: platform, Python, CPU count and the 1-minute load average when measured (wall times depend on it)."""
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    return f"{platform.platform()}, Python {platform.python_version()}, {os.cpu_count()} CPUs, load {load:.2f}"


def _program() -> str:
    """This process's program as a reader would type it: `python studies/x.py` for a script in the repository,
    `wormsim` for the console script."""
    prog = Path(sys.argv[0])
    try:
        rel = prog.resolve().relative_to(ROOT)
    except ValueError:
        return prog.name
    return f"python {rel}" if rel.suffix == ".py" else str(rel)


def provenance(command: str | None = None) -> dict:
    """{command, commit, date, machine} of a measurement made now; command defaults to this process's argv."""
    cmd = command if command is not None else " ".join([_program(), *sys.argv[1:]])
    date = datetime.datetime.now(datetime.timezone.utc).replace(microsecond=0).isoformat()
    return {"command": cmd, "commit": git_commit(), "date": date, "machine": machine()}


def finite(x):
    """x with every non-finite float replaced by None (JSON has no NaN), recursively."""
    if isinstance(x, float):
        return x if math.isfinite(x) else None
    if isinstance(x, dict):
        return {k: finite(v) for k, v in x.items()}
    if isinstance(x, list | tuple):
        return [finite(v) for v in x]
    return x


def record(name: str, data: dict, command: str | None = None, prov: dict | None = None) -> Path:
    """Write docs/data/NAME.json: data with its provenance (`prov`, or measured now by `provenance(command)`)."""
    DATA.mkdir(parents=True, exist_ok=True)
    path = DATA / f"{name}.json"
    out = {"provenance": prov if prov is not None else provenance(command), **finite(data)}
    path.write_text(json.dumps(out, indent=1, allow_nan=False) + "\n")
    return path
