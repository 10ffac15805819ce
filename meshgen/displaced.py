"""Geometry of a displaced worm gear pair: assembly errors and manufacturing deviations, SI units.

The nominal frames are meshgen.assembly's (assembly frame: wheel axis z through the origin, worm axis parallel to x
at y = -a, z = 0). The errors enter as rigid transforms of each part's BODY (the frame its surfaces are written in:
meshgen.worm, meshgen.wheel) into the assembly:

    worm body  -> assembly:  Trans(0, -(a + da), 0) R0 Trans(0, 0, dw) Rz(dw / p) Rz(theta1) Trans(e1, 0, 0) (1)
    wheel body -> assembly:  Trans(0, 0, dz) Ry(dS) Rz(theta2) Trans(e2 cos(ph2), e2 sin(ph2), 0)          (2)

with R0 of meshgen.assembly and
    da  errors.center_distance_mm         the worm axis moved away from the wheel axis (a larger a is positive);
    dS  errors.shaft_angle_deg            the wheel axis turned about the line of centres (assembly +y, from the worm
                                          axis to the wheel centre); the worm's +z axis and the wheel's +z axis then
                                          make Sigma = 90 deg + dS;
    dz  errors.wheel_axial_offset_mm      the wheel mid-plane moved along the wheel axis (+z);
    dw  errors.worm_axial_offset_mm       the worm moved along its own axis (worm +z = assembly -x): a phase only,
                                          since the helicoid z = p phi + const is invariant under the screw motion
                                          Trans(0, 0, p t) Rz(t); the turn Rz(dw / p) in (1) takes the phase out, so
                                          theta1 = 0 still puts a thread centred in a tooth space (the angle counts
                                          from the thread), and what remains is where the threaded length ends;
    e1  errors.worm_runout_mm             the thread's axis off the worm's axis of rotation, towards worm +x (which
                                          points at the wheel centre at theta1 = 0);
    e2, ph2  errors.wheel_runout_mm/_phase_deg   the pitch circle's centre off the wheel's axis of rotation, at
                                          wheel-frame polar angle ph2;
    f_k errors.wheel_pitch_deviation_um   wheel tooth k shifted along the reference circle by f_k (angle f_k / r2,
                                          positive in the wheel's positive sense): its single pitch deviation is
                                          f_pt,k = f_k - f_(k-1) (DIN 3960 / ISO 1328-1 names).
Zero errors give exactly meshgen.assembly's transforms.

Limits (each derived in docs/errors.md; `check_limits` raises meshgen's GeometryError naming the key and the limit;
wormsim.physics.geometry turns it into ScenarioError, exit 2).
j is the circumferential backlash at d2 (j / 2 per flank), alpha_x the axial pressure angle, c = h_f - h_a the tip
clearance. In the worm's axial section through the pitch point the thread is a rack of flank angle alpha_x (ZA
exactly; ZI: the slope of its axial profile at r1 is tan(alpha_x) as well), so a radial approach dr of the worm
removes 2 dr tan(alpha_x) of the circumferential play, and a radial approach beyond c puts a tip on a root:

    closing (da < 0), runouts e1, e2 (radial swing at the mesh) and their sum:
        r_close = max(0, -da) + e1 + e2 < min(j / (2 tan(alpha_x)), c)                                      (3)
    opening: da < h_a (the worm tip must still reach the wheel's reference circle, the pitch point
        stays on the flanks; beyond it the contact leaves the design flanks and the contact ratio halves)       (4)
    shaft angle: the face edges (zeta = +-b2/2) move along the worm axis by (b2/2) sin(dS), which is
        circumferential at the pitch point: |dS| < asin(j / b2) (each flank keeps its j / 2)                   (5)
    wheel axial offset: the throat (tip torus of tube radius r1 - h_a about the worm axis) must clear the worm
        root cylinder r_f1 at the face edges: |dz| < root of min over zeta of dist(tip(zeta), worm axis) = r_f1 (6)
    worm axial offset: the threaded length must still cover the wheel's reach on the worm axis:
        |dw| < b1 / 2 - sqrt(r_e2^2 - (a - r_a1)^2)                                                         (7)
    pitch deviations: |f_k| < j / 2 (a tooth shifted by f closes one flank's j / 2 by f); at most z2 entries  (8)
Together they are a first-order budget; the kinematic tooth contact analysis (meshgen.kinematic_tca) measures the
play of the displaced flanks, and a play <= 0 anywhere over the analysed period is rejected as interference.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from meshgen import assembly, wheel
from meshgen.geometry import DEG, MM, GearGeometry, GeometryError

UM = 1e-6  # m per um


class ErrorsData(Protocol):
    """What Deviations.from_data reads (read-only): the fields of a scenario's `errors:` block
    (wormsim.scenario.Errors has them, validated), in the units of their names."""

    @property
    def center_distance_mm(self) -> float: ...
    @property
    def shaft_angle_deg(self) -> float: ...
    @property
    def wheel_axial_offset_mm(self) -> float: ...
    @property
    def worm_axial_offset_mm(self) -> float: ...
    @property
    def wheel_runout_mm(self) -> float: ...
    @property
    def wheel_runout_phase_deg(self) -> float: ...
    @property
    def worm_runout_mm(self) -> float: ...
    @property
    def wheel_pitch_deviation_um(self) -> Sequence[float]: ...


@dataclass(frozen=True)
class Deviations:
    """The errors of a scenario in SI (module docstring, symbols of (1), (2))."""

    center_distance: float = 0.0  # da, m
    shaft_angle: float = 0.0  # dS, rad
    wheel_axial_offset: float = 0.0  # dz, m
    worm_axial_offset: float = 0.0  # dw, m
    wheel_runout: float = 0.0  # e2, m
    wheel_runout_phase: float = 0.0  # ph2, rad
    worm_runout: float = 0.0  # e1, m
    tooth_shift: tuple = ()  # f_k, m, tooth 0, 1, ... (missing teeth 0)

    @classmethod
    def from_data(cls, errors: ErrorsData) -> Deviations:
        return cls(
            center_distance=errors.center_distance_mm * MM,
            shaft_angle=errors.shaft_angle_deg * DEG,
            wheel_axial_offset=errors.wheel_axial_offset_mm * MM,
            worm_axial_offset=errors.worm_axial_offset_mm * MM,
            wheel_runout=errors.wheel_runout_mm * MM,
            wheel_runout_phase=errors.wheel_runout_phase_deg * DEG,
            worm_runout=errors.worm_runout_mm * MM,
            tooth_shift=tuple(float(f) * UM for f in errors.wheel_pitch_deviation_um),
        )

    def is_zero(self) -> bool:
        return not (
            self.center_distance
            or self.shaft_angle
            or self.wheel_axial_offset
            or self.worm_axial_offset
            or self.wheel_runout
            or self.worm_runout
            or any(self.tooth_shift)
        )

    def per_wheel_revolution(self) -> bool:
        """True when an error repeats once per wheel revolution (runout, pitch deviations)."""
        return bool(self.wheel_runout or any(self.tooth_shift))

    def tooth_angle_shift(self, g: GearGeometry, k) -> np.ndarray:
        """f_k / r2 (rad) for wheel tooth indices k (any integers, taken mod z2)."""
        f = np.zeros(g.z2)
        f[: len(self.tooth_shift)] = self.tooth_shift
        return f[np.mod(np.asarray(k, dtype=int), g.z2)] / g.r2


def _trans(x: float, y: float, z: float) -> np.ndarray:
    m = np.eye(4)
    m[:3, 3] = (x, y, z)
    return m


def _ry(b: float) -> np.ndarray:
    c, s = math.cos(b), math.sin(b)
    m = np.eye(4)
    m[0, 0], m[0, 2], m[2, 0], m[2, 2] = c, s, -s, c
    return m


def worm_mount(g: GearGeometry, dev: Deviations) -> tuple[np.ndarray, np.ndarray]:
    """(M, E): worm body -> assembly = M Rz(theta1) E, (1). M places the axis of rotation, E the thread's axis on it."""
    M = _trans(0.0, -(g.a + dev.center_distance), 0.0)
    M[:3, :3] = assembly.R0
    return M @ _trans(0.0, 0.0, dev.worm_axial_offset) @ assembly._rz(dev.worm_axial_offset / g.p), _trans(
        dev.worm_runout, 0.0, 0.0
    )


