"""The compiled kernels' cache: one per machine, shared by every process and dask worker, keyed by the code and the CPU.

numba's own cache (`cache=True`) keeps a function's machine code next to its source and checks only that source file's
time stamp: a change in a callee or a constant of another module leaves stale code, and every clone compiles anew.
Here every wormsim process points numba at one folder per (code, CPU, numba, Python):

    $WORMSIM_JIT_CACHE (default: $WORMSIM_CACHE/numba, i.e. ~/.cache/wormsim/numba) / KEY /

KEY hashes the text of every module whose code or constants the compiled functions use (every wormsim / meshgen
module that imports numba, and `SOURCES`: the modules whose constants they read; this module's own text is not part
of it), the CPU (model name and flags), numba's and Python's versions, and the folder the code is in: numba files
each source folder's functions apart (a subfolder named by its path), so a second checkout of the same code would
find the first one's warm.json and compile in every process. A NUMBA_CACHE_DIR set by the user wins. numba's own
index, inside the folder, still checks each source file's time stamp and the CPU.

The folder is filled once per machine (`ensure_warm`): the first contact3d run, `make install` or a sweep's
worker plugin runs the short contact3d runs of `WARM_RUNS` (wormsim.contact3d.runner.warm_runs, handed to ensure_warm:
this module imports no level), compiling every entry point with the signatures the runs use, while holding the
folder's lock, then writes `warm.json`. A process that finds the lock held waits and then
loads what the other compiled: a sweep of N workers on a fresh machine compiles once, not N times.

`watch` tells a progress line when numba compiles (the "numba:compile" event, numba.core.event) and how many
seconds compiling took, so it says "compiling" and leaves those seconds out of its time estimate.
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import os
import platform
import re
import sys
import time
from collections.abc import Callable, Iterator
from pathlib import Path

ENV = "WORMSIM_JIT_CACHE"
_OURS = "WORMSIM_NUMBA_CACHE_DIR"  # the NUMBA_CACHE_DIR this module set (a child process recomputes it)
WARM_NAME = "warm.json"
LAST_NAME = "last_compile.json"  # in the root: the last full compile's seconds on this machine
# the seconds of a cold compile when this machine has none on record: the screw jack's cold run on a 2-core machine,
# docs/decisions/0028-kernel-compile-time.md (61.9 s)
DEFAULT_COMPILE_S = 60.0
_ROOT = Path(__file__).resolve().parents[2]
_IMPORTS_NUMBA = re.compile(r"^\s*(import numba|from numba)", re.MULTILINE)
# the modules whose constants the compiled code reads, relative to the repository / site-packages root; every
# wormsim / meshgen module that imports numba is added (_sources; tests/runtime/test_jit_cache.py checks that each
# constant
# a compiled module imports comes from one of them)
SOURCES = (
    "wormsim/physics/friction.py",
    "wormsim/physics/units.py",
    "wormsim/physics/gear_theory.py",
    "wormsim/contact3d/diagnosis.py",
    "wormsim/contact3d/timestep.py",
    "wormsim/tooth/grid.py",
    "meshgen/worm_forms.py",
)
# the warm-up runs: scenario (a seed shipped in wormsim.scenarios) and overrides; together they call every compiled
# entry point with the signatures a run uses (tests/runtime/test_jit_cache.py checks that a later run compiles nothing)
WARM_STEPS = 40
WARM_RUNS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("screw_jack", ()),
    ("screw_jack", ("contact.geometry=pieces", "simulation.resolution=coarse")),  # coarse: fewer pieces to build
    (
        "screw_jack",
        ("shafts.worm.bearings_mm=[-40, 40]", "shafts.worm.radial_stiffness_n_per_um=300", "shafts.worm.bending=true"),
    ),
)

WAIT_NOTE = "another process is compiling the contact3d kernels; waiting to load them"
_in_warm = False  # ensure_warm's own runs do not warm again
_watchers: list[Callable[[bool], None]] = []  # called with True when a compile starts, False when it ends
_compile_s = 0.0  # seconds spent compiling in this process (outermost compiles)
_listener_installed = False


def _sources() -> list[Path]:
    files = {_ROOT / rel for rel in SOURCES if (_ROOT / rel).is_file()}
    for pkg in ("wormsim", "meshgen"):
        for p in (_ROOT / pkg).rglob("*.py"):
            if p not in files and p.name != "jit_cache.py" and _IMPORTS_NUMBA.search(p.read_text(errors="replace")):
                files.add(p)
    return sorted(files)


def _cpu() -> str:
    """The CPU's model name and flags (Linux: /proc/cpuinfo), else platform's description."""
    try:
        text = Path("/proc/cpuinfo").read_text()
        first = text.split("\n\n", 1)[0]
        fields = dict(line.split(":", 1) for line in first.splitlines() if ":" in line)
        return "|".join(fields.get(k, "").strip() for k in ("model name", "flags", "Features", "CPU part"))
    except OSError:
        return f"{platform.machine()}|{platform.processor()}"


def _machine() -> str:
    from importlib import metadata

    try:
        numba_version = metadata.version("numba")
    except metadata.PackageNotFoundError:
        numba_version = "?"
    return f"{numba_version}|{sys.version}|{platform.machine()}|{_cpu()}"


def cache_key() -> str:
    """16 hex digits of the SHA-256 of the sources' text (_sources), the CPU, numba's and Python's versions and the
    code's folder (module docstring)."""
    h = hashlib.sha256(_machine().encode())
    h.update(str(_ROOT).encode())
    for p in _sources():
        h.update(str(p.relative_to(_ROOT)).encode())
        h.update(p.read_bytes())
    return h.hexdigest()[:16]


