"""README.md for a newcomer: short, the two commands CI and `make demo` use, no lab notebook."""

from __future__ import annotations

import re

from tests.conftest import ROOT

README = (ROOT / "README.md").read_text()


def test_readme_is_short_and_names_the_two_commands():
    """At most 300 lines (a newcomer reads it in minutes); `make demo` and `make test` (.ci/run calls the latter)."""
    assert len(README.splitlines()) <= 300
    assert "make demo" in README and "make test" in README


def test_readme_has_no_history():
    """Facts in the present tense: no pass, stop or issue history, no xfail bookkeeping (STYLE.md, "Present tense":
    history goes to docs/decisions/)."""
    for pattern in (r"\b(first|second|third|fourth|fifth|sixth|seventh) pass\b", r"\bthis stop\b", r"\bissue \d+",
                    r"\bxfail", r"\bwas \d", r"\bbefore issue"):  # fmt: skip
        assert not re.search(pattern, README, re.IGNORECASE), pattern


def test_readme_template_is_a_valid_scenario(tmp_path):
    """The "your own gear" template in the README loads as a scenario (the file a newcomer copies)."""
    from wormsim.scenario import load_scenario

    block = README.split("```yaml\n", 1)[1].split("```", 1)[0]
    path = tmp_path / "my_gear.yaml"
    path.write_text(block)
    sc = load_scenario(path)
    assert sc.name == "my_gear" and sc.gear.worm_starts == 2 and sc.gear.wheel_teeth == 30


def test_readme_template_is_what_wormsim_init_writes(tmp_path, monkeypatch):
    """`wormsim init my_gear.yaml` writes the README's template character for character, and its profile comment
    names all five flank forms."""
    from wormsim.cli.init import write_template

    block = README.split("```yaml\n", 1)[1].split("```", 1)[0]
    monkeypatch.chdir(tmp_path)
    path = write_template("my_gear.yaml")
    assert path.read_text() == block
    profile = block.split("profile:", 1)[1].split("\n  hand:", 1)[0]
    for form in ("ZA", "ZN", "ZI", "ZK", "ZC"):
        assert form in profile, form
    assert "model: torsional" in block and "duration_s: 0.5" in block
