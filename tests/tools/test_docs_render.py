"""`make docs` (tools.docs_render): every rendered block of README.md and docs/*.md equals what the renderer makes
from its record, every record under docs/data/ carries its provenance, no measured record lies outside docs/data/, and
the figures are byte-identical run to run."""

from __future__ import annotations

import json

import pytest

from tests.conftest import ROOT
from tools import docs_render as dr
from wormsim.results.provenance import KEYS

RECORDS = sorted((ROOT / "docs" / "data").glob("*.json"))


@pytest.mark.parametrize("path", dr.markdown_files(), ids=lambda p: p.name)
def test_rendered_blocks_equal_their_records(path):
    text = path.read_text()
    assert dr.render_text(text) == text, f"{path.name}: a rendered block differs from its record (run `make docs`)"


def test_decision_records_are_history_not_rendered():
    """docs/decisions/ keeps each decision with its numbers as measured then: outside the rendered pages."""
    files = dr.markdown_files()
    assert all(p.parent.name != "decisions" for p in files)
    assert (ROOT / "docs" / "contact3d.md") in files


def test_every_block_names_a_registered_table():
    names = {n for p in dr.markdown_files() for n in dr.blocks(p.read_text())}
    assert names, "no rendered block in README.md or docs/*.md"
    assert names <= set(dr.TABLES), names - set(dr.TABLES)


@pytest.mark.parametrize("path", RECORDS, ids=lambda p: p.name)
def test_every_record_has_its_provenance(path):
    prov = json.loads(path.read_text()).get("provenance")
    assert isinstance(prov, dict), path.name
    for k in KEYS:
        assert isinstance(prov.get(k), str) and prov[k].strip(), (path.name, k)


def test_no_record_outside_docs_data():
    """Measured numbers live in docs/data/*.json with provenance, not loose in docs/."""
    assert not sorted((ROOT / "docs").glob("*.json")), "move the record to docs/data/ with its provenance"


def test_a_table_that_disagrees_with_its_record_fails(tmp_path, monkeypatch):
    """The check can fail: the same block rendered from a changed record differs."""
    text = "<!-- render: flank_speed -->\n<!-- /render -->\n"
    rendered = dr.render_text(text)
    rec = json.loads((ROOT / "docs" / "data" / "flank_speed.json").read_text())
    rec["best"]["screw_jack"]["flanks_step_wall_us"] *= 2
    (tmp_path / "flank_speed.json").write_text(json.dumps(rec))
    monkeypatch.setattr(dr, "DATA", tmp_path)
    assert dr.render_text(rendered) != rendered


def test_unknown_block_is_named():
    with pytest.raises(KeyError, match="no_such_table"):
        dr.render_text("<!-- render: no_such_table -->\n<!-- /render -->\n")


def test_figures_are_byte_identical_run_to_run(tmp_path):
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    a = dr.render_figures(tmp_path / "a", ["bench_quick"])
    b = dr.render_figures(tmp_path / "b", ["bench_quick"])
    assert a and a[0].read_bytes() == b[0].read_bytes()
