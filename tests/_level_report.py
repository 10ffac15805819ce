"""A level's report.png and recording.rrd written from a short screw-jack run and read back (the torsional and wedge
report tests)."""

from __future__ import annotations

import matplotlib.image as mpimg

from tests.conftest import SCENARIOS
from wormsim.results.recording import recorded_entities
from wormsim.scenario import load_scenario


def check_report_and_recording(model: str, report, tmp_path) -> None:
    """report: the level's report module (write_report, write_recording)."""
    from wormsim.run import simulate

    res = simulate(load_scenario(SCENARIOS / "screw_jack.yaml", [f"model={model}", "simulation.duration_s=0.05"]))
    png, rrd = tmp_path / "report.png", tmp_path / "recording.rrd"
    report.write_report(res, png)
    report.write_recording(res, rrd)
    img = mpimg.imread(png)
    assert img.ndim == 3 and img.shape[0] > 400 and img.shape[1] > 600  # a figure, not an empty file
    assert not list(tmp_path.glob(".*tmp*")), "the temporary file is renamed into place"
    entities = recorded_entities(rrd)
    assert any("speed" in e for e in entities), entities
