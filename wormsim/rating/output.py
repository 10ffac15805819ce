"""rating.json and rating.md of `wormsim rate`, written atomically into a locked folder (wormsim.runfolder.writer)."""

from __future__ import annotations

from pathlib import Path

from wormsim.runfolder.writer import locked_dir, write_json_atomic, write_text_atomic

RATING_FILES = ("rating.json", "rating.md")

SAFETY_ROWS = (
    ("safety_pitting", "S_H", "pitting"),
    ("safety_wear", "S_W", "wear"),
    ("safety_root", "S_F", "tooth root (nominal shear stress)"),
    ("safety_deflection", "S_delta", "worm deflection"),
    ("safety_temperature", "S_T", "oil sump temperature"),
    ("safety_pitting_sim", "S_H,sim", "pitting, sigma_H from the simulation"),
    ("safety_root_sim", "S_F,sim", "tooth root, FE root stress"),
)


def _fmt(v) -> str:
    if v is None:
        return "-"
    if isinstance(v, bool):
        return str(v).lower()
    if isinstance(v, float):
        return f"{v:.4g}"
    return str(v)


def markdown(result: dict, scenario_name: str) -> str:
    """The readable report: inputs, safety factors, every intermediate factor with its symbol and source, warnings,
    sources."""
    lines = [f"# Load-capacity rating: {scenario_name}", ""]
    lines += [
        "ISO/TS 14521 / DIN 3996 method B and AGMA 6034 as publicly reproduced (formulas and sources: "
        "docs/rating.md). A safety factor below 1 fails its criterion; `-` is not computed (see the warnings).",
        "",
    ]
    if result.get("refused"):
        lines += [f"**Not rated:** {result['refused']}", ""]
    lines += ["## Safety factors", "", "| criterion | symbol | safety |", "| --- | --- | --- |"]
    for key, sym, what in SAFETY_ROWS:
        if key in result:
            lines.append(f"| {what} | {sym} | {_fmt(result[key])} |")
    lines += [
        "",
        f"Oil sump temperature {_fmt(result.get('oil_temperature_c'))} C; mean Hertz stress "
        f"{_fmt(result.get('contact_stress_mean_iso_mpa'))} MPa; friction {_fmt(result.get('friction_iso'))}; "
        f"efficiency {_fmt(result.get('efficiency_iso'))} (worm driving); sliding speed "
        f"{_fmt(result.get('sliding_speed_m_s'))} m/s.",
        f"AGMA 6034: allowable wheel tangential force {_fmt(result.get('agma_rated_tangential_force_n'))} N, "
        f"friction {_fmt(result.get('agma_friction'))}, efficiency {_fmt(result.get('agma_efficiency'))}.",
        "",
    ]
    fe = result.get("fe_root")
    if fe:
        lines += [
            "## FE root stress (wheel tooth)",
            "",
            f"Max principal stress at the root {_fmt(result.get('root_stress_max_mpa'))} MPa at "
            f"({', '.join(f'{v:.1f}' for v in fe.get('position_mm', []))}) mm (wheel frame: x, y, z along the wheel "
            f"axis), range over the tooth's engagement {_fmt(result.get('root_stress_range_mpa'))} MPa; "
            f"{fe.get('elements')} tetrahedra (mesh density {fe.get('density')}), {fe.get('positions')} positions; "
            "not mesh-converged within 5 % (docs/rating.md, 'FE root stress').",
            "",
        ]
    lines += ["## Inputs", "", "| input | value |", "| --- | --- |"]
    lines += [f"| {k} | {_fmt(v)} |" for k, v in result.get("inputs", {}).items()]
    lines += ["", "## Factors", "", "| symbol | value | unit | meaning | source |", "| --- | --- | --- | --- | --- |"]
    lines += [
        f"| {r['symbol']} | {_fmt(r['value'])} | {r['unit']} | {r['meaning']} | {r['source']} |"
        for r in result.get("factors", [])
    ]
    lines += ["", "## Warnings", ""]
    lines += [f"- {w}" for w in result.get("warnings", [])] or ["- none"]
    lines += ["", "## Sources", ""]
    lines += [f"- {s}" for s in result.get("sources", [])]
    return "\n".join(lines) + "\n"


def write_rating(out_dir: str | Path, result: dict, scenario_name: str) -> tuple[Path, Path]:
    """DIR/rating.json and DIR/rating.md, each replaced whole or not at all, one writer per folder."""
    with locked_dir(out_dir, names=RATING_FILES) as out:
        write_text_atomic(out / "rating.md", markdown(result, scenario_name))
        write_json_atomic(out / "rating.json", {"scenario": scenario_name, **result})
    return out / "rating.json", out / "rating.md"
