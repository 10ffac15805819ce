"""Where the CPU goes during a `wormsim sweep` on a LocalCluster: each process's and each thread's CPU seconds and
run-queue wait (Linux /proc/PID/task/TID/schedstat: time on a CPU, time runnable but waiting for one), sampled from
a second process while the sweep runs in this one (the client: scheduler, nannies and client in its threads).

    .venv/bin/python studies/trace_sweep_cpu.py [--workers 2] [--points 16] [--duration 0.3] [--out out/sweep_trace]

Prints a table per process (client, fork server, workers; their threads by Python name where the process tells
it, native threads such as OpenBLAS's as "native") and writes the raw samples to OUT/trace.json. The sweep is the
one of studies/measure_sweep_scaling.py. Linux only.
"""

from __future__ import annotations

import argparse
import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _schedstat(pid: int, tid: int) -> tuple[float, float]:
    """(seconds on a CPU, seconds runnable and waiting) of one thread."""
    try:
        run_ns, wait_ns, _ = Path(f"/proc/{pid}/task/{tid}/schedstat").read_text().split()
    except (OSError, ValueError):
        return 0.0, 0.0
    return int(run_ns) / 1e9, int(wait_ns) / 1e9


def _comm(pid: int, tid: int) -> str:
    try:
        return Path(f"/proc/{pid}/task/{tid}/comm").read_text().strip()
    except OSError:
        return "?"


def _steal_s() -> float:
    """The machine's steal time (the hypervisor's), seconds summed over CPUs (/proc/stat)."""
    fields = Path("/proc/stat").read_text().split("\n", 1)[0].split()
    return int(fields[8]) / os.sysconf("SC_CLK_TCK")


def sample(root: int, out: str, period_s: float) -> None:
    """The sampler's loop (a separate process): every period_s, every process under root and each of its threads;
    the last reading of each is kept. Ends when root ends or on SIGTERM, writing out."""
    import psutil

    procs: dict[int, dict] = {}
    stop = []
    signal.signal(signal.SIGTERM, lambda *_: stop.append(1))
    steal0 = _steal_s()
    t0 = time.time()
    while not stop:
        try:
            top = psutil.Process(root)
            everyone = [top, *top.children(recursive=True)]
        except psutil.NoSuchProcess:
            break
        for p in everyone:
            try:
                with p.oneshot():
                    rec = procs.setdefault(
                        p.pid,
                        {
                            "pid": p.pid,
                            "ppid": p.ppid(),
                            "cmdline": " ".join(p.cmdline())[:300],
                            "first": time.time() - t0,
                        },
                    )
                    ct = p.cpu_times()
                    rec["cpu_user_s"], rec["cpu_system_s"] = ct.user, ct.system
                    rec["last"] = time.time() - t0
                    rec.setdefault("series", []).append((round(time.time(), 3), round(ct.user + ct.system, 3)))
                    threads = rec.setdefault("threads", {})
                    for th in p.threads():
                        run_s, wait_s = _schedstat(p.pid, th.id)
                        cpu = th.user_time + th.system_time
                        t = threads.setdefault(str(th.id), {"comm": _comm(p.pid, th.id), "series": []})
                        t.update(cpu_s=cpu, run_s=run_s, wait_s=wait_s)
                        t["series"].append((round(time.time(), 3), round(cpu, 3), round(wait_s, 3)))
            except (psutil.NoSuchProcess, psutil.AccessDenied):
                continue
        time.sleep(period_s)
    Path(out).write_text(json.dumps({"procs": procs, "steal_s": _steal_s() - steal0, "wall_s": time.time() - t0}))


