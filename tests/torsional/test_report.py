"""The torsional level's report.png and recording.rrd (wormsim.torsional.report), written from a short run, read
back."""

from __future__ import annotations

import matplotlib.image as mpimg

from tests.conftest import SCENARIOS
from wormsim.results.recording import recorded_entities
from wormsim.scenario import load_scenario
from wormsim.torsional import report as torsional_report


def _run(model: str, name: str = "screw_jack"):
    from wormsim.run import simulate

    sc = load_scenario(SCENARIOS / f"{name}.yaml", [f"model={model}", "simulation.duration_s=0.05"])
    return simulate(sc)


def test_report_and_recording_are_written(tmp_path):
    res = _run("torsional")
    png, rrd = tmp_path / "report.png", tmp_path / "recording.rrd"
    torsional_report.write_report(res, png)
    torsional_report.write_recording(res, rrd)
    img = mpimg.imread(png)
    assert img.ndim == 3 and img.shape[0] > 400 and img.shape[1] > 600  # a figure, not an empty file
    assert not list(tmp_path.glob(".*tmp*")), "the temporary file is renamed into place"
    entities = recorded_entities(rrd)
    assert any("speed" in e for e in entities), entities
