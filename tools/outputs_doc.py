"""docs/outputs.md, generated from the summary-key table wormsim.results.summary_keys
(`python -m tools.outputs_doc > docs/outputs.md`); tests/results/test_summary_keys.py keeps the file current."""

from __future__ import annotations

import sys

from wormsim.results.summary_keys import ALL, FORCE_KEYS, FORCE_SIGNS, KEYS, SERIES, SIGN_NOTE


def markdown() -> str:
    """docs/outputs.md."""
    lines = [
        "# Outputs: summary.json keys and time series",
        "",
        "Generated from `wormsim/results/summary_keys.py` (`python -m tools.outputs_doc > docs/outputs.md`); "
        "do not edit by hand.",
        "Every run writes `DIR/summary.json`, `DIR/timeseries.npz` (arrays on `t_s`, units in the names), "
        "`DIR/report.png` and `DIR/recording.rrd`. Levels: W wedge, T torsional, C contact3d.",
        "",
        "## Force signs",
        "",
        "Forces are those the worm exerts on the wheel, at the pitch point on the line of centres, in the wheel's "
        "directions there (DIN 3975-2):",
        "",
    ]
    lines += [f"- **{k}**: {v}." for k, v in FORCE_SIGNS.items()]
    lines += [
        "",
        SIGN_NOTE,
        "",
        "## Force keys",
        "",
        FORCE_KEYS + ".",
        "",
        "## Keys",
        "",
        "| key | unit | levels | meaning |",
        "| --- | --- | --- | --- |",
    ]
    for name, k in KEYS.items():
        lv = "".join(x[0].upper() for x in ALL if x in k.levels)
        sign = f" Sign: {k.sign}." if k.sign else ""
        lines.append(f"| `{name}` | {k.unit} | {lv} | {k.meaning}.{sign} |")
    lines += [
        "",
        "## Time series (timeseries.npz, recording.rrd /series/)",
        "",
        "Arrays sampled on `t_s`; the unit is in the name.",
        "",
        "| series | levels | meaning |",
        "| --- | --- | --- |",
    ]
    for name, (levels, meaning) in SERIES.items():
        lv = "".join(x[0].upper() for x in ALL if x in levels)
        lines.append(f"| `{name}` | {lv} | {meaning}. |")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    sys.stdout.write(markdown())
