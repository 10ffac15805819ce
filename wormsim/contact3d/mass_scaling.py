"""Mass scaling for quasi-static contact3d runs (`simulation.mass_scaling`).

Explicit FE codes add inertia to quasi-static runs and check that the kinetic energy stays a small part of the work
(Abaqus Analysis User's Guide 6.14, "Mass scaling" and "Quasi-static analysis": kinetic energy a small fraction,
5-10 %, of the internal energy; LS-DYNA *CONTROL_TIMESTEP DT2MS). Here both shafts' axial inertias, and the driven
machine's load.inertia_kg_m2, are multiplied by S before the contact law takes them (wormsim.contact3d.mjcf.prepare).
The law's A_hat = arm1^2 / (I1 + J1) + arm2^2 / (I2 + J2) is then A_hat / S, so everything that follows from it
follows S: the mesh mode omega = sqrt(K A_hat) falls by sqrt(S), the stable limit grows by sqrt(S), the damping cap
(10 % of 2 sqrt(K m_eff)) grows by sqrt(S), impratio (law (3)) falls by sqrt(S) (impratio x c_c, the friction
regularisation, stays). The step is SCALED_STEP_FRACTION of the scaled stable limit (at 0.62 of it a scaled run rang).

What stays: the means over whole mesh periods (ratio, mean forces, efficiency); what is lost: everything the inertia
shapes (F_t p2p, transmission error, the wheel's rattle, start-up peaks). So S > 1 is refused (ScenarioError naming
simulation.mass_scaling, exit 2) where a run is dynamic:

- a torque drive (its speed, hence the meshing frequency, is not known before the run);
- the scaled mesh mode f_S = sqrt(K A_hat / S) / (2 pi) (one tooth pair: the lowest) below MODE_TO_MESH_MIN x the
  meshing frequency f_z = z1 n1 / 60: the mode must stay well above the meshing frequency and its first harmonics
  (a harmonic k f_z amplifies by 1 / (1 - (k f_z / f_S)^2): under 1 % up to k = 10 at f_S = MODE_TO_MESH_MIN f_z;
  measured on the seat motor at 36 rpm: at 50 x the tangential force's spectrum peaked at the scaled mode, not at
  f_z, while ratio and efficiency still held; at 113 x it peaked at f_z);
- with contact.geometry pieces, f_S below FACET_TO_MODE_MIN x the piece-passing frequency (worm pieces per turn x
  n1 / 60), whose facets excite the mesh (seat motor, 36 rpm, pieces medium, 28.8 Hz: at S = 5000, f_S = 4.7 x it,
  the efficiency fell 1.9 % against the unscaled pieces run, with flanks it held to 4e-7);
- drive.ramp_s (and load.ramp_s when there is a load) shorter than RAMP_PERIODS_MIN scaled mode periods 1 / f_S;
- the estimated kinetic-energy share above KE_SHARE_TARGET (below).

Kinetic-energy share, the one definition for the estimate and the measurement: the largest, from the end of the
ramps (gear_theory.ramps_end_s) to the end of the run, of KE(t) / W(t), KE = (I1 w1^2 + I2 w2^2) / 2 with the scaled
inertias (load inertia included), W(t) the drive's work since t = 0. Before the run: the commanded steady speeds and
W from the drive and load STEPs, P = T_drive w_drive with T_drive = gear_theory.expected_drive_torque_nm (the load
through the mesh at the wedge efficiency), at the end of the ramps (where the share is largest: W only grows). After
the run: the sampled speeds (the rattle included) and the runner's step-by-step drive power.
`auto` takes the largest S that passes every check, rounded down to 1-2-5 (1 when none does).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from wormsim.exceptions import RingingError
from wormsim.physics import gear_theory as gt
from wormsim.physics.units import rpm_to_rad_s
from wormsim.scenario import ScenarioError

KE_SHARE_TARGET = 0.01  # kinetic energy at most 1 % of the drive's work
MODE_TO_MESH_MIN = 100.0  # scaled mesh mode at least 100 x the meshing frequency (seat motor, 36 rpm: at 50 x
# the F_t spectrum peaked at the scaled mode, at 113 x at z1 n1 / 60)
FACET_TO_MODE_MIN = 20.0  # contact.geometry pieces: scaled mode at least 20 x the piece-passing frequency
RAMP_PERIODS_MIN = 10.0  # ramps at least 10 scaled mesh-mode periods (S = 1e4 failed 0.05 s ramps: 5.7)
SCALED_STEP_FRACTION = 0.35  # default step of a scaled run: this fraction of the scaled stable limit
SCALED_SAMPLES = 2000  # automatic record_every of a scaled run aims at this many samples (the per-sample
# bookkeeping cost more than the scaled steps; samples are means over their steps)
RINGING_KE_SHARE = 10 * KE_SHARE_TARGET  # measured share beyond this, or efficiency > 1: the run rang
AUTO_MAX = 1e8  # the schema's upper bound


@dataclass(frozen=True)
class ScalingCheck:
    """What the checks found for a factor S (SI)."""

    factor: float
    mode_hz: float  # scaled mesh mode of one tooth pair
    mesh_hz: float  # z1 n1 / 60 at the commanded speed
    ramp_s: float  # the shortest ramp that counts
    ke_share_estimate: float
    factor_limits: dict  # the largest S each check allows
    facet_hz: float = float("nan")  # contact.geometry pieces: worm pieces per turn x n1 / 60


def _work_j(duty: gt.Duty, t_drv: float, t_s: float) -> float:
    """Drive work from 0 to t_s at the commanded speeds and the expected drive torque t_drv (module docstring)."""
    w_drv = abs(rpm_to_rad_s(duty.drive.speed_rpm))
    if t_s <= 0:
        return 0.0
    t = np.linspace(0.0, t_s, 2001)
    cmds = duty.commands  # only their magnitudes count
    s_drv = np.abs(cmds.drive(t)) / max(abs(cmds.drive_target), 1e-300)
    s_load = np.abs(cmds.load(t)) / abs(cmds.load_target_nm) if cmds.load_target_nm else np.ones_like(t)
    return float(np.trapezoid(t_drv * w_drv * s_drv * s_load, t))


def kinetic_energy_j(inertias_kg_m2: tuple[float, float], w1_rad_s, w2_rad_s):
    """(I1 w1^2 + I2 w2^2) / 2 (floats or arrays)."""
    return 0.5 * (inertias_kg_m2[0] * np.square(w1_rad_s) + inertias_kg_m2[1] * np.square(w2_rad_s))


def check(
    duty: gt.Duty,
    ratio: float,
    z1: int,
    worm_speed_rad_s: float,
    drive_torque_nm: float,
    pair_stiffness_n_per_m: float,
    inv_mass_hat: float,
    inertias_kg_m2: tuple[float, float],
    factor: float,
    segments_per_turn: int = 0,
) -> ScalingCheck:
    """The quasi-static checks for factor S with the UNSCALED A_hat and shaft inertias (I1 + J1, I2 + J2) of a
    speed-driven run (duty) at the commanded worm speed (gear_theory.worm_speed_command_rad_s) and the drive's
    expected torque (gear_theory.expected_drive_torque_of); segments_per_turn: the worm's convex pieces per turn
    (contact.geometry pieces; 0 for flanks)."""
    w1 = worm_speed_rad_s
    mesh_hz = z1 * w1 / (2 * math.pi)
    mode1_hz = math.sqrt(pair_stiffness_n_per_m * inv_mass_hat) / (2 * math.pi)
    facet_hz = segments_per_turn * w1 / (2 * math.pi)
    ramps = [duty.drive.ramp_s] + ([duty.load.ramp_s] if duty.load.torque_nm != 0 else [])
    ramp = min(ramps)
    work = _work_j(duty, drive_torque_nm, duty.ramps_end_s)
    ke1 = float(kinetic_energy_j(inertias_kg_m2, w1, w1 / ratio))
    limits = {
        "mode": (mode1_hz / (MODE_TO_MESH_MIN * mesh_hz)) ** 2 if mesh_hz > 0 else float("inf"),
        "ramp": (ramp * mode1_hz / RAMP_PERIODS_MIN) ** 2,
        "facets": (mode1_hz / (FACET_TO_MODE_MIN * facet_hz)) ** 2 if facet_hz > 0 else float("inf"),
        # KE share at S: S ke1 / (work + S ke1) <= target
        "kinetic_energy": KE_SHARE_TARGET * work / ((1 - KE_SHARE_TARGET) * ke1) if ke1 > 0 else float("inf"),
    }
    ke_s = factor * ke1 / (work + factor * ke1) if ke1 > 0 else 0.0  # at standstill: no kinetic energy
    return ScalingCheck(
        factor,
        mode1_hz / math.sqrt(factor),
        mesh_hz,
        ramp,
        ke_s,
        limits,
        facet_hz if segments_per_turn else float("nan"),
    )


def refuse_if_dynamic(c: ScalingCheck, requested) -> None:
    """ScenarioError (exit 2) naming simulation.mass_scaling when factor S > 1 fails a check."""
    if c.factor <= 1:
        return
    head = f"simulation.mass_scaling = {requested:g}: the run is dynamic"
    lim = min(c.factor_limits.values())
    allowed = f"allowed here: 1 <= simulation.mass_scaling <= {max(1.0, lim):.3g} (or auto)"
    if c.mode_hz < MODE_TO_MESH_MIN * c.mesh_hz:
        raise ScenarioError(
            f"{head}: the scaled mesh mode {c.mode_hz:.3g} Hz comes within {MODE_TO_MESH_MIN:g} x the "
            f"meshing frequency {c.mesh_hz:.3g} Hz (z1 n1 / 60) and its harmonics; {allowed}"
        )
    if c.factor > c.factor_limits.get("facets", float("inf")):
        facet_hz = c.facet_hz
        raise ScenarioError(
            f"{head}: the scaled mesh mode {c.mode_hz:.3g} Hz comes within {FACET_TO_MODE_MIN:g} x the "
            f"frequency at which the worm's convex pieces pass ({facet_hz:.3g} Hz, contact.geometry "
            f"pieces); use contact.geometry flanks, or {allowed}"
        )
    if c.ramp_s < RAMP_PERIODS_MIN / c.mode_hz:
        raise ScenarioError(
            f"{head}: the ramp of {c.ramp_s:.3g} s is shorter than {RAMP_PERIODS_MIN:g} periods of the "
            f"scaled mesh mode ({RAMP_PERIODS_MIN / c.mode_hz:.3g} s at {c.mode_hz:.3g} Hz); lengthen "
            f"drive.ramp_s / load.ramp_s, or {allowed}"
        )
    if c.ke_share_estimate > KE_SHARE_TARGET:
        raise ScenarioError(
            f"{head}: the kinetic energy would be {100 * c.ke_share_estimate:.3g} % of the drive's "
            f"work at the end of the ramps (at most {100 * KE_SHARE_TARGET:g} %); {allowed}"
        )


def resolve(ms, duty: gt.Duty, **kw) -> ScalingCheck:
    """The factor a run uses: ms, the scenario's simulation.mass_scaling (checked: refuse_if_dynamic), or auto's (the
    largest passing S, 1-2-5 rounded down, 1 when even S = 1 fails a check). kw: check's arguments less `duty` and
    `factor`."""
    if ms == 1:
        return (
            check(duty, factor=1.0, **kw)
            if duty.speed_driven
            else ScalingCheck(1.0, float("nan"), float("nan"), float("nan"), float("nan"), {})
        )
    if not duty.speed_driven:
        raise ScenarioError(
            f"simulation.mass_scaling = {ms}: needs a speed-driven drive (drive.speed_rpm): with "
            "drive.torque_nm the speed, the meshing frequency and the kinetic energy are not known "
            "before the run; allowed: simulation.mass_scaling = 1 with a torque drive"
        )
    c1 = check(duty, factor=1.0, **kw)
    if ms == "auto":
        s = min(AUTO_MAX, *c1.factor_limits.values())
        s = gt.round_down_125(s) if s >= 1 else 1.0
        return check(duty, factor=s, **kw)
    c = check(duty, factor=float(ms), **kw)
    refuse_if_dynamic(c, ms)
    return c


def measured_ke_share(
    S: dict, inertias_kg_m2: tuple[float, float], t_from_s: float, drive_power_w: np.ndarray
) -> float:
    """The measured share (module docstring) from the runner's series: KE at each sample's end from the sampled speeds,
    W from the drive shaft's interval-mean power (every step's T w) times the interval."""
    t = S["t_s"]
    if not len(t):
        return float("nan")
    w1, w2 = rpm_to_rad_s(S["worm_speed_rpm"]), rpm_to_rad_s(S["wheel_speed_rpm"])
    ke = kinetic_energy_j(inertias_kg_m2, w1, w2)
    dt = np.diff(t, prepend=0.0)
    work = np.cumsum(drive_power_w * dt)
    sel = (t >= t_from_s) & (work > 0)
    if not sel.any():
        return float("nan")
    return float(np.max(ke[sel] / work[sel]))


def floor_2_digits(x: float) -> float:
    """x rounded down to two significant digits, as its decimal value (2.4e-04, not 2.4 * 10.0 ** -4)."""
    e = math.floor(math.log10(x)) - 1
    return float(f"{math.floor(x / 10**e * (1 + 1e-12))}e{e}")


def run_summary(
    S: dict, duty: gt.Duty, requested, c: ScalingCheck, inertias_kg_m2: tuple[float, float], summary: dict
) -> dict:
    """Summary keys of the run's scaling (mass_scaling, kinetic_energy_share, ..., requested: the scenario's
    simulation.mass_scaling; c: the scaling's check, inertias_kg_m2: the shafts' scaled (I1, I2) with the driven
    machine's) and the ringing guard: a scaled run whose efficiency exceeds 1 (output power above input:
    the power balance broken) or whose measured kinetic-energy share exceeds RINGING_KE_SHARE raises RingingError
    (exit 3)."""
    drive_power = S["worm_power_w"] if duty.drive.on == "worm" else S["wheel_power_w"]
    share = measured_ke_share(S, inertias_kg_m2, duty.ramps_end_s, drive_power)
    out = {
        "mass_scaling": c.factor,
        "kinetic_energy_share": share,
        "kinetic_energy_share_estimate": c.ke_share_estimate,
        "mass_scaling_mesh_mode_hz": c.mode_hz,
        "mass_scaling_requested": requested,
    }
    if c.factor > 1:
        eff = summary.get("efficiency", float("nan"))
        why = []
        if eff > 1:
            why.append(f"efficiency {eff:.3g} > 1 (more power out than in)")
        if not share <= RINGING_KE_SHARE:
            why.append(
                f"kinetic energy {100 * share:.3g} % of the drive's work (target {100 * KE_SHARE_TARGET:g} %, "
                f"limit {100 * RINGING_KE_SHARE:g} %)"
            )
        if why:
            h, lim = summary["timestep_s"], summary["timestep_stable_limit_s"]
            raise RingingError(
                f"the mass-scaled run rang (simulation.mass_scaling = {c.factor:g}, timestep {h:.3g} s, {h / lim:.2f} "
                f"of the scaled stable limit {lim:.3g} s): {'; '.join(why)}; its means are not quasi-static. Leave "
                f"simulation.timestep_s unset (default {SCALED_STEP_FRACTION} x the limit) or lower "
                f"simulation.mass_scaling"
            )
    return out


def note(c: ScalingCheck, requested, timestep_s: float) -> str:
    """The line a scaled run prints before it starts."""
    if c.factor == 1:
        lim = min(c.factor_limits.values()) if c.factor_limits else float("nan")
        return (
            f"mass scaling: {requested} -> 1 (off): the run is dynamic (the checks allow at most {lim:.3g}); "
            f"docs/contact3d.md, 'Mass scaling'"
        )
    return (
        f"mass scaling: inertias x {c.factor:g} ({requested}), timestep {timestep_s:.3g} s, mesh mode "
        f"{c.mode_hz:.3g} Hz, kinetic energy ~{100 * c.ke_share_estimate:.2g} % of the work: quasi-static means "
        f"only (ratio, mean forces, efficiency); F_t p2p, transmission error, rattle and start-up peaks are not "
        f"physical"
    )
