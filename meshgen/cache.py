"""The on-disk cache of computed geometry (convex pieces, k(theta) tables, flank grids): one pickle per key.

Files live in $WORMSIM_CACHE (default ~/.cache/wormsim), named PREFIX-HASH.pkl, HASH the SHA-256 of the JSON of
what the result depends on (gear geometry, resolution, the producing code's version). Written atomically
(temporary file + os.replace); a file that cannot be read is recomputed; a cache that cannot be written is skipped.
"""

from __future__ import annotations

import hashlib
import json
import os
import pickle
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import TypeVar

T = TypeVar("T")


def cache_dir() -> Path:
    return Path(os.environ.get("WORMSIM_CACHE", Path.home() / ".cache" / "wormsim"))


def cache_key(parts: dict) -> str:
    blob = json.dumps(parts, sort_keys=True, default=str)
    return hashlib.sha256(blob.encode()).hexdigest()[:24]


def cached(prefix: str, parts: dict, compute: Callable[[], T], use_cache: bool = True) -> T:
    """compute(), or its result stored under (prefix, parts) by an earlier call."""
    if not use_cache:
        return compute()
    path = cache_dir() / f"{prefix}-{cache_key(parts)}.pkl"
    if path.exists():
        try:
            with open(path, "rb") as fh:
                return pickle.load(fh)
        except Exception:  # a corrupt, truncated or stale file: recompute
            pass
    value = compute()
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{prefix}-", dir=path.parent)
        with os.fdopen(fd, "wb") as fh:
            pickle.dump(value, fh, protocol=pickle.HIGHEST_PROTOCOL)
        os.replace(tmp, path)
    except OSError:
        pass
    return value