def _stamp() -> str:
    """A hash of every wormsim / meshgen module's path, size and time stamp, and of _machine(): where it is the same,
    so is cache_key() (reading the files costs ~0.1 s at each start; a stat of each costs ~2 ms)."""
    h = hashlib.sha256(_machine().encode())
    for pkg in ("wormsim", "meshgen"):
        for p in sorted((_ROOT / pkg).rglob("*.py")):
            st = p.stat()
            h.update(f"{p}|{st.st_size}|{st.st_mtime_ns}".encode())
    return h.hexdigest()


def _key_memo(root: Path) -> str:
    """cache_key(), remembered in root/keys.json by _stamp() (the last 32 stamps)."""
    stamp, memo_path = _stamp(), root / "keys.json"
    try:
        memo = json.loads(memo_path.read_text())
    except (OSError, ValueError):
        memo = {}
    if not isinstance(memo, dict):
        memo = {}
    key = memo.get(stamp)
    if isinstance(key, str):
        return key
    key = cache_key()
    memo = dict(list(memo.items())[-31:])
    memo[stamp] = key
    _write_json(memo_path, memo)
    return key


def cache_root() -> Path:
    env = os.environ.get(ENV)
    if env:
        return Path(env)
    from meshgen.cache import cache_dir

    return cache_dir() / "numba"


_dir: Path | None = None


def cache_path() -> Path | None:
    """The folder numba uses now: ours (root / key), the user's NUMBA_CACHE_DIR, or None (numba's default, beside the
    sources: the root could not be made)."""
    if _dir is not None:
        return _dir
    user = os.environ.get("NUMBA_CACHE_DIR")
    return Path(user) if user else None


def configure() -> Path | None:
    """Point numba at this machine's folder for this code (module docstring); before any compiled function is
    defined (wormsim/__init__.py calls it first). Does not import numba."""
    global _dir
    user = os.environ.get("NUMBA_CACHE_DIR")
    if user and user != os.environ.get(_OURS):  # the user's own choice
        return Path(user)
    root = cache_root()
    try:
        root.mkdir(parents=True, exist_ok=True)
        path = root / _key_memo(root)
        path.mkdir(exist_ok=True)
    except OSError:  # no writable cache: numba's default
        return None
    _dir = path
    os.environ["NUMBA_CACHE_DIR"] = os.environ[_OURS] = str(path)
    if "numba" in sys.modules:  # imported before wormsim: its config has read the environment already
        from numba.core import config

        config.CACHE_DIR = str(path)
    return path


# ----------------------------------------------------------------------------- compile events


def _install_listener() -> None:
    """Count the seconds of outermost compiles and tell the watchers (numba's "numba:compile" event)."""
    global _listener_installed
    if _listener_installed:
        return
    from numba.core import event

    class _Listener(event.Listener):
        depth = 0
        t0 = 0.0

        def on_start(self, ev):
            self.depth += 1
            if self.depth == 1:
                self.t0 = time.perf_counter()
                for w in list(_watchers):
                    w(True)

        def on_end(self, ev):
            global _compile_s
            self.depth -= 1
            if self.depth == 0:
                _compile_s += time.perf_counter() - self.t0
                for w in list(_watchers):
                    w(False)

    event.register("numba:compile", _Listener())
    _listener_installed = True


def compile_seconds() -> float:
    """Seconds this process has spent compiling (outermost compiles, since the listener was installed)."""
    return _compile_s


@contextlib.contextmanager
def watch(callback: Callable[[bool], None]) -> Iterator[None]:
    """callback(True) when numba starts compiling, callback(False) when it ends, while the block runs."""
    _install_listener()
    _watchers.append(callback)
    try:
        yield
    finally:
        _watchers.remove(callback)


def add_watcher(callback: Callable[[bool], None]) -> None:
    """As watch, until remove_watcher; numba's listener is installed when numba is imported (lazily: no import)."""
    _watchers.append(callback)
    if "numba" in sys.modules:
        _install_listener()


def remove_watcher(callback: Callable[[bool], None]) -> None:
    if callback in _watchers:
        _watchers.remove(callback)


