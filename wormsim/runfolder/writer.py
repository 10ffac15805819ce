"""Result folders: atomic writes, one writer at a time, and what an interrupt or a failure leaves behind.

Guarantees for a run's folder DIR (docs/cli.md, "Reliability"):

* Files are written into a hidden staging folder DIR/.staging-* and moved in with os.replace; the old
  summary.json is removed first and the new one moved in last, so a reader that sees an "ok" summary sees
  complete files of that run (SIGINT/SIGTERM are held back while the files move).
* A run that FAILS (exit 2/3 or an internal error) replaces an earlier result by a "failed" summary.json only:
  the summary is replaced first, then the earlier result files are removed.
* A run that is INTERRUPTED (Ctrl-C, SIGTERM) leaves DIR exactly as it was: the staging folder is removed,
  nothing else is touched.
* One writer per folder: DIR/.wormsim.lock is held with flock while a run writes (and removed after); a second
  run into the same DIR is refused (exit 2) with the id of the process holding it. The lock dies with its
  process, so a killed run never blocks the next one; that next run removes the staging folders and temp files
  it left.
* A folder that cannot be written (a regular file, a read-only file system, /dev/null/x) is refused before any
  work with "cannot write to PATH: reason" (exit 2); nothing existing is touched.
"""

from __future__ import annotations

import errno
import fcntl
import json
import math
import os
import shutil
import signal
import tempfile
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from wormsim.scenario import ScenarioError

RESULT_FILES = ("summary.json", "timeseries.npz", "recording.rrd", "report.png")
LOCK_NAME = ".wormsim.lock"
STAGING_PREFIX = ".staging-"


class OutputPathError(ScenarioError):
    """An output path that cannot be written: exit 2, "cannot write to PATH: reason"."""


class FolderBusy(ScenarioError):
    """Another process holds the folder's lock: exit 2, naming that process."""


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


def _umask() -> int:
    umask = os.umask(0)
    os.umask(umask)
    return umask


