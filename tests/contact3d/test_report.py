"""contact3d's recording.rrd (wormsim.contact3d.report.write_recording): the contact points and force arrows, sent
as columns, hold one row per recorded instant with that instant's finite points, on the same sim_time nanoseconds as
rr.set_time gives; two recordings of one run hold identical content (no wall-clock log_time timeline)."""

from __future__ import annotations

import numpy as np

from tests.conftest import SCENARIOS
from wormsim.contact3d.report import MAX_FRAMES, write_recording
from wormsim.contact3d.runner import simulate
from wormsim.results.recording import recorded_data
from wormsim.scenario import load_scenario


def test_contact_rows_and_reproducible_content(tmp_path):
    sc = load_scenario(
        SCENARIOS / "screw_jack.yaml",
        ["drive.ramp_s=0.005", "load.ramp_s=0.005", "simulation.duration_s=0.01", "simulation.resolution=coarse"],
    )
    res = simulate(sc)
    write_recording(res, tmp_path / "a.rrd")
    write_recording(res, tmp_path / "b.rrd")
    a, b = recorded_data(tmp_path / "a.rrd"), recorded_data(tmp_path / "b.rrd")
    assert repr(a) == repr(b)  # repr: the series hold nan (nan != nan)
    t, P = res.series["t_s"], res.extra["points_world"]
    idx = np.unique(np.linspace(0, len(t) - 1, min(len(t), MAX_FRAMES)).astype(int))
    for ent, key in (
        ("/assembly/contacts/points", "Points3D:positions"),
        ("/assembly/contacts/forces", "Arrows3D:origins"),
    ):
        rows = sorted((c["sim_time"][i], c[key][i]) for c in a[ent] for i in range(len(c["sim_time"])))
        assert all("log_time" not in c for c in a[ent])
        assert [r[0] for r in rows] == [round(1e9 * float(x)) for x in t[idx]]
        n_ok = np.isfinite(P[idx, :, 0]).sum(axis=1)
        assert [len(r[1] or []) for r in rows] == n_ok.tolist() and n_ok.sum() > 0
        first = next(i for i, n in enumerate(n_ok) if n)
        p = P[idx[first]]
        assert np.array_equal(np.asarray(rows[first][1]), p[np.isfinite(p[:, 0])].astype(np.float32))
