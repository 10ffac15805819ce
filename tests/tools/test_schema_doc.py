"""docs/scenario.md is generated from the schema and must be current."""

from pathlib import Path

from tools.schema_doc import markdown

DOC = Path(__file__).resolve().parents[2] / "docs" / "scenario.md"


def test_scenario_reference_is_up_to_date():
    assert DOC.read_text() == markdown(), "regenerate: python -m tools.schema_doc > docs/scenario.md"
