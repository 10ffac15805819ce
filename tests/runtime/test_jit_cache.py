"""The compiled kernels' cache (wormsim.runtime.jit_cache): keyed by the code the compiled functions read, one folder per
machine for every process, filled once under a lock, and the progress line's "compiling". The long test compiles on a
fresh cache: two processes at once compile once, and a later process's contact3d runs compile nothing."""

from __future__ import annotations

import ast
import io
import json
import os
import shutil
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from wormsim.runfolder import progress
from wormsim.runtime import jit_cache

ROOT = Path(__file__).resolve().parents[2]


def _copy_tree(dst: Path) -> Path:
    for pkg in ("wormsim", "meshgen"):
        shutil.copytree(ROOT / pkg, dst / pkg, ignore=shutil.ignore_patterns("__pycache__", "*.pyc", "*.png"))
    return dst


def test_key_follows_the_compiled_code_and_not_the_rest(tmp_path, monkeypatch):
    monkeypatch.setattr(jit_cache, "_ROOT", _copy_tree(tmp_path))
    k0 = jit_cache.cache_key()
    assert k0 == jit_cache.cache_key() and len(k0) == 16
    cli = tmp_path / "wormsim" / "cli" / "entry.py"
    cli.write_text(cli.read_text() + "\n# a comment\n")
    assert jit_cache.cache_key() == k0  # the command line is not compiled code
    for rel in ("wormsim/physics/friction.py", "wormsim/tooth/gap.py", "meshgen/worm_forms_jit.py"):
        f = tmp_path / rel
        text = f.read_text()
        f.write_text(text + "\n# changed\n")
        assert jit_cache.cache_key() != k0, rel  # a callee or a constant module of the kernels
        f.write_text(text)
    assert jit_cache.cache_key() == k0
    # the same code in another folder: numba files each source folder's functions apart, so its own warm-up
    monkeypatch.setattr(jit_cache, "_ROOT", _copy_tree(tmp_path / "clone"))
    assert jit_cache.cache_key() != k0


def test_the_key_is_remembered_by_the_files_stamps(tmp_path, monkeypatch):
    monkeypatch.setattr(jit_cache, "_ROOT", _copy_tree(tmp_path / "src"))
    root = tmp_path / "jit"
    root.mkdir()
    k0 = jit_cache._key_memo(root)
    assert k0 == jit_cache.cache_key() and json.loads((root / "keys.json").read_text()) == {jit_cache._stamp(): k0}
    f = tmp_path / "src" / "wormsim" / "physics" / "friction.py"
    f.write_text(f.read_text() + "\n# changed\n")
    k1 = jit_cache._key_memo(root)
    assert k1 != k0 and k1 == jit_cache.cache_key() and len(json.loads((root / "keys.json").read_text())) == 2


def _imported_constants(path: Path) -> set[str]:
    """Modules of wormsim / meshgen from which `path` imports an UPPER_CASE name (a constant numba freezes into the
    compiled code)."""
    mods = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.split(".")[0] in ("wormsim", "meshgen"):
            if any(a.name.isupper() for a in node.names):
                mods.add(node.module)
    return mods


def test_every_constant_module_of_the_compiled_code_is_in_the_key():
    files = set(jit_cache._sources())
    numba_modules = [p for p in files if jit_cache._IMPORTS_NUMBA.search(p.read_text())]
    assert len(numba_modules) >= 15 and not any(p.name == "runner.py" for p in files)
    for p in numba_modules:
        for mod in _imported_constants(p):
            target = ROOT / (mod.replace(".", "/") + ".py")
            if not target.exists():
                target = ROOT / mod.replace(".", "/") / "__init__.py"
            assert target in files, f"{p.relative_to(ROOT)} reads constants of {mod}: add it to jit_cache.SOURCES"


def _python(code: str, env: dict) -> str:
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    return out.stdout.strip()


