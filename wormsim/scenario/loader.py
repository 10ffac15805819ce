"""Loading a scenario: the YAML reader within limits (size, depth, expanded nodes; YAML 1.2 booleans), `--set`
overrides, validation into a Scenario, and every failure as one ScenarioError (exit 2) naming the field."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import yaml
from pydantic import BaseModel, ValidationError

from wormsim.exceptions import ScenarioError
from wormsim.scenario.messages import MAX_SHOWN, abbreviate, describe_errors
from wormsim.scenario.schema import Scenario

MAX_FILE_BYTES = 256_000  # a scenario file is a few kB; larger input is refused before parsing (pure-Python YAML)
MAX_DEPTH = 32  # nesting of blocks/lists (the schema needs 4)
MAX_NODES = 100_000  # YAML nodes after alias expansion ("billion laughs": 373 bytes -> 1e9 nodes)


class _Loader(yaml.SafeLoader):
    """YAML 1.2 booleans: only true/false. YAML 1.1 would read the key `on:` (drive.on) as True.

    Nesting deeper than MAX_DEPTH is refused while composing (PyYAML's composer recurses: 70 000 `[` gave a
    RecursionError), and the node graph is measured with aliases expanded before any Python object is built."""

    def compose_node(self, parent, index):
        self._depth = getattr(self, "_depth", 0) + 1
        try:
            if self._depth > MAX_DEPTH:
                mark = self.peek_event().start_mark
                raise ScenarioError(
                    f"nested deeper than {MAX_DEPTH} levels at line {mark.line + 1}; a scenario needs at most 4"
                )
            return super().compose_node(parent, index)
        finally:
            self._depth -= 1


_Loader.yaml_implicit_resolvers = {
    ch: [(tag, rx) for tag, rx in resolvers if tag != "tag:yaml.org,2002:bool"]
    for ch, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()
}
_Loader.add_implicit_resolver(
    "tag:yaml.org,2002:bool", re.compile(r"^(?:true|True|TRUE|false|False|FALSE)$"), list("tTfF")
)


def _expanded_size(root) -> int:
    """Nodes of the YAML graph with every alias expanded, computed per distinct node (linear in the file)."""
    size: dict[int, int] = {}
    stack = [(root, False)]
    while stack:
        node, done = stack.pop()
        if id(node) in size:
            continue
        children = (
            [c for pair in node.value for c in pair]
            if isinstance(node, yaml.MappingNode)
            else (node.value if isinstance(node, yaml.SequenceNode) else [])
        )
        if done:
            size[id(node)] = 1 + sum(size.get(id(c), 0) for c in children)  # a cycle counts 0 (refused below)
        else:
            stack.append((node, True))
            stack.extend((c, False) for c in children if id(c) not in size)
    return size[id(root)]


def yaml_load(text: str, source: str = "scenario"):
    """Parse one YAML document within the limits above; ScenarioError (exit 2) for anything else."""
    try:
        loader = _Loader(text)
        try:
            node = loader.get_single_node()
            if node is None:
                return None
            n = _expanded_size(node)
            if n > MAX_NODES:
                raise ScenarioError(
                    f"{source}: {n:.3g} YAML values (aliases expanded); allowed at most {MAX_NODES} "
                    "(a scenario has about 100)"
                )
            return loader.construct_document(node)
        finally:
            loader.dispose()
    except ScenarioError as exc:
        raise ScenarioError(str(exc) if str(exc).startswith(source) else f"{source}: {exc}") from None
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}" if mark else ""
        problem = getattr(exc, "problem", None) or exc.__class__.__name__
        raise ScenarioError(f"{source}: not valid YAML{where} ({abbreviate(problem)})") from None
    except RecursionError:  # a cycle or a depth the composer guard did not see (constructor)
        raise ScenarioError(f"{source}: nested too deeply (allowed at most {MAX_DEPTH} levels)") from None
    except (ValueError, TypeError, OverflowError) as exc:  # constructors of odd tags/values
        raise ScenarioError(f"{source}: a value cannot be read ({exc.__class__.__name__}: {abbreviate(exc)})") from None


def format_validation_error(err: ValidationError, source: str = "scenario", root: type[BaseModel] | None = None) -> str:
    """One line per problem (wormsim.scenario.messages), the Scenario's fields as the top of every dotted name."""
    return describe_errors(err, source, root, Scenario)


