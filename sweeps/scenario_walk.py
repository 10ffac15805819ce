"""The walk of `scenario` through one simulate: which files the scenario object travels through.

A profile hook (sys.setprofile) sees every Python call; a call whose frame holds a Scenario among its locals (its
arguments at the call) is a step of the walk, named by its file (wormsim/ and meshgen/ only). A move is a step into
another file than the previous step's; a move back up is a move into a file the walk has already left once.

    .venv/bin/python sweeps/scenario_walk.py [LEVEL ...]      # default: contact3d torsional wedge

prints per level: calls, moves, moves back up and the files in walk order. The run is the screw jack seed, short
(simulation.duration_s 0.01 s at contact3d, 0.05 s below), run once untraced before (numba's compile and the caches
are not part of the walk).
"""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DURATION_S = {"contact3d": 0.01, "torsional": 0.05, "wedge": 0.05}


def walk(level: str) -> list[str]:
    """The files of the calls that hold a Scenario, in call order, for one simulate of the screw jack at `level`."""
    from wormsim.run import simulate
    from wormsim.scenario import Scenario, load_scenario

    sc = load_scenario(ROOT / "scenarios" / "screw_jack.yaml", [f"model={level}"])
    sc.simulation.duration_s = DURATION_S[level]
    roots = (str(ROOT / "wormsim"), str(ROOT / "meshgen"))
    files: list[str] = []

    def hook(frame, event, arg):
        if event != "call":
            return
        fn = frame.f_code.co_filename
        if not fn.startswith(roots):
            return
        if any(isinstance(v, Scenario) for v in frame.f_locals.values()):
            files.append(str(Path(fn).relative_to(ROOT)))

    simulate(sc.model_copy(deep=True))  # compiled and cached first: the walk is the run's, not the compiler's
    sys.setprofile(hook)
    try:
        simulate(sc)
    finally:
        sys.setprofile(None)
    return files


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
        files = walk(level)
        n, back = moves(files)
        print(f"{level}: {len(files)} calls, {n} moves between files, {back} back up")
        order = [f for i, f in enumerate(files) if i == 0 or f != files[i - 1]]
        print("  " + " > ".join(order))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
