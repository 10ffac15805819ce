"""The walk of `scenario` through one simulate: which files the scenario object travels through.

A profile hook (sys.setprofile) sees every Python call; a call whose frame holds a Scenario among its locals (its
arguments at the call) is a step of the walk, named by its file (wormsim/ and meshgen/ only). A move is a step into
another file than the previous step's; a move back up is a move into a file the walk has already left once. The
second count ("with returns") also steps back into the caller's file when such a call returns, as a reader who
follows the scenario into a helper and back does.

    .venv/bin/python studies/scenario_walk.py [LEVEL ...]      # default: contact3d torsional wedge

prints per level: calls, moves, moves back up and the files in walk order. The run is the screw jack seed, short
(simulation.duration_s 0.01 s at contact3d, 0.05 s below), run once untraced before (numba's compile and the caches
are not part of the walk).
"""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DURATION_S = {"contact3d": 0.01, "torsional": 0.05, "wedge": 0.05}


def walk(level: str) -> tuple[list[str], list[str]]:
    """The files of the calls that hold a Scenario, in call order, for one simulate of the screw jack at `level`;
    and the same walk with the returns of those calls (into the caller's file) as steps too."""
    from wormsim.run import simulate
    from wormsim.scenario import Scenario, load_scenario

    sc = load_scenario(ROOT / "scenarios" / "screw_jack.yaml", [f"model={level}"])
    sc.simulation.duration_s = DURATION_S[level]
    roots = (str(ROOT / "wormsim"), str(ROOT / "meshgen"))
    files: list[str] = []
    with_returns: list[str] = []
    held: set[int] = set()  # the frames of the walk still running

    def hook(frame, event, arg):
        if event == "return" and id(frame) in held:
            held.discard(id(frame))
            back = frame.f_back
            if back is not None and back.f_code.co_filename.startswith(roots):
                with_returns.append(str(Path(back.f_code.co_filename).relative_to(ROOT)))
            return
        if event != "call":
            return
        fn = frame.f_code.co_filename
        if not fn.startswith(roots):
            return
        if any(isinstance(v, Scenario) for v in frame.f_locals.values()):
            files.append(str(Path(fn).relative_to(ROOT)))
            with_returns.append(files[-1])
            held.add(id(frame))

    simulate(sc.model_copy(deep=True))  # compiled and cached first: the walk is the run's, not the compiler's
    sys.setprofile(hook)
    try:
        simulate(sc)
    finally:
        sys.setprofile(None)
    return files, with_returns


def moves(files: list[str]) -> tuple[int, int]:
    """(moves between files, moves back up into a file already left)."""
    n = back = 0
    left: set[str] = set()
    for a, b in zip(files, files[1:], strict=False):
        if a != b:
            n += 1
            left.add(a)
            back += b in left
    return n, back


def main(argv: list[str]) -> int:
    for level in argv or ["contact3d", "torsional", "wedge"]:
        files, with_returns = walk(level)
        n, back = moves(files)
        nr, backr = moves(with_returns)
        print(
            f"{level}: {len(files)} calls, {n} moves between files, {back} back up; "
            f"with returns {nr} moves, {backr} back up"
        )
        order = [f for i, f in enumerate(files) if i == 0 or f != files[i - 1]]
        print("  " + " > ".join(order))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
