"""`wormsim` console script (docs/cli.md): run, mesh, model, bench, sweep, rate, schema, check, init.

Exit codes: 0 ok, 2 invalid input or an output path that cannot be written (the message names the field or
the path), 3 the simulation failed (with a diagnosis), 130 / 143 interrupted by SIGINT (Ctrl-C) / SIGTERM
(an earlier result in --out stays as it was), 1 an internal error (a bug: rerun with --debug for the traceback).
Warnings (numpy, scipy) raised during a command are shown after it only when it succeeds; an error message is
the only output of a failed command.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import sys
import traceback
import warnings
from pathlib import Path

from wormsim.exceptions import ScenarioError, SimulationError
from wormsim.runfolder import interrupt

# Each command imports what it uses (the scenario's schema, the levels, the mesh generator, MuJoCo) when it runs:
# `wormsim sweep` starts its cluster's fork server before any of them is imported (wormsim.sweep.cluster).

EXIT_OK, EXIT_INTERNAL, EXIT_INPUT, EXIT_SIM = 0, 1, 2, 3


def _add_scenario_args(p: argparse.ArgumentParser, out_required: bool = True) -> None:
    p.add_argument("scenario", help="scenario YAML file")
    p.add_argument("--out", required=out_required, help="output directory")
    p.add_argument(
        "--set",
        dest="overrides",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="override a field by its dotted path, e.g. gear.wheel_teeth=41 (repeatable)",
    )


def build_parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="wormsim", description="Worm gear drive dynamics with real tooth contact.")
    ap.add_argument("--debug", action="store_true", help="show tracebacks of internal errors")
    sub = ap.add_subparsers(dest="command", required=True)
    p = sub.add_parser("run", help="run one scenario: summary.json, timeseries.npz, recording.rrd, report.png")
    _add_scenario_args(p)
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument(
        "--rexs", metavar="OUT.rexs", help="also write the stage and its results as REXS (.rexs XML, .rexsj JSON)"
    )
    p = sub.add_parser("import", help="a worm stage from a REXS file (.rexs, .rexsj) as a commented scenario YAML")
    p.add_argument("rexs_file", help="REXS model (XML .rexs or JSON .rexsj, REXS 1.x) with one worm stage")
    p.add_argument("--out", required=True, help="the scenario YAML to write")
    p = sub.add_parser("mesh", help="geometry only: worm.stl, wheel.stl, assembly.json, recording.rrd, section.png")
    _add_scenario_args(p)
    p = sub.add_parser(
        "model", help="write a standalone MJCF (model.xml + mesh assets, collision pieces) for MuJoCo's viewer"
    )
    _add_scenario_args(p)
    p = sub.add_parser("bench", help="speed-accuracy benchmark: bench.json and bench.png")
    p.add_argument("--quick", action="store_true", help="CI-sized subset")
    p.add_argument("--repeats", type=int, default=None, help="timed runs per case (median; default 1 quick, 3 full)")
    p.add_argument(
        "--scenario",
        action="append",
        default=None,
        dest="scenarios",
        help="only this seed scenario (repeatable): seat_motor, screw_jack, involute_41",
    )
    p.add_argument(
        "--geometry",
        action="append",
        default=None,
        dest="geometries",
        choices=("flanks", "pieces"),
        help="contact3d: only this contact.geometry (repeatable; default both, for the speed-up)",
    )
    p.add_argument(
        "--shafts",
        action="store_true",
        help="contact3d flanks: each default-step case also with a shafts: block (compliant bearings, the worm "
        "bending), its step against the rigid one's (bench_meta.json step_ratio_shafts_vs_rigid)",
    )
    p.add_argument(
        "--resolution",
        action="append",
        default=None,
        dest="resolutions",
        help="contact3d: only this resolution level (repeatable): coarse, medium, fine",
    )
    p.add_argument("--out", required=True)
    p = sub.add_parser("sweep", help="parameter study on dask.distributed: sweep.csv, sweep.json, sweep.png; resumes")
    p.add_argument("sweep", help="sweep YAML file")
    p.add_argument("--out", required=True, help="output directory (rerun into it to resume)")
    p.add_argument(
        "--scheduler",
        help="address of an existing dask scheduler (default: $DASK_SCHEDULER_ADDRESS, else a local cluster)",
    )
    p.add_argument("--workers", type=int, help="local workers (default: one per core); with --scheduler: wait for them")
    p.add_argument("--keep-runs", action="store_true", help="also write each point's result folder into DIR/runs/")
    p.add_argument("--no-progress", action="store_true", help="no progress bar or progress lines")
    p = sub.add_parser("rate", help="load-capacity rating (ISO/TS 14521 method B, AGMA 6034): rating.json, rating.md")
    _add_scenario_args(p)
    p.add_argument("--fe", action="store_true", help="add the FE root stress of the wheel tooth (rating.root_stress)")
    p = sub.add_parser("schema", help="print the scenario JSON schema (for editors)")
    p.add_argument("--out", help="write to this file instead of stdout")
    p = sub.add_parser("check", help="validate a scenario and print it with defaults filled in")
    _add_scenario_args(p, out_required=False)
    p = sub.add_parser("init", help="write a commented scenario template to fill in (default my_gear.yaml)")
    p.add_argument("path", nargs="?", default="my_gear.yaml", help="the new scenario file")
    return ap


def _cmd_run(args) -> int:
    from wormsim.run import run_scenario
    from wormsim.scenario import load_scenario

    sc = load_scenario(args.scenario, args.overrides)
    if Path(args.scenario).suffix.lower() in (".rexs", ".rexsj"):  # what the import assumed, as `wormsim import` says
        from wormsim.scenario import rexs

        for note in rexs.import_file(args.scenario).notes:
            print(f"wormsim: {note}", file=sys.stderr)
    summary = run_scenario(sc, args.out, progress=False if args.no_progress else None)
    out = Path(args.out)
    keys = [k for k in summary if k not in ("status", "message")]
    width = max(len(k) for k in keys)
    for k in keys:
        v = summary[k]
        print(f"  {k:<{width}}  {v:.6g}" if isinstance(v, float) else f"  {k:<{width}}  {v}")
    print(f"wrote {out / 'summary.json'}, {out / 'timeseries.npz'}, {out / 'report.png'}")
    print(f"recording: {out / 'recording.rrd'}  (view with: rerun {out / 'recording.rrd'})")
    for w in summary.get("warnings") or []:  # also in summary.json (wormsim.results.run_warnings)
        print(f"warning: {w}", file=sys.stderr)
    if args.rexs:
        _write_rexs(sc, summary, args.rexs)
    return EXIT_OK


def _write_rexs(sc, summary: dict, path: str) -> None:
    """The stage with the run's results and its rating (where the gear can be rated) as REXS."""
    from wormsim.rating.rate import rate
    from wormsim.runfolder.writer import write_rexs
    from wormsim.scenario import rexs

    rating = None
    if sc.gear is not None and summary.get("status") == "ok":
        try:
            rating = rate(sc)
        except ScenarioError as exc:  # e.g. no load torque: the run's results only
            print(f"wormsim: REXS export without the rating: {exc}", file=sys.stderr)
    written = write_rexs(rexs.export_model(sc, summary, rating), path)
    print(f"wrote {written} (REXS {'JSON' if written.suffix.lower() == '.rexsj' else 'XML'})")


