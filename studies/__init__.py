"""Measurement and study scripts: each writes a record under docs/data/ (wormsim.results.provenance) or a sweep
file for `wormsim sweep`; `make docs` renders the records (tools.docs_render). Not part of the installed package."""