def test_every_process_uses_the_machine_folder_unless_the_user_chose_one(tmp_path):
    code = "import wormsim, numba; print(numba.config.CACHE_DIR)"
    env = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CACHE_DIR", jit_cache._OURS)}
    env[jit_cache.ENV] = str(tmp_path / "jit")
    folder = _python(code, env)
    assert Path(folder).parent == tmp_path / "jit" and len(Path(folder).name) == 16
    # a child of that process (a dask worker, a test's subprocess) computes the same folder again
    assert _python(code, {**env, "NUMBA_CACHE_DIR": folder, jit_cache._OURS: folder}) == folder
    # numba imported before wormsim: its config is set too
    assert _python("import numba, wormsim; print(numba.config.CACHE_DIR)", env) == folder
    user = str(tmp_path / "mine")
    assert _python(code, {**env, "NUMBA_CACHE_DIR": user}) == user


def test_warm_up_runs_once_per_folder_and_waits_for_another_process(tmp_path, monkeypatch):
    monkeypatch.setattr(jit_cache, "_dir", tmp_path)
    monkeypatch.setattr(jit_cache, "cache_root", lambda: tmp_path.parent)
    calls, notes = [], []

    def work():
        calls.append(1)

    # another process holds the lock: this one waits (and says so), then runs the warm-up itself
    holder = subprocess.Popen(
        [
            sys.executable,
            "-c",
            "import fcntl, sys, time; fh = open(sys.argv[1], 'a+'); fcntl.flock(fh, fcntl.LOCK_EX); "
            "print('held', flush=True); time.sleep(1.0)",
            str(tmp_path / ".lock"),
        ],
        stdout=subprocess.PIPE,
        text=True,
    )
    assert holder.stdout.readline().strip() == "held"
    t0 = time.perf_counter()
    assert jit_cache.ensure_warm(work, notes.append) is True
    waited = time.perf_counter() - t0
    holder.wait(10)
    assert waited > 0.3 and notes[0] == jit_cache.WAIT_NOTE and notes[1].startswith("compiling the contact3d kernels")
    assert calls == [1] and jit_cache.is_warm()
    rec = json.loads((tmp_path / jit_cache.WARM_NAME).read_text())
    assert rec["error"] is None and rec["runs"] == [[n, list(o)] for n, o in jit_cache.WARM_RUNS]
    assert jit_cache.ensure_warm(work, notes.append) is False and calls == [1]  # warm: nothing again


def test_a_failed_warm_up_is_recorded_and_not_retried(tmp_path, monkeypatch):
    monkeypatch.setattr(jit_cache, "_dir", tmp_path)
    monkeypatch.setattr(jit_cache, "cache_root", lambda: tmp_path.parent)
    calls = []

    def boom():
        calls.append(1)
        raise RuntimeError("no LLVM")

    assert jit_cache.ensure_warm(boom) is True
    assert json.loads((tmp_path / jit_cache.WARM_NAME).read_text())["error"] == "RuntimeError: no LLVM"
    assert jit_cache.ensure_warm(boom) is False and calls == [1]


class _Log(io.StringIO):
    def isatty(self):
        return False


@pytest.mark.parametrize("enabled", [None, True])
def test_restart_clock_after_a_warm_up(enabled):
    bar = progress.Progress(1.0, label="run", stream=_Log(), enabled=enabled)
    bar.compiling("compiling")
    bar.restart_clock()
    bar.update(0.5)
    bar.close()


def test_progress_says_compiling_once_and_leaves_the_compile_out_of_its_estimate(monkeypatch):
    clock = [1000.0]
    monkeypatch.setattr(progress.time, "perf_counter", lambda: clock[0])
    monkeypatch.delenv("WORMSIM_NO_PROGRESS", raising=False)
    monkeypatch.setattr(jit_cache, "expected_compile_s", lambda: 42.0)
    log = _Log()
    bar = progress.Progress(1.0, label="run", stream=log)
    try:
        for started in (True, False, True, False):  # two compiles: one line
            for w in list(jit_cache._watchers):
                w(started)
        monkeypatch.setattr(jit_cache, "_compile_s", jit_cache._compile_s + 100.0)  # they took 100 s
        clock[0] += 110.0  # 100 s compiling, 10 s simulating half the run
        bar.update(0.5)
    finally:
        bar.close()
    lines = log.getvalue().splitlines()
    assert lines[0] == "run: compiling the contact3d kernels (once per machine, about 42 s; later runs load them)"
    assert len(lines) == 2 and "1.8 min elapsed, about 0.2 min left" in lines[1], lines  # 10 s left, not 110 s
    assert bar._on_compile not in jit_cache._watchers  # closed: no longer told


