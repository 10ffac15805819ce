"""Tooth-contact law of contact3d: the scenario's `contact:` block (ADAMS IMPACT K, e, C, d and friction)
mapped onto MuJoCo's soft contact constraints (solref / solimp), and the friction coefficient mu(Vs).

MuJoCo (modeling.rst "Solver parameters", computation "Soft constraints") computes a contact's normal
force from the constraint-space dynamics  a1 + d (b v + k r) = (1 - d) a0  with impedance d
(solimp), reference stiffness k and damping b (solref). In the direct (negative) solref format
(-S, -B) with constant impedance d = solimp[0] = solimp[1]:  d k = S, d b = B.  The regulariser is
R = (1 - d) / d * A_hat, where A_hat is MuJoCo's approximate constraint-space inverse mass of the row
(for a contact: body_invweight0[worm, 0] + body_invweight0[wheel, 0]). At static equilibrium
(qacc = 0) the primal optimality of the constraint solve gives, per row,

    f = R^-1 a_ref = -(k / R) r = -S / ((1 - d) A_hat) * r        (a linear spring, exactly)

and in motion f = -S/((1-d) A_hat) r - B/((1-d) A_hat) v - R^-1 a1: the same spring and damper plus
an added mass 1/R = d / ((1 - d) A_hat) in the contact normal, which is small for small d. So we set
A_hat ourselves (model.body_invweight0, see wormsim.contact3d.mjcf) and choose

    S = k_c (1 - d) A_hat,    B = c_c (1 - d) A_hat                                     (1)

for a wanted linear stiffness k_c (N/m) and damping c_c (N s/m) per MuJoCo contact.

ADAMS IMPACT is F = K delta^e + STEP(delta, 0, 0, d_max, C) delta_dot. MuJoCo's contact is linear in
the penetration, so the exponent e cannot be represented. We read `contact.stiffness_n_per_m` as
the linear (secant) stiffness of one tooth pair at its working load, in N/m as the key says: that is
what seed 001 derives it as (K = pi L E* / 4, Hertz line contact, N/mm), and reading seed 001's
K = 1.47e7 with e = 1.5 in SI as N/m^1.5 would give a 2 mm penetration at the 1.3 kN tooth load of a
0.7 mm module gear. The exponent is reported, not used. Damping C is the full (delta >= d_max)
value; it is capped at 10 % of critical damping of one tooth pair against the mesh's effective mass
(MAX_DAMPING_RATIO; measured gear-mesh damping ratios are 0.03-0.17). ADAMS's C of seeds 001/002
is ~100x over-critical for these masses (it acts there only through the STEP over d); as a
constant damper it would need timesteps below 1e-7 s, and at critical damping every facet impact
of the convex pieces dissipates energy: the seat motor's efficiency measured 0.546 at zeta = 1
(0.877 frictionless) against 0.606 at zeta = 0.1 (theory 0.620). The cap is reported as
`contact_damping_used_n_s_per_m` and `contact_damping_ratio`.

A tooth pair touches along a line; the convex collision pieces turn it into several point contacts
(one per worm-piece/wheel-piece pair). Each MuJoCo contact gets k_c = K / n_ref, with n_ref the
number of wheel-tooth pieces across the face width per flank (`contacts_per_pair`), so a pair whose
line contact spans the face carries K.

K is k' b2 with k' the per-length stiffness of wormsim.tooth.stiffness.per_length_stiffness, the one place
every level takes it from: the scenario's K (an override of the teeth's stiffness, as the seeds' ADAMS penalty
constants ran: docs/decisions/0034-contact-stiffness-override.md), else the teeth's own compliance (bending, shear,
rim and contact flattening, wormsim.tooth.compliance: a tooth pair in MuJoCo is as stiff as the loaded TCA says), or
with contact.stiffness_model hertz the Hertz line contact of seed 001, K = pi L E* / 4 with L = b2 and
1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2. Default damping: 10 % of critical.

Friction: MuJoCo has one Coulomb coefficient per contact (elliptic cone). We set it every few steps
from the sliding speed Vs = omega1 r1 / cos(gamma) (seed 000):
  friction: mu                           constant
  friction_static/_dynamic: mu(Vs) = STEP(|Vs|, 0, mu_s, v_t, mu_d)   (ADAMS-style cubic blend over
                                          the transition velocity v_t = contact.transition_velocity_m_s)
  friction_group: mu(Vs) = tan(rho(Vs)), rho of seed 000 (wormsim.physics.friction)
  none given: mu = 0.05 (lubricated steel/bronze, DEFAULT_FRICTION).
Where the wheel drives a pair that self-locks at rest, mu keeps its static value mu(0) until the friction the pair
needs reaches its static limit (the stick state, wormsim.physics.friction.stuck_after, wormsim.contact3d.breakaway;
docs/decisions/0039-static-holding.md, 0058-breakaway-on-static-friction.md).

Friction hardness (opt.impratio). MuJoCo's elliptic friction rows have no position term: their reference
acceleration is a_ref = -b v_t (b = B / d, the normal row's damping) and their regulariser is
R_f = R / impratio. Below the cone the solver's force is f_t = -R_f^-1 (J qacc - a_ref); where the slip is
imposed by the mechanism (the worm turned by its servo slides along the flank), J qacc ~ 0 and

    f_t = b v_t / R_f = impratio B / ((1 - d) A_hat) v_t = impratio c_c v_t,                      (2)

a viscous friction, saturating at Coulomb's mu f_n only above v_reg = mu f_n / (impratio c_c). Measured with
impratio 1: f_t / v_t = 12.16 N s/m = c_c on every unsaturated seat-motor contact; with f_n ~ 33 N per
contact v_reg ~ 0.13 m/s, so at seed 001's 36 rpm (Vs 0.016 m/s) friction reached 12-19 % of mu f_n and the
efficiency came out 0.92 against 0.62 (docs/contact3d.md, "Friction at low sliding speed"). We choose

    impratio = max(1, mu_max F_n / (c_c v_t))                                                    (3)

with F_n the whole mesh's nominal normal force at the working load (DIN 3975: T2 / (r2 cos(alpha_n)
cos(gamma))), mu_max = max(mu(0), mu(1 m/s)) and v_t = contact.transition_velocity_m_s: even a contact
carrying the whole load saturates once it slips faster than the static -> dynamic transition velocity (the
stiction range of ADAMS's friction), so friction is Coulomb's wherever mu(Vs) is dynamic. Only the friction rows
change: the normal rows and the stiffness mapping (1) are untouched.

Friction-row damping of the flank contacts (friction-driven rattle; MuJoCo 4.0.0 engine_core_constraint.c,
mj_makeImpedance and the elliptic cone's middle zone). On the cone (sliding) the solver's forces are
f_n = D_n / (1 + mu_r^2) (-jar_n + mu |jar_t|) and |f_t| = mu f_n, with jar = J qacc - a_ref, D_n = 1 / R,
mu_r = mu / sqrt(impratio). The friction rows' a_ref = -b_f v_t enters the normal force: at an imposed slip
(J qacc_t ~ 0) a sliding contact gains f_n,slip = mu c_f |v_t| / (1 + mu_r^2), c_f = B_f / ((1 - d) A_hat),
whatever its depth: a damper-like push that lifts a fast-sliding contact off its flank (docs/contact3d.md,
"Friction-driven rattle"). With solreffriction = solref (MuJoCo's default) c_f = c_c. The flank contacts set
their own solreffriction (-S, -B_f) with

    c_f = min(c_c, EPS_SLIP mu_max^-1 F_n / (n_ref Vs))                                                   (4)

so that f_n,slip stays below EPS_SLIP of a contact's share F_n / n_ref of the nominal normal force at the nominal
sliding speed Vs = omega1 r1 / cos(gamma); impratio (3) is then taken with c_f, so friction still saturates above
the transition velocity.

Added mass of the flank contacts. The rows of a mesh act in parallel, so their added masses 1/R sum over the rows in
contact: with d per row, S slices put about S d/(1-d) m_eff per tooth pair in contact on the mesh's effective mass,
and the contact mode sqrt(K_mesh / m_eff) fell with the count (involute_41: 772 / 652 Hz at 24 / 48 slices against
930 Hz from the zero-load TCA's mean k; docs/contact3d.md "Default slice count"). The flank contacts take

    d_row = IMPEDANCE / S  (at least MIN_IMPEDANCE),   impratio' = impratio d0 (1 - d_row) / (d_row (1 - d0)),
    c_f' = c_f impratio / impratio'   (d0 = IMPEDANCE)                                                        (5)

so that a tooth pair's rows together carry the added mass IMPEDANCE / (1 - IMPEDANCE) m_eff whatever the count
(involute_41: 941 Hz at 24 and at 48 slices), the spring and damper (1) are unchanged (S and B are taken with
d_row), and the friction rows are those of d0: their regulariser R_f = R / impratio and the viscous friction
impratio c_f (2) are both kept (keep_friction_rows), so the stick and slip of static holding (docs/decisions/
0039-static-holding.md) are unchanged. Pieces keep d = IMPEDANCE per row.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from meshgen.geometry import GearGeometry
from wormsim.physics.gear_theory import DEFAULT_DAMPING_RATIO, MAX_DAMPING_RATIO
from wormsim.scenario import Contact, Materials
from wormsim.tooth.stiffness import hertz_per_length_n_per_m2, pair_stiffness_n_per_m

STABLE_LIMIT_PAIRS = 3  # tooth pairs in contact at once that the stable limit allows for
EPS_SLIP = 0.01  # (4): the sliding contact's spurious normal force, share of its static load
IMPEDANCE = 0.01  # d: added mass in the contact normal d/(1-d) = 1 % of the mesh's effective mass per row (pieces)
# or per tooth pair (flanks: each of its S rows d / S, (5))
MIN_IMPEDANCE = 1e-4  # MuJoCo's mjMINIMP: the smallest impedance its solver takes


@dataclass(frozen=True)
class ContactLaw:
    """Numbers of the mapping (1); SI units."""

    pair_stiffness_n_per_m: float  # K, one tooth pair (linear, secant)
    stiffness_source: str  # "teeth" | "scenario" | "hertz" (wormsim.tooth.stiffness.STIFFNESS_SOURCES)
    exponent: float  # ADAMS e (reported, not representable)
    contacts_per_pair: int  # n_ref
    contact_stiffness_n_per_m: float  # k_c = K / n_ref
    contact_damping_requested_n_s_per_m: float
    contact_damping_n_s_per_m: float  # c_c used (capped at critical)
    effective_mass_kg: float  # 1 / A_hat: mesh effective mass at a contact's normal
    inv_mass_hat: float  # A_hat (1/kg)
    impedance: float  # d
    solref: tuple[float, float]  # (-S, -B)
    solimp: tuple[float, float, float, float, float]
    impratio: float = 1.0  # MuJoCo opt.impratio: R_normal / R_friction, (3)
    friction_damping_n_s_per_m: float | None = None  # c_f of the friction rows, (4); None: c_c (solref)

    @property
    def friction_damping(self) -> float:
        """c_f: the friction rows' damping per contact (c_c where the contacts use solref for them)."""
        c = self.friction_damping_n_s_per_m
        return self.contact_damping_n_s_per_m if c is None else c

    @property
    def solreffriction(self) -> tuple[float, float]:
        """MuJoCo's per-contact solreffriction, direct (-S, -B_f) with B_f = c_f (1 - d) A_hat; (0, 0) = solref."""
        if self.friction_damping_n_s_per_m is None:
            return (0.0, 0.0)
        return (self.solref[0], -self.friction_damping_n_s_per_m * (1 - self.impedance) * self.inv_mass_hat)

    def natural_frequency_rad_s(self, contacts: int) -> float:
        """omega = sqrt(n k_c A_hat): mesh mode with `contacts` contacts in parallel."""
        return math.sqrt(contacts * self.contact_stiffness_n_per_m * self.inv_mass_hat)

    def stable_timestep_s(self, contacts: int) -> float:
        """Explicit (semi-implicit Euler) limit of the spring-damper in the contact normal:
        h < 2 / omega * (sqrt(1 + zeta^2) - zeta), zeta = c / (2 sqrt(k m)) (per contact, in parallel)."""
        w = self.natural_frequency_rad_s(contacts)
        zeta = self.damping_ratio * math.sqrt(contacts / self.contacts_per_pair)
        return 2.0 / w * (math.sqrt(1 + zeta * zeta) - zeta)

    @property
    def stable_limit_s(self) -> float:
        """The stable limit contact3d works to: stable_timestep_s with STABLE_LIMIT_PAIRS tooth pairs' contacts in
        parallel (the timestep default, the divergence diagnosis and the bench's stability map use it)."""
        return self.stable_timestep_s(STABLE_LIMIT_PAIRS * self.contacts_per_pair)

    @property
    def damping_ratio(self) -> float:
        """zeta of one tooth pair (n_ref contacts) against the mesh's effective mass."""
        return (
            self.contact_damping_n_s_per_m
            * self.contacts_per_pair
            / (2 * math.sqrt(self.pair_stiffness_n_per_m * self.effective_mass_kg))
        )


