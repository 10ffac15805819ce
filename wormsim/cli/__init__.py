"""The `wormsim` console script: entry (the parser, the dispatch, the exit codes), and the commands that are not a
level's or a tool's own: check (the derived values), init (the scenario template), mesh (the geometry files)."""

from wormsim.cli.entry import main

__all__ = ["main"]
