"""Repository tooling, not part of the installed package: docs_render (`make docs`), api_doc (docs/api.md),
schema_doc (docs/scenario.md), outputs_doc (docs/outputs.md). Run from the repository root: `python -m tools.NAME`."""