def hertz_line_stiffness_n_per_m(materials: Materials, contact_length_m: float) -> float:
    """K = pi L E* / 4 (seed 001, Hertz line contact of two cylinders): hertz_per_length_n_per_m2 times L."""
    return contact_length_m * hertz_per_length_n_per_m2(materials)


def contact_law(
    contact: Contact,
    materials: Materials,
    g: GearGeometry,
    contacts_per_pair: int,
    inv_mass_hat: float,
    impedance: float | None = None,
) -> ContactLaw:
    """Map the scenario's contact block onto per-contact solref/solimp by (1); K from
    wormsim.tooth.stiffness.pair_stiffness_n_per_m (module docstring).

    `inv_mass_hat` is A_hat = 1 / m_eff, the constraint-space inverse mass the model assigns to every
    worm-wheel contact (wormsim.contact3d.mjcf sets body_invweight0 so that it holds).
    """
    k_pair, source = pair_stiffness_n_per_m(contact, g, materials)
    n_ref = max(int(contacts_per_pair), 1)
    k_c = k_pair / n_ref
    m_eff = 1.0 / inv_mass_hat
    c_crit = 2.0 * math.sqrt(k_pair * m_eff) / n_ref  # per contact: critical damping of one pair
    if contact.damping_n_s_per_m is not None:
        c_req = contact.damping_n_s_per_m / n_ref
    else:
        c_req = DEFAULT_DAMPING_RATIO * c_crit
    c_c = min(c_req, MAX_DAMPING_RATIO * c_crit)
    d = IMPEDANCE if impedance is None else max(impedance, MIN_IMPEDANCE)
    s = k_c * (1 - d) * inv_mass_hat
    b = c_c * (1 - d) * inv_mass_hat
    return ContactLaw(
        pair_stiffness_n_per_m=k_pair,
        stiffness_source=source,
        exponent=contact.exponent,
        contacts_per_pair=n_ref,
        contact_stiffness_n_per_m=k_c,
        contact_damping_requested_n_s_per_m=c_req,
        contact_damping_n_s_per_m=c_c,
        effective_mass_kg=m_eff,
        inv_mass_hat=inv_mass_hat,
        impedance=d,
        solref=(-s, -b),
        solimp=(d, d, 0.001, 0.5, 2.0),
    )