def _thread_names() -> dict:
    """{native id: Python name} of the calling process's Python threads."""
    return {str(t.native_id): t.name for t in threading.enumerate()}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--points", type=int, default=16)
    ap.add_argument("--duration", type=float, default=0.3)
    ap.add_argument("--out", default=str(ROOT / "out" / "sweep_trace"))
    ap.add_argument("--period", type=float, default=0.5)
    ap.add_argument("--cli", action="store_true", help="trace the `wormsim sweep` command as a child process instead")
    ap.add_argument("--sample", nargs=2, metavar=("PID", "OUT"), help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.sample:
        sample(int(args.sample[0]), args.sample[1], args.period)
        return
    t_start = time.time()
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    sys.path.insert(0, str(ROOT / "studies"))
    from measure_sweep_scaling import SWEEP

    (out / "scaling.yaml").write_text(
        SWEEP.format(base=ROOT / "scenarios" / "screw_jack.yaml", duration=args.duration, points=args.points)
    )
    run_dir = out / f"workers{args.workers}"
    for f in run_dir.glob("*"):
        f.unlink()
    raw = out / "samples.json"
    if args.cli:
        cli(out, run_dir, args.workers, args.period)
        return
    sampler = subprocess.Popen(
        [sys.executable, __file__, "--sample", str(os.getpid()), str(raw), "--period", str(args.period)]
    )
    cpu0 = time.process_time()
    from wormsim.sweep.cluster import ClusterStart, early_fork_server

    early_fork_server(out / "scaling.yaml", None)
    started: list[ClusterStart] = []
    from wormsim.sweep import load_sweep, run_sweep

    sw = load_sweep(out / "scaling.yaml", on_parsed=lambda c: started.append(ClusterStart(None, args.workers, warm=c)))
    from multiprocessing import forkserver

    pids = {"client": os.getpid(), "fork server": forkserver._forkserver._forkserver_pid}
    names = {"client": _thread_names()}

    def late_names():  # once the points run (the executor's threads start with the first task)
        client = started[0].get()[0]
        time.sleep(6.0)
        try:
            pids.update(client.run(os.getpid))
            for k, v in client.run(_thread_names).items():
                names.setdefault(k, {}).update(v)
            names["client"].update(_thread_names())
        except Exception:
            pass

    threading.Thread(target=late_names, daemon=True).start()
    run_sweep(sw, run_dir, started=started[0], progress=False)
    names["client"].update(_thread_names())
    client_cpu = time.process_time() - cpu0
    wall = time.time() - t_start
    sampler.send_signal(signal.SIGTERM)
    sampler.wait()
    data = json.loads(raw.read_text())
    data.update(names=names, pids=pids, wall_s=wall, client_process_time_s=client_cpu)
    doc = json.loads((run_dir / "sweep.json").read_text())
    data["points"] = [p["timing"] for p in doc["points"]]
    data["cluster"] = doc["cluster"]
    (out / "trace.json").write_text(json.dumps(data, indent=1))
    report(data)


def cli(out: Path, run_dir: Path, workers: int, period_s: float) -> None:
    """The command as users run it (a child process, ending with os._exit): the timeline of its start and end."""
    raw = out / "samples.json"
    t0 = time.time()
    cmd = subprocess.Popen(
        [str(Path(sys.executable).parent / "wormsim"), "sweep", str(out / "scaling.yaml"), "--out", str(run_dir),
         "--workers", str(workers), "--no-progress"]
    )  # fmt: skip
    sampler = subprocess.Popen(
        [sys.executable, __file__, "--sample", str(cmd.pid), str(raw), "--period", str(period_s)]
    )
    cmd.wait()
    t1 = time.time()
    sampler.send_signal(signal.SIGTERM)
    sampler.wait()
    data = json.loads(raw.read_text())
    doc = json.loads((run_dir / "sweep.json").read_text())
    pts = [p["timing"] for p in doc["points"]]
    a, b = min(t["start"] for t in pts), max(t["end"] for t in pts)
    print(f"command {t1 - t0:.2f} s: first point starts at {a - t0:.2f} s, last ends {t1 - b:.2f} s before the exit")
    print(f"cluster start {doc['cluster']['start_s']:.2f} s, warm {doc['cluster'].get('warm_s', 0):.2f} s")
    for pid, rec in sorted(data["procs"].items(), key=lambda kv: kv[1]["first"]):
        ser = rec["series"]
        cpu_a = _at(ser, a)
        t95 = next((t for t, c in ser if c >= 0.95 * cpu_a), ser[-1][0]) if cpu_a else ser[0][0]
        print(
            f"{rec['cmdline'][:70]:70s} pid {pid}: seen {ser[0][0] - t0:5.2f}-{ser[-1][0] - t0:5.2f} s, "
            f"cpu before the first point {cpu_a:.2f} s (95 % of it by {t95 - t0:.2f} s), after the last "
            f"{rec['cpu_user_s'] + rec['cpu_system_s'] - _at(ser, b):.2f} s"
        )
    by_w: dict[str, list] = {}
    for t in pts:
        by_w.setdefault(t["worker"], []).append(t)
    for w, ts in by_w.items():
        ts.sort(key=lambda t: t["start"])
        print(
            w,
            "starts",
            " ".join(f"{t['start'] - t0:.2f}" for t in ts[:3]),
            "walls",
            " ".join(f"{t['end'] - t['start']:.2f}" for t in ts),
            "cpu",
            " ".join(f"{t.get('thread_cpu_s', 0):.2f}" for t in ts),
        )


def _at(series: list, t: float, col: int = 1) -> float:
    """The reading of a (time, cpu, ...) series at time t: the last sample at or before t (0 before the first)."""
    v = 0.0
    for row in series:
        if row[0] > t:
            break
        v = row[col]
    return v


def report(data: dict) -> None:
    role = {str(v): k for k, v in data["pids"].items()}
    names = data["names"]
    pts = data["points"]
    t_a, t_b = min(t["start"] for t in pts), max(t["end"] for t in pts)
    print(f"wall {data['wall_s']:.1f} s, points' span {t_b - t_a:.1f} s, steal {data['steal_s']:.2f} CPU-s")
    print("CPU s: whole command | within the points' span; wait s (runnable, no core) within the span")
    for pid, rec in sorted(data["procs"].items(), key=lambda kv: kv[1]["first"]):
        r = role.get(pid, rec["cmdline"][:60])
        tn = names.get(r, {})
        cpu = rec["cpu_user_s"] + rec["cpu_system_s"]
        span = _at(rec["series"], t_b) - _at(rec["series"], t_a)
        print(f"{r} pid {pid}: cpu {cpu:.2f} | {span:.2f}")
        for tid, th in sorted(rec["threads"].items(), key=lambda kv: -kv[1]["cpu_s"]):
            if th["cpu_s"] >= 0.01 or th["wait_s"] >= 0.05:
                ser = th["series"]
                c_span = _at(ser, t_b) - _at(ser, t_a)
                w_span = _at(ser, t_b, 2) - _at(ser, t_a, 2)
                name = tn.get(tid, f"[{th['comm']}]")
                print(f"    {name:42s} cpu {th['cpu_s']:6.2f} | {c_span:6.2f}  wait {w_span:6.2f}")
    by_w: dict[str, list] = {}
    for t in pts:
        by_w.setdefault(t["worker"], []).append(t)
    for w, ts in by_w.items():
        ts.sort(key=lambda t: t["start"])
        print(w, "point wall", " ".join(f"{t['end'] - t['start']:.2f}" for t in ts))
        print(w, "point cpu ", " ".join(f"{t.get('thread_cpu_s', float('nan')):.2f}" for t in ts))


if __name__ == "__main__":
    main()