def _cmd_import(args) -> int:
    from wormsim.runfolder.writer import check_writable_file, write_text_atomic
    from wormsim.scenario import rexs

    imp = rexs.import_file(args.rexs_file)
    text = rexs.to_yaml(imp)
    from wormsim.scenario import scenario_from_dict

    scenario_from_dict(imp.data, args.rexs_file)  # the imported stage validates (exit 2 naming the key otherwise)
    out = check_writable_file(args.out)
    write_text_atomic(out, text)
    for n in imp.notes:
        print(f"wormsim: {n}", file=sys.stderr)
    print(f"wrote {out}: run it with: wormsim run {out} --out out/{Path(out).stem}")
    return EXIT_OK


# mesh, model and bench import their machinery on use (the mesh generator, MuJoCo): `wormsim run` of a wedge
# scenario, `check` and `schema` load neither


def _cmd_mesh(args) -> int:
    from wormsim.cli.mesh import write_mesh_outputs
    from wormsim.runfolder.writer import locked_dir
    from wormsim.scenario import load_scenario

    sc = load_scenario(args.scenario, args.overrides)
    with locked_dir(args.out, names=("worm.stl", "wheel.stl", "assembly.json", "recording.rrd", "section.png")):
        write_mesh_outputs(sc, args.out)
    return EXIT_OK


