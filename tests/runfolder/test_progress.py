"""Progress reporting: a long run without a terminal (logs, CI, nohup) prints one line per 10 % of simulated time
once it has taken LOG_AFTER_S of wall time; short runs and --no-progress stay silent."""

import io

from wormsim.runfolder import progress as P


def _feed(monkeypatch, enabled, elapsed_s):
    clock = iter([0.0] + [elapsed_s] * 100)
    monkeypatch.setattr(P.time, "perf_counter", lambda: next(clock))
    monkeypatch.delenv("WORMSIM_NO_PROGRESS", raising=False)
    out = io.StringIO()
    with P.Progress(20.0, label="seat_motor (contact3d)", enabled=enabled, stream=out) as bar:
        for k in range(1, 41):
            bar.update(0.5 * k)
    return out.getvalue()


def test_long_run_without_a_terminal_logs_every_tenth(monkeypatch):
    text = _feed(monkeypatch, None, elapsed_s=60.0)
    lines = [ln for ln in text.splitlines() if ln]
    assert len(lines) == 10 and lines[0].startswith("seat_motor (contact3d):  10 %")
    assert "min elapsed" in lines[-1] and "100 %" in lines[-1]


def test_short_run_and_disabled_progress_are_silent(monkeypatch):
    assert _feed(monkeypatch, None, elapsed_s=1.0) == ""
    assert _feed(monkeypatch, False, elapsed_s=60.0) == ""
