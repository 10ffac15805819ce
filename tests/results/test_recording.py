"""recording.rrd of two identical runs (issue 10): the content is identical; the bytes are not, because rerun
stamps rows and chunks with time-based ids (wormsim.results.recording.recorded_data, docs/recording.md)."""

from tests.conftest import SCENARIOS
from wormsim.results.recording import recorded_data
from wormsim.run import run_scenario
from wormsim.scenario import load_scenario

MOV = SCENARIOS / "mov_1.yaml"


def test_identical_runs_record_identical_content(tmp_path):
    sc = load_scenario(MOV)
    for name in ("a", "b"):
        run_scenario(sc, tmp_path / name, progress=False)
    a, b = recorded_data(tmp_path / "a" / "recording.rrd"), recorded_data(tmp_path / "b" / "recording.rrd")
    assert "/series/S1_n" in a and len(a) >= 10
    assert a == b
    assert (tmp_path / "a" / "timeseries.npz").read_bytes() == (tmp_path / "b" / "timeseries.npz").read_bytes()