def _stats_script(name: str, duration_s: float, *overrides: str) -> str:
    return (
        "import json, wormsim; from wormsim.runtime import jit_cache; from wormsim.scenario import load_scenario; "
        "from wormsim.run import simulate; "
        f"sc = load_scenario('{ROOT / 'scenarios' / name}.yaml', {list(overrides)!r}); "
        f"sc.simulation.duration_s = {duration_s}; simulate(sc); print(json.dumps(jit_cache.dispatcher_stats()))"
    )


def _setup_warm_command() -> list[str]:
    """The set-up's warm-up as the Makefile's install recipe runs it (`make install`, `make demo`):
    jit_cache.main with the contact3d warm-up runs."""
    line = next(x for x in (ROOT / "Makefile").read_text().splitlines() if "jit_cache" in x and " -c " in x)
    return [sys.executable, "-c", line.split(" -c ", 1)[1].strip().strip("'")]


def test_the_setup_warms_with_the_contact3d_warm_up():
    cmd = _setup_warm_command()
    assert "j.main(r.warm_runs)" in cmd[2] and "wormsim.contact3d.runner as r" in cmd[2]


@pytest.mark.long
def test_a_fresh_machine_compiles_once_and_later_processes_compile_nothing(tmp_path):
    """On an empty cache a `wormsim run` compiles and its progress line says so; the set-up's warm-up (the Makefile's,
    as `make demo` runs it), started while it compiles, says that it waits and loads; then fresh processes run the
    demo, the seat motor, one contact per tooth flank, a table-form (ZK) worm, shafts and the pieces without compiling
    anything."""
    env = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CACHE_DIR", jit_cache._OURS, "WORMSIM_NO_PROGRESS")}
    env[jit_cache.ENV] = str(tmp_path / "jit")
    cmd = [str(Path(sys.executable).parent / "wormsim"), "run", str(ROOT / "scenarios" / "screw_jack.yaml")]
    run = [*cmd, "--out", str(tmp_path / "o"), "--set", "simulation.duration_s=0.004"]

    def start(c):
        return subprocess.Popen(c, env=env, stderr=subprocess.PIPE, stdout=subprocess.DEVNULL, text=True, cwd=ROOT)

    first, head = start(run), []
    try:
        while not head or "compiling the contact3d kernels (once per machine" not in head[-1]:
            line = first.stderr.readline()
            assert line, head  # the run ended without saying that it compiles
            head.append(line)
    except BaseException:
        first.kill()
        raise
    assert head[-1].startswith("screw_jack (contact3d): compiling the contact3d kernels"), head  # the progress line
    setup = start(_setup_warm_command())
    errs = ["".join(head) + first.communicate(timeout=1200)[1], setup.communicate(timeout=1200)[1]]
    assert [first.returncode, setup.returncode] == [0, 0], errs
    assert "min left" not in errs[0] and jit_cache.WAIT_NOTE not in errs[0], errs[0]
    assert jit_cache.WAIT_NOTE in errs[1] and "(once per machine" not in errs[1], errs[1]  # it waited and loaded
    folders = list((tmp_path / "jit").iterdir())
    folders = [f for f in folders if f.is_dir()]
    assert len(folders) == 1 and json.loads((folders[0] / jit_cache.WARM_NAME).read_text())["error"] is None
    files_before = sorted(p.name for p in folders[0].rglob("*") if p.is_file())
    for case in (
        ("seat_motor_demo", 0.003),
        ("seat_motor", 0.003, "model=contact3d"),
        ("seat_motor", 0.003, "model=contact3d", "contact.flank_contacts=tooth"),
        ("seat_motor", 0.003, "model=contact3d", "contact.flank_contacts=slice"),  # the default is 4 per flank
        ("screw_jack", 0.003, "gear.profile=ZK"),
        ("screw_jack", 0.003, "shafts.worm.bearings_mm=[-40, 40]", "shafts.worm.bending=true"),
        ("involute_41", 0.003, "model=contact3d", "contact.geometry=pieces"),
    ):
        stats = json.loads(_python(_stats_script(*case), env).splitlines()[-1])
        assert stats["misses"] == 0 and stats["hits"] >= 3, (case, stats)
    assert sorted(p.name for p in folders[0].rglob("*") if p.is_file()) == files_before  # no new cache file


