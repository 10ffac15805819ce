"""Derived dimensions of a cylindrical worm gear pair (90 deg shaft angle), SI units.

Sources: DIN 3975-1 / ISO 1122-1 for the names and the basic relations; seed 003
(`../shared/seeds/003_a94382a6f782276d.txt`) for the involute helicoid parameters r_b and p.

Relations (m_x axial module, m_n normal module, z1 starts, z2 wheel teeth, gamma lead angle at d1):

    m_n   = m_x cos(gamma)
    q     = d1 / m_x = z1 / tan(gamma)                  (diameter quotient)
    d1    = q m_x,  d2 = z2 m_x,  a = (d1 + d2) / 2     (reference diameters, centre distance)
    p_x   = pi m_x (axial pitch),  p_z = z1 p_x (lead),  p = p_z / (2 pi) = r1 tan(gamma)   (helix parameter, seed 003)
    tan(alpha_x) = tan(alpha_n) / cos(gamma)            (axial pressure angle at d1)
    cos(gamma_b) = cos(gamma) cos(alpha_n),  r_b = p / tan(gamma_b)   (ZI base cylinder, seed 003)
    h_a = addendum_coef m_x,  h_f = dedendum_coef m_x,  c = h_f - h_a  (tip clearance)
    r_a1 = r1 + h_a, r_f1 = r1 - h_f (worm tip/root); r_a2 = r2 + h_a, r_f2 = r2 - h_f (wheel throat tip/root)
    wheel tip surface: torus about the worm axis, tube radius a - r_a2 = r1 - h_a (the "throat")
    wheel root surface: torus about the worm axis, tube radius a - r_f2 = r1 + h_f
    r_e2 = r_a2 + m_x / 2  (outside radius of the wheel rim; DIN 3975 guide d_e2 <= d_a2 + 2 m for z1 = 1)
    b2 = 0.75 d_a1 (z1 <= 3), 0.67 d_a1 (z1 >= 4)  (default face width, DIN 3975 guide), at most 1.2 d_a1;
    q <= 40 (so also for a given lead angle); p_x <= b1 <= 4 x the default b1 (threaded length, meshgen cost);
    b2 <= 2 sqrt((a - r_f2)^2 - (a - r_e2 + 0.1 (h_a + h_f))^2)  (tooth depth left at the face edges, meshgen;
          the default is clipped to it, a given face width beyond it is an input error)
    wheel tooth thickness on d2: s2 = p_x / 2 - j_t   (backlash j_t taken from the wheel, symmetric)
    ratio i = z2 / z1,  meshing frequency f_m = z1 n1 / 60

Hand: right-hand worms have p > 0; a left-hand worm is the mirror image (p -> -p, seed 003).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass
from typing import Literal, Protocol

from meshgen import worm_forms
from meshgen.errors import GeometryError
from meshgen.worm_forms import DEFAULT_PROFILE_RADIUS_MODULES, DEFAULT_TOOL_DIAMETER_MM

# meshgen reads gear data in the units of its field names (mm, deg) and works in SI: these are its conversions
# (the simulator's are in wormsim.units; meshgen imports nothing from wormsim)
MM = 1e-3  # m per mm
DEG = math.pi / 180.0  # rad per deg


class GearData(Protocol):
    """What derive() reads (read-only): the fields of a scenario's `gear:` block (wormsim.scenario.Gear has them,
    validated), or a GearSpec."""

    @property
    def profile(self) -> str: ...
    @property
    def hand(self) -> str: ...
    @property
    def worm_starts(self) -> int: ...
    @property
    def wheel_teeth(self) -> int: ...
    @property
    def normal_module_mm(self) -> float | None: ...
    @property
    def axial_module_mm(self) -> float | None: ...
    @property
    def normal_pressure_angle_deg(self) -> float: ...
    @property
    def lead_angle_deg(self) -> float | None: ...
    @property
    def diameter_quotient(self) -> float | None: ...
    @property
    def face_width_mm(self) -> float | None: ...
    @property
    def worm_length_mm(self) -> float | None: ...
    @property
    def backlash_mm(self) -> float: ...
    @property
    def addendum_coef(self) -> float: ...
    @property
    def dedendum_coef(self) -> float: ...


@dataclass(frozen=True)
class GearSpec:
    """Plain gear data for using meshgen on its own (the defaults of a scenario's `gear:` block). Give exactly one
    of normal_module_mm / axial_module_mm and one of lead_angle_deg / diameter_quotient."""

    wheel_teeth: int
    normal_module_mm: float | None = None
    axial_module_mm: float | None = None
    lead_angle_deg: float | None = None
    diameter_quotient: float | None = None
    profile: Literal["ZA", "ZN", "ZI", "ZK", "ZC"] = "ZI"
    hand: Literal["right", "left"] = "right"
    worm_starts: int = 1
    normal_pressure_angle_deg: float = 20.0
    face_width_mm: float | None = None
    worm_length_mm: float | None = None
    backlash_mm: float = 0.05
    addendum_coef: float = 1.0
    dedendum_coef: float = 1.2
    zn_section: Literal["thread", "space"] = "thread"
    tool_diameter_mm: float | None = None
    profile_radius_mm: float | None = None


@dataclass(frozen=True)
class GearGeometry:
    profile: str  # "ZA" | "ZN" | "ZI" | "ZK" | "ZC" (meshgen.worm, meshgen.worm_forms)
    hand: int  # +1 right, -1 left
    z1: int
    z2: int
    m_x: float  # axial module, m
    m_n: float  # normal module, m
    gamma: float  # lead angle at d1, rad
    alpha_n: float  # normal pressure angle, rad
    alpha_x: float  # axial pressure angle, rad
    q: float  # diameter quotient
    d1: float
    d2: float
    a: float  # centre distance, m
    p_x: float  # axial pitch, m
    lead: float  # p_z, m
    p: float  # helix parameter lead / 2 pi (signed by hand), m/rad
    gamma_b: float  # base lead angle (ZI), rad
    r_b: float  # base radius (ZI), m
    h_a: float
    h_f: float
    r_a1: float
    r_f1: float
    r_a2: float
    r_f2: float
    r_e2: float  # wheel outside (rim) radius
    throat_radius: float  # tube radius of the wheel tip torus, a - r_a2
    root_torus_radius: float  # tube radius of the wheel root torus, a - r_f2
    face_width: float  # b2, m
    worm_length: float  # b1, m
    backlash: float  # circumferential at d2, m
    wheel_tooth_thickness: float  # s2 on d2 (arc), m
    ratio: float  # z2 / z1
    zn_section: str = "thread"  # ZN: "thread" (ZN1) | "space" (ZN2)
    tool_diameter: float = 0.1  # ZK, ZC: disc diameter at the pitch point, m
    profile_radius: float = 0.0  # ZC: the disc's arc profile radius, m

    @property
    def r1(self) -> float:
        return self.d1 / 2

    @property
    def r2(self) -> float:
        return self.d2 / 2

    def mesh_frequency_hz(self, worm_speed_rpm: float) -> float:
        """f_m = z1 n1 / 60 (seed 001)."""
        return self.z1 * abs(worm_speed_rpm) / 60.0

    def as_dict_mm_deg(self) -> dict:
        """For printing: lengths in mm, angles in deg, names carrying the unit."""
        out = {}
        angles = {"gamma", "alpha_n", "alpha_x", "gamma_b"}
        plain = {"profile", "hand", "z1", "z2", "q", "ratio", "zn_section"}
        for k, v in asdict(self).items():
            if k in plain:
                out[k] = v
            elif k in angles:
                out[f"{k}_deg"] = v / DEG
            elif k == "p":
                out["p_mm_per_rad"] = v / MM
            else:
                out[f"{k}_mm"] = v / MM
        return out


Q_MAX = 40.0  # largest diameter quotient (the schema's bound on gear.diameter_quotient)
WORM_LENGTH_MAX = 4.0  # threaded length at most 4 x the mesh zone (the default length)


def derive(gear: GearData) -> GearGeometry:
    """All derived quantities from gear data (a validated `gear:` block or a GearSpec). Raises GeometryError on
    impossible data."""
    z1, z2 = gear.worm_starts, gear.wheel_teeth
    alpha_n = gear.normal_pressure_angle_deg * DEG
    if gear.lead_angle_deg is not None:
        gamma = gear.lead_angle_deg * DEG
        q = z1 / math.tan(gamma)
        if q > Q_MAX:  # a tiny lead angle is a huge worm: 1e-9 deg gave d1 = 4e10 mm
            raise GeometryError(
                f"gear.lead_angle_deg = {gear.lead_angle_deg:.4g}: gives diameter quotient q = z1 / tan(gamma) = "
                f"{q:.4g}; allowed: q <= {Q_MAX:g}, i.e. lead_angle_deg >= {math.atan(z1 / Q_MAX) / DEG:.4g} "
                f"for {z1} start(s)"
            )
    else:
        q = gear.diameter_quotient
        gamma = math.atan(z1 / q)
        if not (0 < gamma < 45 * DEG):
            raise GeometryError(
                f"gear.diameter_quotient = {q}: gives lead angle {gamma / DEG:.2f} deg; allowed (0, 45) deg"
            )
    if gear.axial_module_mm is not None:
        m_x = gear.axial_module_mm * MM
    else:
        m_x = gear.normal_module_mm * MM / math.cos(gamma)
    m_n = m_x * math.cos(gamma)
    d1, d2 = q * m_x, z2 * m_x
    r1, r2 = d1 / 2, d2 / 2
    a = r1 + r2
    p_x = math.pi * m_x
    lead = z1 * p_x
    hand = 1 if gear.hand == "right" else -1
    p = hand * lead / (2 * math.pi)
    alpha_x = math.atan(math.tan(alpha_n) / math.cos(gamma))
    gamma_b = math.acos(math.cos(gamma) * math.cos(alpha_n))
    r_b = abs(p) / math.tan(gamma_b)
    h_a, h_f = gear.addendum_coef * m_x, gear.dedendum_coef * m_x
    r_a1, r_f1 = r1 + h_a, r1 - h_f
    r_a2, r_f2 = r2 + h_a, r2 - h_f
    if r_f1 <= 0.2 * r1:
        q_min = 2.5 * gear.dedendum_coef
        given = (
            f"gear.diameter_quotient = {q:g}: allowed diameter_quotient >= {q_min:.1f}"
            if gear.lead_angle_deg is None
            else f"gear.lead_angle_deg = {gear.lead_angle_deg:g} (q = z1 / tan(gamma) = {q:.2f}): allowed "
            f"lead_angle_deg <= {math.atan(z1 / q_min) / DEG:.3g} for {z1} start(s)"
        )
        raise GeometryError(
            f"{given} (the worm root radius {r_f1 / MM:.3f} mm is too small for the reference radius {r1 / MM:.3f} mm "
            f"with dedendum_coef {gear.dedendum_coef:g})"
        )
    r_e2 = r_a2 + 0.5 * m_x
    b2 = gear.face_width_mm * MM if gear.face_width_mm is not None else (0.75 if z1 <= 3 else 0.67) * 2 * r_a1
    if b2 >= 2 * (a - r_f1) * 0.999 or b2 > 2 * r_a1 * 1.2:
        given = (
            f"gear.face_width_mm = {b2 / MM:.3f}"
            if gear.face_width_mm is not None
            else f"gear.face_width_mm not given: its default {b2 / MM:.3f} mm ({0.75 if z1 <= 3 else 0.67:g} x worm "
            "tip diameter, DIN 3975 guide)"
        )
        raise GeometryError(
            f"{given}: too wide for this worm; allowed up to "
            f"{min(1.2 * 2 * r_a1, 2 * (a - r_f1) * 0.999) / MM:.3f} mm (1.2 x worm tip diameter, and within the "
            f"wheel's root)"
        )
    # the wheel root torus (tube radius a - r_f2) rises towards the face edges; the tooth must keep at least
    # 0.1 of its full depth h_a + h_f under the rim radius r_e2 at zeta = +-b2/2
    R_root, edge = a - r_f2, a - r_e2 + 0.1 * (h_a + h_f)
    b2_max = 2 * math.sqrt(max(R_root**2 - edge**2, 0.0))
    if gear.face_width_mm is None:
        b2 = min(b2, b2_max)  # the DIN guide default, clipped where the root torus would eat the edges
    if b2 > b2_max:
        raise GeometryError(
            f"gear.face_width_mm = {b2 / MM:.3f}: the wheel root torus leaves no tooth at the face edges; "
            f"allowed up to {b2_max / MM:.3f} mm"
        )
    # threaded length: cover every point of the wheel rim that can reach the worm tip cylinder, plus one pitch
    reach = r_e2**2 - (a - r_a1) ** 2
    b1_mesh = 2 * math.sqrt(max(reach, 0.0)) + p_x
    b1 = gear.worm_length_mm * MM if gear.worm_length_mm is not None else b1_mesh
    if not p_x <= b1 <= WORM_LENGTH_MAX * b1_mesh:  # 1e6 mm ran for > 10 min at 5 GB (pieces along the thread)
        raise GeometryError(
            f"gear.worm_length_mm = {b1 / MM:.4g}: allowed {p_x / MM:.4g} (one axial pitch) to "
            f"{WORM_LENGTH_MAX * b1_mesh / MM:.4g} mm ({WORM_LENGTH_MAX:g} x the mesh zone {b1_mesh / MM:.4g} mm)"
        )
    s2 = p_x / 2 - gear.backlash_mm * MM
    if s2 <= 0.1 * p_x:
        raise GeometryError(
            f"gear.backlash_mm = {gear.backlash_mm}: leaves a wheel tooth of {s2 / MM:.3f} mm on d2; "
            f"allowed below {0.4 * p_x / MM:.3f} mm (0.4 axial pitch)"
        )
    # flank form settings (meshgen.worm_forms; defaults documented in docs/flank_forms.md)
    tool_d = getattr(gear, "tool_diameter_mm", None)
    rho_c = getattr(gear, "profile_radius_mm", None)
    g = GearGeometry(
        zn_section=getattr(gear, "zn_section", "thread"),
        tool_diameter=(DEFAULT_TOOL_DIAMETER_MM if tool_d is None else tool_d) * MM,
        profile_radius=rho_c * MM if rho_c is not None else DEFAULT_PROFILE_RADIUS_MODULES * m_x,
        profile=gear.profile,
        hand=hand,
        z1=z1,
        z2=z2,
        m_x=m_x,
        m_n=m_n,
        gamma=gamma,
        alpha_n=alpha_n,
        alpha_x=alpha_x,
        q=q,
        d1=d1,
        d2=d2,
        a=a,
        p_x=p_x,
        lead=lead,
        p=p,
        gamma_b=gamma_b,
        r_b=r_b,
        h_a=h_a,
        h_f=h_f,
        r_a1=r_a1,
        r_f1=r_f1,
        r_a2=r_a2,
        r_f2=r_f2,
        r_e2=r_e2,
        throat_radius=a - r_a2,
        root_torus_radius=a - r_f2,
        face_width=b2,
        worm_length=b1,
        backlash=gear.backlash_mm * MM,
        wheel_tooth_thickness=s2,
        ratio=z2 / z1,
    )
    if g.profile in worm_forms.TABLE_FORMS:
        worm_forms.form_table(g)  # GeometryError here where the tool cannot generate the flank
    return g
