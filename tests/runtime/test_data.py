"""Where the package data is (wormsim.runtime.data): the MJCF template and the seed scenarios, installed or from the
source tree."""

from __future__ import annotations

from tests.conftest import ROOT
from wormsim.runtime import data


def test_models_and_scenarios_are_found():
    assert data.data_dir("models").joinpath("worm_pair.xml").is_file()
    assert data.data_dir("scenarios").joinpath("screw_jack.yaml").is_file()


def test_the_source_tree_fallback_is_this_repository():
    assert data.SOURCE_ROOT == ROOT
    assert (data.SOURCE_ROOT / "models" / "worm_pair.xml").is_file()