def parse_override(text: str) -> tuple[list[str], Any]:
    """`--set a.b.c=VALUE`; VALUE is parsed as YAML (numbers, booleans, lists, null)."""
    if "=" not in text:
        raise ScenarioError(f"--set {text}: expected KEY=VALUE with a dotted KEY, e.g. gear.wheel_teeth=41")
    key, raw = text.split("=", 1)
    path = [p for p in key.strip().split(".") if p]
    if not path:
        raise ScenarioError(f"--set {text}: empty KEY")
    value = yaml_load(raw, f"--set {key.strip()[: 2 * MAX_SHOWN]}") if raw.strip() else ""
    return path, value


def set_path(data: dict, path: list[str], value: Any, source: str) -> dict:
    """data[path[0]][path[1]]... = value, creating missing blocks; `source` starts the error message."""
    node = data
    for i, key in enumerate(path[:-1]):
        nxt = node.get(key)
        if nxt is None:
            nxt = node[key] = {}
        if not isinstance(nxt, dict):
            raise ScenarioError(f"{source}: '{'.'.join(path[: i + 1])}' is not a block")
        node = nxt
    node[path[-1]] = value
    return data


def apply_overrides(data: dict, overrides: list[str]) -> dict:
    for text in overrides:
        path, value = parse_override(text)
        set_path(data, path, value, f"--set {text}")
    return data


def scenario_from_dict(data: Any, source: str = "scenario", overrides: list[str] | None = None) -> Scenario:
    if not isinstance(data, dict):
        raise ScenarioError(f"{source}: the top level must be a mapping of keys (name, model, gear, ...)")
    data = apply_overrides(dict(data), overrides or [])
    try:
        return Scenario.model_validate(data)
    except ValidationError as err:
        raise ScenarioError(format_validation_error(err, source)) from None


def load_scenario(path: str | Path, overrides: list[str] | None = None) -> Scenario:
    """Read and validate a scenario YAML file (docs/scenario.md has every key, its unit and default).

    Args:
        path: the scenario file (YAML, UTF-8, at most 256 kB).
        overrides: `--set` style "dotted.key=VALUE" strings applied before validation, e.g.
            ["model=torsional", "gear.wheel_teeth=41", "simulation.duration_s=0.1"]; VALUE is read as YAML.

    Returns:
        Scenario: the validated model; its blocks validate on assignment (`sc.gear.axial_module_mm = -3` raises
        ScenarioError and leaves the block as it was).

    Raises:
        ScenarioError: the file is missing or unreadable, or a value is invalid; the message names the field, the
            value and what is allowed, one line per problem (exit 2 at the CLI).
    """
    path = Path(path)
    if path.suffix.lower() in (".rexs", ".rexsj"):  # a REXS worm stage, imported in memory (wormsim.scenario.rexs)
        from wormsim.scenario import rexs

        imp = rexs.import_file(path)
        return scenario_from_dict(imp.data, str(path.name), overrides)
    if not path.is_file():
        raise ScenarioError(f"{path}: no such scenario file")
    try:
        size = path.stat().st_size
        if size > MAX_FILE_BYTES:
            raise ScenarioError(f"{path}: {size} bytes; a scenario file may have at most {MAX_FILE_BYTES} bytes")
        raw = path.read_bytes()
    except OSError as exc:
        raise ScenarioError(f"{path}: cannot read: {exc.strerror or exc}") from None
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise ScenarioError(f"{path}: not a UTF-8 text file (byte {exc.start}); a scenario is YAML text") from None
    data = yaml_load(text, path.name)
    return scenario_from_dict(data, str(path.name), overrides)