def test_dispatcher_stats_count_loads_and_compiles():
    import numba

    from wormsim.contact3d import jit_warmup

    jit_warmup._touch(1.0)
    st = jit_cache.dispatcher_stats()
    assert st["hits"] + st["misses"] >= 1
    assert isinstance(jit_warmup._touch, numba.core.registry.CPUDispatcher)


def test_watchers_are_told_in_the_compiling_thread():
    seen = []
    with jit_cache.watch(lambda started: seen.append((started, threading.current_thread().name))):
        import numba

        @numba.njit
        def _f(x):
            return x * 2

        _f(3)
    assert [s for s, _ in seen] == [True, False] and seen[0][1] == threading.current_thread().name


@pytest.mark.long
def test_a_two_worker_sweep_on_a_fresh_cache_compiles_once(tmp_path):
    """`wormsim sweep` of 4 short contact3d points on 2 workers, empty cache: the kernels are compiled once, in the
    fork server both workers are forked from (wormsim.sweep.preload_warm), and neither worker compiles anything of its
    own: each reports the fork server's compile seconds and signatures (a worker's counters start from its parent's),
    the same on both."""
    sweep = tmp_path / "s.yaml"
    sweep.write_text(
        f"name: fresh\nbase: {ROOT / 'scenarios' / 'screw_jack.yaml'}\n"
        "set: {model: contact3d, simulation.duration_s: 0.004}\n"
        "grid:\n  drive.speed_rpm: [1000, 1200, 1400, 1600]\n"
    )
    env = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CACHE_DIR", jit_cache._OURS)}
    env.update({jit_cache.ENV: str(tmp_path / "jit"), "WORMSIM_NO_PROGRESS": "1"})
    env.pop("DASK_SCHEDULER_ADDRESS", None)
    out = subprocess.run(
        [
            str(Path(sys.executable).parent / "wormsim"),
            "sweep",
            str(sweep),
            "--out",
            str(tmp_path / "o"),
            "--workers",
            "2",
        ],
        env=env,
        capture_output=True,
        text=True,
        timeout=1500,
    )
    assert out.returncode == 0, out.stderr
    doc = json.loads((tmp_path / "o" / "sweep.json").read_text())
    assert all(p["status"] == "ok" for p in doc["points"])
    timing = [p["timing"] for p in doc["points"]]
    per_worker: dict[str, dict] = {}
    for t in timing:
        w = per_worker.setdefault(t["worker"], {"compile_s": 0.0, "misses": 0})
        w["compile_s"] = max(w["compile_s"], t["compile_s"])
        w["misses"] = max(w["misses"], t["jit_misses"])
    assert len(per_worker) == 2, per_worker
    warmed_by = {t["warmed_by_pid"] for t in timing}
    assert len(warmed_by) == 1 and None not in warmed_by and not warmed_by & {t["pid"] for t in timing}, timing
    # one compile, in the fork server: both workers carry its counters and added none
    assert len({w["misses"] for w in per_worker.values()}) == 1, per_worker
    assert len({w["compile_s"] for w in per_worker.values()}) == 1, per_worker
    w = next(iter(per_worker.values()))
    assert w["misses"] > 5 and w["compile_s"] > 5.0, per_worker