def flank_impedance(contacts_per_pair: int) -> float:
    """(5): each flank contact row's impedance, IMPEDANCE / S (at least MIN_IMPEDANCE)."""
    return max(IMPEDANCE / max(int(contacts_per_pair), 1), MIN_IMPEDANCE)


def keep_friction_rows(law: ContactLaw, reference_impedance: float | None = None) -> ContactLaw:
    """(5): the friction rows of `law` made those of the same law at impedance d0 = reference_impedance: R_f =
    R / impratio and the viscous friction impratio c_f (2) both kept, by impratio' = impratio d0 (1 - d) / (d (1 - d0))
    and c_f' = c_f impratio / impratio' (d0 None: IMPEDANCE)."""
    d, d0 = law.impedance, IMPEDANCE if reference_impedance is None else reference_impedance
    imp = law.impratio * d0 * (1 - d) / (d * (1 - d0))
    return replace(law, impratio=imp, friction_damping_n_s_per_m=law.friction_damping * law.impratio / imp)


def friction_damping_n_s_per_m(
    law: ContactLaw, mu_max: float, normal_force_n: float, sliding_speed_m_s: float, eps: float | None = None
) -> float:
    """(4): c_f = min(c_c, eps F_n / (n_ref mu_max Vs)), eps = EPS_SLIP; c_c where there is no friction, load or
    sliding speed."""
    eps = EPS_SLIP if eps is None else eps
    c_c = law.contact_damping_n_s_per_m
    if mu_max <= 0 or normal_force_n <= 0 or sliding_speed_m_s <= 0:
        return c_c
    return min(c_c, eps * normal_force_n / (law.contacts_per_pair * mu_max * sliding_speed_m_s))


