"""Atomic result writing: a run's files appear in DIR all at once, or DIR says the run failed.

Files are written into a hidden temporary folder beside DIR and moved in with os.replace;
summary.json is moved last, so a reader that sees an "ok" summary sees complete files. A failed run
removes earlier result files from DIR and leaves only summary.json with status "failed".
"""
from __future__ import annotations

import json
import math
import os
import shutil
import tempfile
from pathlib import Path

import numpy as np

RESULT_FILES = ("summary.json", "timeseries.npz", "recording.rrd", "report.png")


def _clean(obj):
    """JSON-safe: numpy scalars/arrays to Python, NaN/inf to None."""
    if isinstance(obj, dict):
        return {str(k): _clean(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_clean(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return _clean(obj.tolist())
    if isinstance(obj, (np.bool_,)):
        return bool(obj)
    if isinstance(obj, (np.integer,)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        v = float(obj)
        return v if math.isfinite(v) else None
    return obj


def write_json_atomic(path: Path, data) -> None:
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
    with os.fdopen(fd, "w") as fh:
        json.dump(_clean(data), fh, indent=2)
        fh.write("\n")
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)       # mkstemp creates 0600; a result file is as readable as any other file
    os.replace(tmp, path)


class ResultDir:
    """Context for writing one run's outputs: `staging` is where files go; commit() moves them in."""

    def __init__(self, out_dir: str | Path):
        self.out = Path(out_dir)
        self.out.mkdir(parents=True, exist_ok=True)
        self.staging = Path(tempfile.mkdtemp(prefix=".staging-", dir=self.out))

    def path(self, name: str) -> Path:
        return self.staging / name

    def commit(self, summary: dict) -> None:
        for f in sorted(self.staging.iterdir()):
            os.replace(f, self.out / f.name)
        write_json_atomic(self.out / "summary.json", summary)
        shutil.rmtree(self.staging, ignore_errors=True)

    def fail(self, summary: dict) -> None:
        shutil.rmtree(self.staging, ignore_errors=True)
        for name in RESULT_FILES[1:]:
            (self.out / name).unlink(missing_ok=True)
        write_json_atomic(self.out / "summary.json", summary)
