"""Ctrl-C and SIGTERM as one sticky interrupt.

The handler raises `Interrupted` (a KeyboardInterrupt) AND records the signal, because a KeyboardInterrupt can be
swallowed: one that lands in a lazy import inside trimesh is caught there (`except BaseException`) and resurfaces
later as an unrelated TypeError, or not at all (measured: a SIGINT 0.3 s into a torsional run finished with exit
0). `check()` re-raises a recorded interrupt; the runner calls it between phases and Progress on every update, so
an interrupt always ends the run as an interrupt and never commits or fails a result. One that lands where Python
cannot raise it (a weakref callback or a __del__, e.g. importlib's module-lock callback during an import) goes to
sys.unraisablehook, which would print "Exception ignored in ..." with a traceback: while the handler is installed
that hook drops an `Interrupted` (it is recorded; check() raises it) and passes everything else on.
"""

from __future__ import annotations

import signal
import sys
from collections.abc import Callable

_pending: int | None = None
_old_unraisable: Callable | None = None  # sys.unraisablehook before install()


class Interrupted(KeyboardInterrupt):
    """SIGINT / SIGTERM: exit 128 + signal number; an earlier result stays as it was."""

    def __init__(self, signum: int):
        super().__init__(signal.Signals(signum).name)
        self.signum = signum


def _handler(signum, frame):
    global _pending
    _pending = signum
    raise Interrupted(signum)


def _unraisable(unraisable) -> None:
    """sys.unraisablehook while the handler is installed: an Interrupted raised where Python cannot raise it is
    recorded already (check() raises it); anything else goes to the hook that was there."""
    if isinstance(unraisable.exc_value, Interrupted):
        return
    (_old_unraisable or sys.__unraisablehook__)(unraisable)


def install() -> dict:
    """Handle SIGTERM, and SIGINT unless it is ignored (nohup, a background job); returns the old handlers."""
    global _old_unraisable
    old = {}
    for sig in (signal.SIGINT, signal.SIGTERM):
        cur = signal.getsignal(sig)
        if cur in (signal.SIG_DFL, signal.default_int_handler, None):
            try:
                old[sig] = signal.signal(sig, _handler)
            except ValueError:  # not the main thread (an embedding application): leave signals alone
                pass
    if old and sys.unraisablehook is not _unraisable:
        _old_unraisable, sys.unraisablehook = sys.unraisablehook, _unraisable
    return old


def restore(old: dict) -> None:
    global _pending, _old_unraisable
    for sig, h in old.items():
        signal.signal(sig, h)
    if old and sys.unraisablehook is _unraisable:
        sys.unraisablehook, _old_unraisable = _old_unraisable or sys.__unraisablehook__, None
    _pending = None


def pending() -> int | None:
    return _pending


def check() -> None:
    if _pending is not None:
        raise Interrupted(_pending)