def friction_impratio(law: ContactLaw, mu_max: float, normal_force_n: float, transition_velocity_m_s: float) -> float:
    """(3): impratio = max(1, mu_max F_n / (c_f v_t)), so that by (2) a contact carrying F_n is on the
    friction cone for slip above v_t (c_f = c_c unless the law sets the friction rows' damping, (4))."""
    if mu_max <= 0 or normal_force_n <= 0 or law.friction_damping <= 0:
        return 1.0
    return max(1.0, mu_max * normal_force_n / (law.friction_damping * transition_velocity_m_s))


def friction_regularisation_velocity_m_s(law: ContactLaw, mu: float, normal_force_n: float) -> float:
    """v_reg = mu f_n / (impratio c_f): slip speed above which a contact carrying f_n is on the cone, by (2)."""
    return mu * normal_force_n / (law.impratio * law.friction_damping)


def friction_utilisation(model, data) -> np.ndarray:
    """Per active contact (rows of an (n, 4) array): normal force f_n (N), friction force |f_t| (N), the
    contact's mu, slip speed |v_t| (m/s). Elliptic cones: efc_force rows of a contact are (normal, tangent 1,
    tangent 2) in the contact frame (what mj_contactForce returns) and efc_vel = J qvel the relative velocity
    in the same rows. Utilisation = |f_t| / (mu f_n), 1 on the cone (sliding, Coulomb)."""
    n = data.ncon
    if n == 0:
        return np.zeros((0, 4))
    con = data.contact
    adr = np.asarray(con.efc_address[:n])
    mu = np.asarray(con.friction[:n, 0])
    ok = adr >= 0
    adr, mu = adr[ok], mu[ok]
    f, v = data.efc_force, data.efc_vel
    return np.stack([f[adr], np.hypot(f[adr + 1], f[adr + 2]), mu, np.hypot(v[adr + 1], v[adr + 2])], axis=1)