def wheel_mount(g: GearGeometry, dev: Deviations) -> tuple[np.ndarray, np.ndarray]:
    """(M, E): wheel body -> assembly = M Rz(theta2) E, (2)."""
    e, ph = dev.wheel_runout, dev.wheel_runout_phase
    M = _trans(0.0, 0.0, dev.wheel_axial_offset) @ _ry(dev.shaft_angle)
    return M, _trans(e * math.cos(ph), e * math.sin(ph), 0.0)


def worm_to_assembly(g: GearGeometry, dev: Deviations, theta1: float) -> np.ndarray:
    M, E = worm_mount(g, dev)
    return M @ assembly._rz(theta1) @ E


def wheel_to_assembly(g: GearGeometry, dev: Deviations, theta2: float) -> np.ndarray:
    M, E = wheel_mount(g, dev)
    return M @ assembly._rz(theta2) @ E


# ----------------------------------------------------------------------------- limits (module docstring (3)-(8))


def limits(g: GearGeometry) -> dict:
    """The limits (3)-(8) of this gear, SI."""
    c = g.h_f - g.h_a
    # (6): distance from the worm axis of the wheel tip at wheel zeta, displaced by dz: (a - tip)^2 + (zeta + dz)^2
    zeta = np.linspace(-g.face_width / 2, g.face_width / 2, 401)
    tip = wheel.tip_rho(g, zeta)

    def clear(dz: float) -> float:
        return float(np.min(np.hypot(g.a - tip, zeta + dz))) - g.r_f1

    lo, hi = 0.0, g.face_width
    if clear(0.0) <= 0:
        hi = 0.0
    else:
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if min(clear(mid), clear(-mid)) > 0 else (lo, mid)
    reach = math.sqrt(max(g.r_e2**2 - (g.a - g.r_a1) ** 2, 0.0))
    return {
        "radial_closing_m": min(g.backlash / (2 * math.tan(g.alpha_x)), c),  # (3)
        "radial_closing_backlash_m": g.backlash / (2 * math.tan(g.alpha_x)),
        "tip_clearance_m": c,
        "center_distance_opening_m": g.h_a,  # (4)
        "shaft_angle_rad": math.asin(min(1.0, g.backlash / g.face_width)),  # (5)
        "wheel_axial_offset_m": lo,  # (6)
        "worm_axial_offset_m": max(0.0, g.worm_length / 2 - reach),  # (7)
        "tooth_shift_m": g.backlash / 2,  # (8)
    }


