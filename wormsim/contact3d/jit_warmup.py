"""numba's one-time start-up (typing and target contexts, their registries, LLVM's JIT: ~0.6 s, paid by the first
compiled function a process calls, even one loaded from numba's cache), done in a thread while the model is built.
MuJoCo's model compilation (mjcf.build_model, ~0.7 s) runs mostly without the GIL, so on a second core the start-up
costs little wall time; the run's own compiled functions then only load their cached code (~0.02 s for the first).
numba's compiler lock serialises the thread and the main thread's first call. A failure is dropped: the first
compiled call starts numba itself."""

from __future__ import annotations

import threading

import numba


@numba.njit(cache=True)
def _touch(x: float) -> float:
    return x + 1.0


def _run() -> None:
    try:
        _touch(1.0)
    except Exception:
        pass


def start() -> threading.Thread:
    th = threading.Thread(target=_run, name="wormsim-jit-warmup", daemon=True)
    th.start()
    return th
