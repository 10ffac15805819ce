"""The Python API's reference (docs/api.md from the docstrings) and `wormsim init`'s template, which loads and runs
at all three levels."""

from __future__ import annotations

import inspect

import pytest

import wormsim
from tests.conftest import ROOT
from tools.api_doc import ORDER, markdown
from wormsim import cli
from wormsim.cli.init import write_template
from wormsim.scenario import ScenarioError, load_scenario


def test_docs_api_md_is_current():
    assert (ROOT / "docs" / "api.md").read_text() == markdown(), "regenerate: python -m tools.api_doc > docs/api.md"


@pytest.mark.parametrize("name", ORDER)
def test_public_objects_have_docstrings(name):
    doc = inspect.getdoc(getattr(wormsim, name)) or ""
    assert len(doc) > 60, name
    assert "for tests" not in doc


@pytest.mark.parametrize("name", ["load_scenario", "simulate", "run_scenario"])
def test_public_functions_document_args_returns_raises(name):
    doc = inspect.getdoc(getattr(wormsim, name))
    for section in ("Args:", "Returns:", "Raises:"):
        assert section in doc, (name, section)


def test_init_writes_a_template_and_never_overwrites(tmp_path, capsys):
    path = tmp_path / "Seat Motor.yaml"
    assert cli.main(["init", str(path)]) == 0
    assert "fill in your gear" in capsys.readouterr().out
    assert load_scenario(path).name == "seat_motor"
    assert cli.main(["init", str(path)]) == 2
    assert "exists" in capsys.readouterr().err
    with pytest.raises(ScenarioError):
        write_template(path)


@pytest.fixture(scope="module")
def template(tmp_path_factory):
    return write_template(tmp_path_factory.mktemp("init") / "my_gear.yaml")


SHORT_RAMPS = ["drive.ramp_s=0.02", "load.ramp_s=0.02"]  # the template's 0.05 s ramps, shortened for CI-sized runs


@pytest.mark.parametrize(
    "level, sets",
    [
        ("wedge", []),
        ("torsional", ["simulation.duration_s=0.05", *SHORT_RAMPS]),
        # a few mesh periods of the 2-start worm at 1500 rpm (50 Hz): the start-up and a short window
        ("contact3d", ["simulation.duration_s=0.03", "contact.slices=8", *SHORT_RAMPS]),
    ],
)
def test_the_template_runs_at_every_level(template, tmp_path, level, sets):
    sc = load_scenario(template, [f"model={level}", *sets])
    s = wormsim.run_scenario(sc, tmp_path, progress=False)
    # the gear: ratio z2 / z1 = 30 / 2 = 15; F_t2 = T2 / r2 = 60 N m / 45 mm = 1333.3 N (DIN 3975-2)
    assert s["status"] == "ok" and s["ratio_theory"] == 15
    assert s["ratio"] == pytest.approx(15, rel=0.01)
    assert s["tangential_force_mean_n"] == pytest.approx(60 / 0.045, rel=0.02)
    assert s["self_locking"] is False and 0 < s["efficiency_backdrive"] < 1