def check_limits(g: GearGeometry, errors: ErrorsData) -> Deviations:
    """Validate an errors: block against the gear ((3)-(8)); GeometryError naming the key and the limit. Returns
    the Deviations."""
    dev = Deviations.from_data(errors)
    if dev.is_zero():
        return dev
    lim = limits(g)

    def um(x: float) -> str:
        return f"{x / UM:.4g} um"

    def mm(x: float) -> str:
        return f"{x / MM:.4g} mm"

    if len(dev.tooth_shift) > g.z2:
        raise GeometryError(
            f"errors.wheel_pitch_deviation_um: {len(dev.tooth_shift)} entries for a wheel of "
            f"{g.z2} teeth; allowed at most {g.z2}"
        )
    if dev.center_distance >= lim["center_distance_opening_m"]:
        raise GeometryError(
            f"errors.center_distance_mm = {errors.center_distance_mm}: opens the mesh beyond the addendum h_a = "
            f"{mm(g.h_a)} (the worm tip would no longer reach the wheel's reference circle); allowed below {mm(g.h_a)}"
        )
    r_close = max(0.0, -dev.center_distance) + dev.worm_runout + dev.wheel_runout
    if r_close >= lim["radial_closing_m"]:
        which = "the backlash" if lim["radial_closing_backlash_m"] <= lim["tip_clearance_m"] else "the tip clearance"
        raise GeometryError(
            f"errors: the radial approach max(0, -center_distance_mm) + worm_runout_mm + wheel_runout_mm = "
            f"{mm(r_close)} closes the mesh into interference with {which}: allowed below "
            f"min(j / (2 tan(alpha_x)), h_f - h_a) = min({mm(lim['radial_closing_backlash_m'])}, "
            f"{mm(lim['tip_clearance_m'])}) for gear.backlash_mm = {g.backlash / MM:.4g}"
        )
    if abs(dev.shaft_angle) >= lim["shaft_angle_rad"]:
        raise GeometryError(
            f"errors.shaft_angle_deg = {errors.shaft_angle_deg}: twists the face edges by (b2 / 2) sin(dS) beyond "
            f"the flank clearance j / 2; allowed |dS| < asin(j / b2) = {lim['shaft_angle_rad'] / DEG:.4g} deg "
            f"(gear.backlash_mm = {g.backlash / MM:.4g}, face width {mm(g.face_width)})"
        )
    if abs(dev.wheel_axial_offset) >= lim["wheel_axial_offset_m"]:
        raise GeometryError(
            f"errors.wheel_axial_offset_mm = {errors.wheel_axial_offset_mm}: the wheel throat would hit the worm root "
            f"cylinder at a face edge; allowed |offset| < {mm(lim['wheel_axial_offset_m'])}"
        )
    if abs(dev.worm_axial_offset) >= lim["worm_axial_offset_m"] and dev.worm_axial_offset:
        raise GeometryError(
            f"errors.worm_axial_offset_mm = {errors.worm_axial_offset_mm}: the threaded length ({mm(g.worm_length)}) "
            f"would no longer cover the wheel's reach on the worm axis; allowed |offset| < "
            f"{mm(lim['worm_axial_offset_m'])} (or raise gear.worm_length_mm)"
        )
    if dev.tooth_shift and max(abs(f) for f in dev.tooth_shift) >= lim["tooth_shift_m"]:
        k = int(np.argmax(np.abs(dev.tooth_shift)))
        raise GeometryError(
            f"errors.wheel_pitch_deviation_um[{k}] = {errors.wheel_pitch_deviation_um[k]}: shifts the tooth beyond "
            f"its flank clearance j / 2; allowed |deviation| < {um(lim['tooth_shift_m'])} "
            f"(gear.backlash_mm = {g.backlash / MM:.4g})"
        )
    return dev