def dispatcher_stats() -> dict:
    """numba's counters over this process's compiled functions of wormsim and meshgen: "hits" (signatures loaded from
    the cache), "misses" (signatures compiled) and "functions" with a miss (their qualified names)."""
    if "numba" not in sys.modules:
        return {"hits": 0, "misses": 0, "functions": []}
    from numba.core.registry import CPUDispatcher

    hits = misses = 0
    missed = []
    for name, mod in list(sys.modules.items()):
        if mod is None or not name.startswith(("wormsim", "meshgen")):
            continue
        for attr in list(vars(mod).values()):
            if isinstance(attr, CPUDispatcher) and attr.__module__ == name:
                st = attr.stats
                hits += sum(st.cache_hits.values())
                n = sum(st.cache_misses.values())
                misses += n
                if n:
                    missed.append(f"{name}.{attr.py_func.__qualname__}")
    return {"hits": hits, "misses": misses, "functions": sorted(missed)}


# ----------------------------------------------------------------------------- warm-up


def is_warm() -> bool:
    d = cache_path()
    return d is not None and (d / WARM_NAME).is_file()


def expected_compile_s() -> float:
    """The last full compile's seconds on this machine (any code version), else DEFAULT_COMPILE_S."""
    try:
        return float(json.loads((cache_root() / LAST_NAME).read_text())["compile_s"])
    except (OSError, ValueError, KeyError, TypeError):
        return DEFAULT_COMPILE_S


def compiling_note() -> str:
    return (
        f"compiling the contact3d kernels (once per machine, about {expected_compile_s():.0f} s; later runs load them)"
    )


@contextlib.contextmanager
def _lock(path: Path, waiting: Callable[[], None] | None = None) -> Iterator[None]:
    """An exclusive lock on path (fcntl.flock; where there is none, no lock); waiting() is called when another process
    holds it."""
    try:
        import fcntl
    except ImportError:  # (Windows) two processes may both compile
        yield
        return
    with open(path, "a+") as fh:
        try:
            fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            if waiting is not None:
                waiting()
            fcntl.flock(fh, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(fh, fcntl.LOCK_UN)


def ensure_warm(work: Callable[[], None], note: Callable[[str], None] | None = None) -> bool:
    """Compile (or load) every contact3d kernel once per machine (module docstring): work() runs the short runs of
    WARM_RUNS (wormsim.contact3d.runner.warm_runs, passed in so that this module imports no level). note(text) is
    told before a compile. Returns True when this call ran the warm-up. A failed warm-up is recorded (no retry by
    every run): the runs then compile what they call."""
    global _in_warm
    d = cache_path()
    if _in_warm or d is None or is_warm():
        return False
    _in_warm = True
    try:
        wait_note = None if note is None else (lambda: note(WAIT_NOTE))
        with _lock(d / ".lock", wait_note):
            if is_warm():  # another process compiled while this one waited
                return False
            if note is not None:
                note(compiling_note())
            t0 = time.perf_counter()
            c0 = compile_seconds()
            error = None
            try:
                listen()
                work()
            except Exception as exc:  # (the run compiles for itself)
                error = f"{exc.__class__.__name__}: {exc}"
            wall = time.perf_counter() - t0
            rec = {
                "wall_s": wall,
                "compile_s": compile_seconds() - c0,
                "error": error,
                "created": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
                "runs": [[n, list(o)] for n, o in WARM_RUNS],
            }
            _write_json(d / WARM_NAME, rec)
            if error is None and rec["compile_s"] > 1.0:
                _write_json(cache_root() / LAST_NAME, {"compile_s": rec["compile_s"], "key": d.name})
            return True
    finally:
        _in_warm = False


def listen() -> None:
    """Count this process's compile seconds from now on (compile_seconds; imports numba)."""
    import numba  # noqa: F401  (the listener needs numba's event module)

    _install_listener()


def _write_json(path: Path, doc: dict) -> None:
    tmp = path.with_name(f".{path.name}.{os.getpid()}")
    try:
        tmp.write_text(json.dumps(doc, indent=1))
        os.replace(tmp, path)
    except OSError:
        tmp.unlink(missing_ok=True)


def main(work: Callable[[], None]) -> int:
    """Warm this machine's cache with work() (ensure_warm) and say where it is (`make install`)."""
    path = cache_path()
    if path is None:
        print("wormsim: no writable numba cache folder; runs compile for themselves", file=sys.stderr)
        return 0
    ran = ensure_warm(work, lambda text: print(text, file=sys.stderr, flush=True))
    doc = json.loads((path / WARM_NAME).read_text()) if (path / WARM_NAME).is_file() else {}
    state = "compiled" if ran else "already warm"
    print(f"wormsim: contact3d kernels {state} in {path} ({doc.get('compile_s', 0):.0f} s compiling)")
    if doc.get("error"):
        print(f"wormsim: the warm-up failed: {doc['error']}", file=sys.stderr)
    return 0