def _cmd_model(args) -> int:
    from wormsim.contact3d.mjcf import write_model
    from wormsim.runfolder.writer import locked_dir
    from wormsim.scenario import load_scenario

    sc = load_scenario(args.scenario, args.overrides)
    with locked_dir(args.out, names=("model.xml",)):
        path = write_model(sc, args.out)
    print(f"wrote {path}  (open with: python -m mujoco.viewer --mjcf {path})")
    print("controls: drive = speed in rpm (or torque in N m), load = torque in N m; keyframe 'scenario' holds the")
    print("scenario's values (viewer: Load key 0); docs/mjcf.md")
    return EXIT_OK


def _cmd_bench(args) -> int:
    from wormsim.bench.run import run_bench
    from wormsim.runfolder.writer import locked_dir

    with locked_dir(args.out, names=("bench.json", "bench_meta.json", "bench.png")):
        run_bench(
            quick=args.quick,
            out_dir=args.out,
            repeats=args.repeats,
            scenarios=tuple(args.scenarios) if args.scenarios else None,
            geometries=tuple(args.geometries) if args.geometries else None,
            resolutions=tuple(args.resolutions) if args.resolutions else None,
            shafts=args.shafts,
        )
    return EXIT_OK


def _cmd_sweep(args) -> int:
    from wormsim.sweep.cluster import ClusterStart, early_fork_server, stop_fork_server

    if args.workers is not None and args.workers < 1:
        raise ScenarioError(f"--workers {args.workers}: allowed an integer >= 1")
    # the local cluster's fork server first (it preloads the workers' imports and kernels on another core), then
    # this process's imports; the cluster itself starts while the points are validated
    early = early_fork_server(args.sweep, args.scheduler)
    started: list[ClusterStart] = []

    def start(contact3d: bool) -> None:
        started.append(ClusterStart(args.scheduler, args.workers, warm=contact3d))

    try:
        from wormsim.sweep import load_sweep, run_sweep

        sw = load_sweep(args.sweep, on_parsed=start)
    except BaseException:
        for s in started:
            s.close()
        if early and not started:  # an invalid sweep file: its fork server's preload is not waited for
            stop_fork_server()
        raise
    try:
        c = run_sweep(
            sw,
            args.out,
            keep_runs=args.keep_runs,
            progress=False if args.no_progress else None,
            started=started[0] if started else None,
        )
    finally:
        if early and not (started and started[0].used):  # no point ran (all done earlier): not waited for either
            stop_fork_server()
    out = Path(args.out)
    print(
        f"sweep {sw.spec.name}: {c['points']} points: {c['ok']} ok, {c['failed']} failed "
        f"({c['resumed']} done earlier, {c['ran']} run now)"
    )
    print(f"wrote {out / 'sweep.csv'}, {out / 'sweep.json'}, {out / 'sweep.png'}")
    if c["points"] and not c["ok"]:  # nothing to study: the table holds only failures
        import csv

        with (out / "sweep.csv").open(newline="") as fh:
            failed = [r for r in csv.DictReader(fh) if r["status"] != "ok"]
        first = failed[0] if failed else {}
        if failed and all(r.get("message", "").startswith("invalid input: ") for r in failed):  # the input's fault
            print(
                f"error: every point of sweep {sw.spec.name} is invalid input (the first: "
                f"{first['message'].removeprefix('invalid input: ')})",
                file=sys.stderr,
            )
            return EXIT_INPUT
        print(
            f"simulation failed: every point of sweep {sw.spec.name} failed (the first: {first.get('message', '?')})",
            file=sys.stderr,
        )
        return EXIT_SIM
    return EXIT_OK


def _cmd_rate(args) -> int:
    from wormsim.rating.cmd import rate_command

    return rate_command(args.scenario, args.out, args.overrides, fe=args.fe)


def _cmd_schema(args) -> int:
    from wormsim.runfolder.writer import check_writable_file, write_text_atomic
    from wormsim.scenario import json_schema

    text = json.dumps(json_schema(), indent=2)
    if args.out:
        write_text_atomic(check_writable_file(args.out), text + "\n")
    else:
        print(text)
    return EXIT_OK