def write_text_atomic(path: Path, text: str) -> None:
    """Write `text` to a temp file beside `path` and rename it over `path` (an existing file is replaced whole
    or not at all)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
    try:
        with os.fdopen(fd, "w") as fh:
            fh.write(text)
        os.chmod(tmp, 0o666 & ~_umask())  # mkstemp creates 0600; a result file is as readable as any other file
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def write_json_atomic(path: Path, data) -> None:
    write_text_atomic(path, json.dumps(_clean(data), indent=2) + "\n")


def _reason(exc: OSError) -> str:
    return exc.strerror or str(exc)


def check_writable_dir(out_dir: str | Path) -> Path:
    """Create DIR if needed and prove that a file can be created in it; OutputPathError otherwise."""
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise OutputPathError(f"cannot write to {out}: it exists and is not a directory; give a folder for --out")
    try:
        out.mkdir(parents=True, exist_ok=True)
        fd, probe = tempfile.mkstemp(prefix=".probe-", dir=out)
        os.close(fd)
        os.unlink(probe)
    except OSError as exc:
        raise OutputPathError(f"cannot write to {out}: {_reason(exc)}") from None
    return out


def check_writable_file(path: str | Path) -> Path:
    """An output FILE path: its folder must exist and be writable, and the path must not be a folder."""
    path = Path(path)
    if path.is_dir():
        raise OutputPathError(f"cannot write to {path}: it is a directory; give a file name")
    parent = path.parent if str(path.parent) else Path(".")
    if not parent.is_dir():
        raise OutputPathError(f"cannot write to {path}: the folder {parent} does not exist")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise OutputPathError(f"cannot write to {path}: {os.strerror(errno.EACCES)}")
    return path


def write_rexs(model, path: str | Path) -> Path:
    """A REXS model (wormsim.scenario.rexs.Model) written atomically as XML (.rexs) or JSON (.rexsj) by the suffix."""
    from wormsim.scenario import rexs

    path = Path(path)
    if path.suffix.lower() not in (".rexs", ".rexsj"):
        raise OutputPathError(f"--rexs {path}: the file name must end in .rexs (XML) or .rexsj (JSON)")
    text = rexs.to_json(model) if path.suffix.lower() == ".rexsj" else rexs.to_xml(model)
    write_text_atomic(check_writable_file(path), text)
    return path


def _holder(lock_path: Path) -> str:
    try:
        pid = lock_path.read_text().split()[0]
        return f"process {int(pid)}"
    except (OSError, IndexError, ValueError):
        return "another process"


class FolderLock:
    """flock on DIR/.wormsim.lock (non-blocking); the file holds the owner's pid for the message of a refused run.
    The owner unlinks the file before closing it, so a finished run leaves no trace; a locker checks that the
    inode it locked is still the one at the path (else a releaser unlinked it in between: try again)."""

    def __init__(self, out: Path):
        self.path = out / LOCK_NAME
        self.fd: int | None = None

    def acquire(self) -> None:
        for _ in range(100):
            try:
                fd = os.open(self.path, os.O_RDWR | os.O_CREAT, 0o644)
            except OSError as exc:
                raise OutputPathError(f"cannot write to {self.path.parent}: {_reason(exc)}") from None
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except OSError as exc:
                os.close(fd)
                if exc.errno in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
                    raise FolderBusy(
                        f"cannot write to {self.path.parent}: {_holder(self.path)} is writing there "
                        f"(lock {self.path}); wait for it to finish or give another --out"
                    ) from None
                raise OutputPathError(f"cannot write to {self.path.parent}: {_reason(exc)}") from None
            try:
                same = os.stat(self.path).st_ino == os.fstat(fd).st_ino
            except FileNotFoundError:
                same = False
            if same:
                os.ftruncate(fd, 0)
                os.write(fd, f"{os.getpid()}\n".encode())
                self.fd = fd
                return
            os.close(fd)
        raise FolderBusy(f"cannot write to {self.path.parent}: its lock {self.path} keeps changing hands")

    def release(self) -> None:
        if self.fd is not None:
            try:
                os.unlink(self.path)
            except OSError:
                pass
            os.close(self.fd)
            self.fd = None


def remove_stale(out: Path, names=RESULT_FILES) -> list[str]:
    """Staging folders and temp files left by a killed run (call only while holding the folder's lock)."""
    removed = []
    for p in out.iterdir():
        stale = p.name.startswith(STAGING_PREFIX) or any(p.name.startswith(f".{n}.") for n in names)
        if stale:
            if p.is_dir() and not p.is_symlink():
                shutil.rmtree(p, ignore_errors=True)
            else:
                p.unlink(missing_ok=True)
            removed.append(p.name)
    return removed


@contextmanager
def locked_dir(out_dir: str | Path, names=RESULT_FILES):
    """Check, lock and clean DIR for the duration of the block (mesh, model, bench)."""
    out = check_writable_dir(out_dir)
    lock = FolderLock(out)
    lock.acquire()
    try:
        remove_stale(out, names)
        yield out
    finally:
        lock.release()


@contextmanager
def signals_held():
    """SIGINT/SIGTERM wait until the block is done (the few renames of a commit)."""
    sigs = {signal.SIGINT, signal.SIGTERM}
    old = signal.pthread_sigmask(signal.SIG_BLOCK, sigs)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


class ResultDir:
    """One run's outputs: `staging` is where files go; commit() moves them in, fail() records a failure,
    abandon() (an interrupt) leaves DIR as it was. Holds DIR's lock from construction to close()."""

    def __init__(self, out_dir: str | Path):
        self.out = check_writable_dir(out_dir)
        self._lock = FolderLock(self.out)
        self._lock.acquire()
        try:
            self.stale_removed = remove_stale(self.out)
            self.staging = Path(tempfile.mkdtemp(prefix=STAGING_PREFIX, dir=self.out))
        except OSError as exc:
            self._lock.release()
            raise OutputPathError(f"cannot write to {self.out}: {_reason(exc)}") from None

    def path(self, name: str) -> Path:
        return self.staging / name

    def commit(self, summary: dict) -> None:
        with signals_held():
            (self.out / "summary.json").unlink(missing_ok=True)  # no "ok" summary beside a mix of old and new
            for f in sorted(self.staging.iterdir()):
                os.replace(f, self.out / f.name)
            write_json_atomic(self.out / "summary.json", summary)
            shutil.rmtree(self.staging, ignore_errors=True)
        self.close()

    def fail(self, summary: dict) -> None:
        """The failed summary replaces the earlier one first, then the earlier result files go."""
        with signals_held():
            shutil.rmtree(self.staging, ignore_errors=True)
            write_json_atomic(self.out / "summary.json", summary)
            for name in RESULT_FILES[1:]:
                (self.out / name).unlink(missing_ok=True)
        self.close()

    def abandon(self) -> None:
        """Interrupted: remove the staging folder only; an earlier result stays as it was."""
        shutil.rmtree(self.staging, ignore_errors=True)
        self.close()

    def close(self) -> None:
        self._lock.release()
