"""`wormsim check`: the derived values printed after the validated scenario, as YAML comments: the gear's sizes
(DIN 3975 names), the level's timestep and, at contact3d with exact flanks, the slices across the face. Each value
is the one the run takes (the same functions), so the user sees what a run will use before it starts."""

from __future__ import annotations

import math
from types import SimpleNamespace

from wormsim.physics.geometry import derive
from wormsim.physics.units import rad_s_to_rpm
from wormsim.scenario import Scenario


def gear_lines(sc: Scenario) -> list[str]:
    """The derived sizes of gear: (mm, deg), one per line; none without a gear: block (a wedge: block's scenario)."""
    if sc.gear is None:
        return []
    g = derive(sc.gear)
    mm = 1e3
    return [
        f"ratio z2 / z1: {g.ratio:.6g}",
        f"lead angle gamma: {math.degrees(g.gamma):.4g} deg",
        f"worm reference diameter d1: {g.d1 * mm:.4g} mm, tip diameter d_a1: {2 * g.r_a1 * mm:.4g} mm, root "
        f"diameter d_f1: {2 * g.r_f1 * mm:.4g} mm",
        f"wheel reference diameter d2: {g.d2 * mm:.4g} mm, throat diameter d_a2: {2 * g.r_a2 * mm:.4g} mm, outside "
        f"diameter d_e2: {2 * g.r_e2 * mm:.4g} mm",
        f"centre distance a: {g.a * mm:.4g} mm (profile shift x2 = {g.x2:g}; the worm meshes on d_m1 "
        f"{2 * g.r_m1 * mm:.4g} mm at gamma_m {math.degrees(g.gamma_m):.4g} deg)",
        f"wheel face width b2: {g.face_width * mm:.4g} mm{'' if sc.gear.face_width_mm else ' (default)'}",
        f"worm length b1: {g.worm_length * mm:.4g} mm",
    ]


def torsional_timestep_s(sc: Scenario) -> float:
    """The torsional run's step: simulation.timestep_s, else one k(theta) sample of worm rotation (a mesh period
    2 pi / z1 over simulation.mesh_stiffness_samples) at the full command speed (wormsim.torsional.dynamics)."""
    from wormsim.torsional.dynamics import default_timestep

    if sc.simulation.timestep_s:
        return sc.simulation.timestep_s
    assert sc.gear is not None and sc.drive is not None  # the gear levels need both (Scenario's validation)
    g = derive(sc.gear)
    drv = sc.drive
    speed_driven = drv.speed_rpm is not None
    w = abs(drv.speed_rpm or 0.0) * math.pi / 30 if speed_driven else 2 * math.pi
    w1 = w * (g.ratio if (speed_driven and drv.on == "wheel") else 1.0)
    ms = SimpleNamespace(period_rad=2 * math.pi / g.z1, samples=sc.simulation.mesh_stiffness_samples)
    return default_timestep(g, ms, w1, sc.simulation.duration_s)  # type: ignore[arg-type]


def level_lines(sc: Scenario) -> list[str]:
    """The timestep (and the slices) the scenario's level uses."""
    if sc.model == "torsional":
        h = torsional_timestep_s(sc)
        src = "simulation.timestep_s" if sc.simulation.timestep_s else "one k(theta) sample at the command speed"
        return [f"timestep: {h:.3g} s ({src}), {sc.simulation.duration_s / h:.0f} steps"]
    if sc.model != "contact3d":
        return []
    from wormsim.contact3d.flank_step import merge_group
    from wormsim.contact3d.mjcf import build, flank_slices, prepare
    from wormsim.contact3d.timestep import timestep_for

    p = prepare(sc)
    h, src = timestep_for(
        sc.simulation.timestep_s, p.worm_speed_rad_s, p.law, p.scaling.factor if p.scaling is not None else 1.0
    )
    if sc.shafts is not None and sc.simulation.timestep_s is None:  # the shafts' modes may lower it: the built model's
        bm = build(p)
        h, src = float(bm.model.opt.timestep), bm.timestep_source
    out = [
        f"timestep: {h:.3g} s ({src}), {sc.simulation.duration_s / h:.0f} steps; stable limit "
        f"{p.law.stable_limit_s:.3g} s",
    ]
    if p.worm_speed_rad_s:
        out.append(f"worm speed command: {rad_s_to_rpm(abs(p.worm_speed_rad_s)):.5g} rpm")
    if sc.contact.geometry == "flanks":
        src = "contact.slices" if sc.contact.slices else f"default for resolution {sc.simulation.resolution}"
        slices = flank_slices(sc, p.geometry)
        out.append(f"flank slices across the face: {slices} ({src})")
        fc = sc.contact.flank_contacts
        if fc != "slice":
            group = merge_group(fc, slices)
            per = "one per slice" if group == 0 else f"{group} slices each"
            out.append(f"MuJoCo contacts per tooth flank: {fc} ({per}; contact.flank_contacts)")
    return out


def derived_text(sc: Scenario) -> str:
    """The derived values as YAML comment lines (the printed scenario stays valid YAML)."""
    lines = ["derived (what the run uses):"] + [f"  {x}" for x in gear_lines(sc) + level_lines(sc)]
    return "".join(f"# {x}\n" for x in lines)