def _cmd_check(args) -> int:
    import yaml

    from wormsim.physics.validate import validate_geometry
    from wormsim.scenario import ignored_inputs, load_scenario

    sc = load_scenario(args.scenario, args.overrides)
    validate_geometry(sc)  # the same geometric checks as mesh and run
    for line in ignored_inputs(sc):
        print(f"wormsim: {line}", file=sys.stderr)
    print(yaml.safe_dump(sc.model_dump(mode="json", exclude_none=True), sort_keys=False), end="")
    from wormsim.cli.check import derived_text

    print(derived_text(sc), end="")  # the sizes, timestep and slices the run takes, as YAML comments
    return EXIT_OK


def _cmd_init(args) -> int:
    from wormsim.cli.init import write_template

    path = write_template(args.path)
    print(f"wrote {path}: fill in your gear, then: wormsim run {path} --out out/{path.stem}")
    return EXIT_OK


COMMANDS = {
    "run": _cmd_run,
    "mesh": _cmd_mesh,
    "model": _cmd_model,
    "bench": _cmd_bench,
    "sweep": _cmd_sweep,
    "rate": _cmd_rate,
    "schema": _cmd_schema,
    "check": _cmd_check,
    "init": _cmd_init,
    "import": _cmd_import,
}


def _out_path(args) -> Path | None:
    out = getattr(args, "out", None)
    return Path(out).absolute() if out else None


def _is_under(filename, root: Path | None) -> bool:
    if root is None or not filename:
        return False
    p = Path(os.fsdecode(filename)).absolute()
    return p == root or root in p.parents


# commands that end the process themselves when run from the command line (exit_now)
EXIT_NOW = ("sweep",)


def main(argv: list[str] | None = None) -> int:
    """Run one command; returns its exit code. argv None: the command line (the console script, `python -m
    wormsim`): a command of EXIT_NOW then ends the process once its files are written (exit_now), without the
    interpreter's finalization."""
    args = build_parser().parse_args(argv)
    code = _main(args)
    if argv is None and args.command in EXIT_NOW:
        exit_now(code)
    return code


def exit_now(code: int) -> None:
    """End this process with `code` once its output is out: stdout / stderr flushed and the atexit handlers run
    (logging, dask, multiprocessing), then os._exit, without Python's finalization (freeing every object of numba,
    distributed and matplotlib costs about a second after `wormsim sweep`). The command's files are written and
    closed before it returns (atomic renames)."""
    import atexit

    try:
        atexit._run_exitfuncs()
    finally:
        for stream in (sys.stdout, sys.stderr):
            try:
                stream.flush()
            except (OSError, ValueError):  # (a closed pipe)
                pass
        os._exit(code)


def _main(args) -> int:
    old_handlers = interrupt.install()
    caught: list[warnings.WarningMessage] = []
    try:
        with warnings.catch_warnings(record=True) as caught:
            code = COMMANDS[args.command](args)
        interrupt.check()  # an interrupt that a library swallowed
        for w in caught:  # a successful command: show what numpy/scipy warned about, after the work
            warnings.showwarning(w.message, w.category, w.filename, w.lineno)
        return code
    except ScenarioError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return EXIT_INPUT
    except SimulationError as exc:
        print(f"simulation failed: {exc}", file=sys.stderr)
        return EXIT_SIM
    except KeyboardInterrupt as exc:
        return _interrupted(getattr(exc, "signum", signal.SIGINT), args)
    except OSError as exc:
        if (sig := interrupt.pending()) is not None:
            return _interrupted(sig, args)
        if _is_under(exc.filename, _out_path(args)):  # disk full, permissions changed under a running command
            print(f"error: cannot write to {exc.filename}: {exc.strerror or exc}", file=sys.stderr)
            return EXIT_INPUT
        return _internal(exc, args)
    except Exception as exc:  # a bug, not a user error (unless an interrupt was swallowed and resurfaced as one)
        if (sig := interrupt.pending()) is not None:
            return _interrupted(sig, args)
        return _internal(exc, args)
    finally:
        interrupt.restore(old_handlers)


def _interrupted(signum: int, args) -> int:
    name = "" if signum == signal.SIGINT else f" ({signal.Signals(signum).name})"
    print(
        f"interrupted{name}" + ("; the earlier result in --out is unchanged" if args.command == "run" else ""),
        file=sys.stderr,
    )
    return 128 + int(signum)


def _internal(exc: BaseException, args) -> int:
    if args.debug:
        traceback.print_exception(exc)
    else:
        print(
            f"internal error: {exc.__class__.__name__}: {exc} (rerun with --debug for the traceback)", file=sys.stderr
        )
    return EXIT_INTERNAL


if __name__ == "__main__":
    sys.exit(main())
