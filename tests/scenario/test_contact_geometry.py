"""contact.geometry: flanks is the default (issue 13); the keys that belong to one geometry are refused with the
other (exit 2, one line naming the key and what is allowed)."""

from __future__ import annotations

import pytest

from tests.conftest import SCENARIOS as SCEN
from wormsim import cli
from wormsim.scenario import ScenarioError, load_scenario

DEMO = SCEN / "seat_motor_demo.yaml"


def test_flanks_is_the_default_geometry():
    for name in ("seat_motor", "screw_jack", "involute_41", "seat_motor_demo"):
        assert load_scenario(SCEN / f"{name}.yaml").contact.geometry == "flanks"


@pytest.mark.parametrize(
    "sets, key",
    [
        (["contact.geometry=pieces", "contact.slices=16"], "contact.slices = 16"),
        (["simulation.speculative=true"], "simulation.speculative = true"),
    ],
)
def test_a_key_of_the_other_geometry_exits_2_in_one_line(tmp_path, capsys, sets, key):
    with pytest.raises(ScenarioError, match=key):
        load_scenario(DEMO, sets)
    args = ["run", str(DEMO), "--out", str(tmp_path / "o"), "--no-progress"]
    for kv in sets:
        args += ["--set", kv]
    assert cli.main(args) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and key in err and "allowed" in err and "Traceback" not in err, err


def test_the_same_keys_build_with_their_own_geometry():
    assert load_scenario(DEMO, ["contact.slices=16"]).contact.slices == 16
    sc = load_scenario(DEMO, ["contact.geometry=pieces", "simulation.speculative=true"])
    assert sc.simulation.speculative and sc.contact.geometry == "pieces"
