"""sweep.png: the main outputs of the finished points against the first swept value, one line per value of a
second swept path (a colour scale when it takes many values), theory dashed where the summary has it, failed
points marked on the x axis."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from wormsim.sweep.spec import Plot

# summary key -> (axis label, theory key); the first six present are drawn
MAIN_OUTPUTS = {
    "tangential_force_mean_n": ("tangential force mean [N]", "tangential_force_theory_n"),
    "tangential_force_p2p_n": ("tangential force p2p [N]", None),
    "efficiency": ("efficiency", "efficiency_theory"),
    "ratio": ("ratio", "ratio_theory"),
    "transmission_error_p2p_urad": ("transmission error p2p [urad]", None),
    "mesh_frequency_hz": ("meshing frequency [Hz]", "mesh_frequency_theory_hz"),
    # wedge summaries (seed 000)
    "speed_steady_m_s": ("steady speed [m/s]", None),
    "S1_peak_n": ("S1 peak [N]", None),
    "S2_peak_n": ("S2 peak [N]", None),
    "efficiency_forward": ("efficiency forward", None),
}
# labels of other keys a sweep file's plot.outputs may name
LABELS = {
    "tangential_force_max_n": "tangential force max (steady) [N]",
    "startup_tangential_force_peak_n": "start-up tangential force peak [N]",
    "worm_torque_mean_nm": "worm torque mean [N m]",
    "wheel_speed_fluctuation": "wheel speed fluctuation",
}
MAX_PANELS = 6
MAX_LINES = 8
# the figure's margins and gaps in inches (matplotlib's subplots_adjust): fixed, not constrained_layout, which
# measures every tick label in extra passes (about 40 % of the figure's time, on the command's path after its last
# point)
MARGIN_IN = {"left": 0.95, "right": 0.25, "bottom": 0.6, "top": 0.55, "wspace": 1.2, "hspace": 0.85}


def parse_value(text):
    """A csv cell back to a number / bool / None where it is one."""
    if not isinstance(text, str):
        return text
    if text == "":
        return None
    if text in ("True", "False"):
        return text == "True"
    for cast in (int, float):
        try:
            return cast(text)
        except ValueError:
            pass
    return text


def _num(v):
    v = parse_value(v)
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        return None
    return float(v)


def _label(v) -> str:
    return f"{v:.4g}" if isinstance(v, float) else str(v)


MIN_REL_SPAN = 0.01  # a y axis spans at least this fraction of its value: a constant output reads as flat


def _plain_axes(ax, numeric_x: bool) -> None:
    """Tick labels as plain numbers, without matplotlib's offset ("1e-7+8.04e-1"), and a y range of at least
    MIN_REL_SPAN of the value, so that an output constant to rounding draws as a flat line, not as a slope."""
    from matplotlib.ticker import ScalarFormatter

    lo, hi = ax.get_ylim()
    mid = 0.5 * (lo + hi)
    if math.isfinite(mid) and hi - lo < MIN_REL_SPAN * abs(mid):
        half = 0.5 * MIN_REL_SPAN * abs(mid)
        ax.set_ylim(mid - half, mid + half)
    ax.yaxis.set_major_formatter(ScalarFormatter(useOffset=False))
    if numeric_x:
        ax.xaxis.set_major_formatter(ScalarFormatter(useOffset=False))


def _panels(plt, nrow: int, ncol: int):
    """(figure, axes grid) of nrow x ncol panels of 5.2 x 3.6 in, margins and gaps MARGIN_IN."""
    width_in, height_in = 5.2 * ncol, 3.6 * nrow
    fig, axes = plt.subplots(nrow, ncol, figsize=(width_in, height_in), squeeze=False)
    m = MARGIN_IN
    left, right = m["left"] / width_in, 1.0 - m["right"] / width_in
    bottom, top = m["bottom"] / height_in, 1.0 - m["top"] / height_in
    ax_w = (width_in * (right - left) - (ncol - 1) * m["wspace"]) / ncol
    ax_h = (height_in * (top - bottom) - (nrow - 1) * m["hspace"]) / nrow
    fig.subplots_adjust(left, bottom, right, top, wspace=m["wspace"] / ax_w, hspace=m["hspace"] / ax_h)
    return fig, axes


def write_sweep_png(rows: list[dict], swept: list[str], plot: Plot | None, path: str | Path, title: str = "") -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    plot = plot or Plot()
    ok = [r for r in rows if r.get("status") == "ok"]
    failed = [r for r in rows if r.get("status") != "ok"]
    keys = plot.outputs or [k for k in MAIN_OUTPUTS if any(_num(r.get(k)) is not None for r in ok)]
    keys = keys[:MAX_PANELS] or ["wall_time_s"]
    xkey = plot.x or swept[0]
    skey = plot.series or next((p for p in swept if p != xkey), None)
    xs_all = [parse_value(r.get(xkey)) for r in rows]
    numeric_x = all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in xs_all if x is not None)
    cats = sorted({str(x) for x in xs_all}) if not numeric_x else []

    def xpos(r):
        x = parse_value(r.get(xkey))
        return float(x) if numeric_x else float(cats.index(str(x)))

    pos = [xpos(r) for r in rows]
    log_x = (
        plot.log_x
        if plot.log_x is not None
        else (numeric_x and len(pos) > 1 and min(pos) > 0 and max(pos) / min(pos) > 50)
    )
    svals = [parse_value(r.get(skey)) for r in ok] if skey else []
    groups = sorted(set(svals), key=lambda v: (isinstance(v, str), v)) if skey else [None]
    continuous = skey is not None and len(groups) > MAX_LINES and all(isinstance(v, (int, float)) for v in groups)

    n = len(keys)
    ncol = 1 if n == 1 else 2 if n <= 4 else 3
    nrow = math.ceil(n / ncol)
    fig, axes = _panels(plt, nrow, ncol)
    for ax, key in zip(axes.flat, keys):
        label, theory = MAIN_OUTPUTS.get(key, (LABELS.get(key, key), None))
        if continuous:
            x = [xpos(r) for r in ok]
            y = [_num(r.get(key)) for r in ok]
            sc = ax.scatter(
                x, [np.nan if v is None else v for v in y], c=[float(v) for v in svals], s=14, cmap="viridis"
            )
            fig.colorbar(sc, ax=ax, label=skey)
        else:
            for g in groups:
                sel = sorted((r for r in ok if not skey or parse_value(r.get(skey)) == g), key=xpos)
                x = [xpos(r) for r in sel]
                y = [_num(r.get(key)) for r in sel]
                ax.plot(
                    x,
                    [np.nan if v is None else v for v in y],
                    "o-",
                    ms=3,
                    label=f"{skey} = {_label(g)}" if skey else None,
                )
                if theory and any(_num(r.get(theory)) is not None for r in sel):
                    yt = [_num(r.get(theory)) for r in sel]
                    ax.plot(
                        x,
                        [np.nan if v is None else v for v in yt],
                        "--",
                        color=ax.lines[-1].get_color(),
                        lw=1,
                        label="theory" if g == groups[0] else None,
                    )
        if failed:
            ax.plot(
                [xpos(r) for r in failed],
                [0.02] * len(failed),
                "x",
                color="red",
                ms=7,
                transform=ax.get_xaxis_transform(),
                clip_on=False,
                label=f"failed ({len(failed)})",
            )
        ax.set_xlabel(xkey)
        ax.set_ylabel(label)
        if log_x:
            ax.set_xscale("log")
        if not numeric_x:
            ax.set_xticks(range(len(cats)), cats)
        _plain_axes(ax, numeric_x and not log_x)
        ax.grid(alpha=0.3)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=7)
    for ax in list(axes.flat)[n:]:
        ax.set_visible(False)
    fig.suptitle(f"sweep {title}: {len(ok)} ok, {len(failed)} failed of {len(rows)} points")
    path = Path(path)
    tmp = path.with_name(f".{path.name}.tmp.png")
    fig.savefig(tmp, dpi=100)
    plt.close(fig)
    os.replace(tmp, path)
