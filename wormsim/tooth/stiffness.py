"""The tooth pair's stiffness, one home for every level: the per-length stiffness k' (N/m per m of contact line)
that the slice models use (wormsim.tooth.mesh_stiffness's TCA, torsional's k(theta1) and loaded TCA, contact3d's law
K = k' b2), its source, and the stiffness and load-sharing keys of a run.

Sources (`mesh_stiffness_source`):
    scenario  contact.stiffness_n_per_m = K given: k' = K / b2, an override of the teeth's stiffness
              (docs/decisions/0034-contact-stiffness-override.md)
    teeth     (the default, contact.stiffness_model: teeth) k'_eff of the teeth's compliance: bending, shear, rim and
              contact flattening (wormsim.tooth.compliance), chosen so that mesh_stiffness's mean k_mesh equals the
              loaded TCA's mean mesh stiffness (wormsim.tooth.ltca) at ISO 6336-1's reference line load
              (compliance.reference_torque_nm)
    hertz     (contact.stiffness_model: hertz) Hertz line contact k' = pi E* / 4 of rigid teeth (seed 001)
"""

from __future__ import annotations

import math

import numpy as np

from meshgen.geometry import GearGeometry
from wormsim.exceptions import SimulationError
from wormsim.physics.gear_theory import effective_modulus_pa
from wormsim.scenario import Contact, Materials
from wormsim.tooth import compliance, ltca, mesh_stiffness
from wormsim.tooth.mesh_stiffness import MeshStiffness

STIFFNESS_SOURCES = ("teeth", "scenario", "hertz")
LTCA_SAMPLES = 16  # loaded TCA samples per mesh cycle (line_stiffness_n_per_m2's, so one LTCA serves both)


def hertz_per_length_n_per_m2(materials: Materials) -> float:
    """k' = pi E* / 4 (Hertz line contact of two cylinders, seed 001; E* =
    wormsim.physics.gear_theory.effective_modulus_pa)."""
    return math.pi * effective_modulus_pa(materials) / 4.0


def per_length_stiffness(contact: Contact, g: GearGeometry, materials: Materials) -> tuple[float, str]:
    """(k' in N/m per m of contact line, its source): K / b2 when the scenario gives contact.stiffness_n_per_m
    ("scenario"), else by contact.stiffness_model the teeth's compliance ("teeth",
    line_stiffness_n_per_m2) or Hertz pi E* / 4 ("hertz"); module docstring."""
    if contact.stiffness_n_per_m is not None:
        return contact.stiffness_n_per_m / g.face_width, "scenario"
    if contact.stiffness_model == "hertz":
        return hertz_per_length_n_per_m2(materials), "hertz"
    try:
        return float(line_stiffness_n_per_m2(g, materials)), "teeth"
    except Exception as exc:  # the FE mesher or solver on an unusual gear: say what to set instead (exit 3)
        raise SimulationError(
            f"the teeth's compliance could not be computed for this gear ({type(exc).__name__}: {exc}); set "
            f"contact.stiffness_n_per_m (one tooth pair's stiffness, N/m) or contact.stiffness_model=hertz"
        ) from exc


def pair_stiffness_n_per_m(contact: Contact, g: GearGeometry, materials: Materials) -> tuple[float, str]:
    """(K = k' b2, the stiffness of one tooth pair whose contact line spans the face width, as contact3d's law reads
    it; its source): per_length_stiffness over the face width."""
    # the scenario's K and Hertz's pi b2 E* / 4 as written (bit for bit: a run above the stable limit rings or not on
    # the last bit of K, tests/contact3d/test_ringing_check.py), the teeth's k' b2
    if contact.stiffness_n_per_m is not None:
        return contact.stiffness_n_per_m, "scenario"
    if contact.stiffness_model == "hertz":
        return math.pi * g.face_width * effective_modulus_pa(materials) / 4.0, "hertz"
    kp, source = per_length_stiffness(contact, g, materials)
    return kp * g.face_width, source


def line_stiffness_n_per_m2(
    g: GearGeometry, materials, torque_nm: float | None = None, samples: int = LTCA_SAMPLES, density: int = 1
) -> float:
    """k'_eff (N/m per m of contact line): the per-length stiffness that makes wormsim.tooth.mesh_stiffness's mean
    k_mesh equal the LTCA's mean mesh stiffness (wormsim.tooth.ltca) at wheel torque torque_nm (default
    reference_torque_nm), flank side +1."""
    t = compliance.reference_torque_nm(g) if torque_nm is None else abs(torque_nm)
    res = ltca.loaded_contact(g, materials, t, samples=samples, density=density)
    unit = mesh_stiffness.mesh_stiffness(g, 1.0, "unit", samples)
    return float(np.mean(res.mesh_stiffness_n_per_m) / np.mean(unit.k_mesh_fwd_n_per_m))


def mesh_stiffness_table(contact: Contact, g: GearGeometry, materials: Materials, samples: int) -> MeshStiffness:
    """torsional's k(theta1) tables over one mesh cycle: wormsim.tooth.mesh_stiffness's TCA with k' of
    per_length_stiffness; where the source is the teeth's compliance, k(theta1) of each flank side is the loaded TCA's
    (wormsim.tooth.ltca at reference_torque_nm, LTCA_SAMPLES per cycle, periodic linear interpolation onto the
    table's samples): the teeth's bending couples the contact lines and smooths the variation (k ptp / mean 0.26 / 0.19
    TCA / LTCA on the screw jack, 0.36 / 0.26 on involute_41, docs/tooth_compliance.md), with the same mean (k' is
    chosen so, line_stiffness_n_per_m2); the contact-line lengths and teeth counts stay the TCA's."""
    import dataclasses

    kp, source = per_length_stiffness(contact, g, materials)
    ms = mesh_stiffness.mesh_stiffness(g, kp, source, samples)
    if source != "teeth":
        return ms
    t = compliance.reference_torque_nm(g)
    k = {}
    for side in (1, -1):
        lt = ltca.loaded_contact(g, materials, t, samples=LTCA_SAMPLES, side=side)
        k[side] = np.interp(ms.theta1_rad, lt.theta1_rad, lt.mesh_stiffness_n_per_m, period=ms.period_rad)
    arm2 = ms.arm0_m**2
    return dataclasses.replace(
        ms,
        k_mesh_fwd_n_per_m=k[1],
        k_mesh_rev_n_per_m=k[-1],
        k_theta_fwd_nm_per_rad=k[1] * arm2,
        k_theta_rev_nm_per_rad=k[-1] * arm2,
    )


def stiffness_outputs(
    ms: MeshStiffness,
    g: GearGeometry,
    materials: Materials,
    wheel_torque_nm: float,
    side: int = 1,
    errors: bool = False,
) -> tuple[dict, object | None]:
    """(summary keys, the LTCA result or None): the keys of the tooth pair's stiffness and load sharing
    (wormsim.results.summary_keys), the same at torsional and contact3d: mesh_stiffness_source and _mean_n_per_m (this
    TCA with the
    k' the run uses), the mean per face width in N/(mm um) (ISO 6336-1's unit of c' and c_gamma), and from the loaded
    tooth contact analysis of the teeth's compliance at the working wheel torque (wormsim.tooth.ltca.loaded_contact)
    the loaded TE p2p and the largest share of one tooth, on the working flank `side`. The LTCA runs only where the
    run's stiffness is the teeth's (source teeth) and the pair has no assembly errors (`errors`: the LTCA takes the
    perfect pair's gaps); elsewhere its keys are null."""
    k_mean = float(np.mean(ms.k_mesh_fwd_n_per_m))
    out = {
        "mesh_stiffness_source": ms.stiffness_source,
        "mesh_stiffness_mean_n_per_m": k_mean,
        "mesh_stiffness_per_width_n_per_mm_um": k_mean / (g.face_width * 1e9),  # N/m / (b2 mm) -> N/(mm um)
        "transmission_error_loaded_p2p_urad": None,
        "load_share_max": None,
    }
    lt = None
    if ms.stiffness_source == "teeth" and wheel_torque_nm != 0 and not errors:
        lt = ltca.loaded_contact(g, materials, abs(wheel_torque_nm), side=1 if side >= 0 else -1)
        s = lt.summary()
        out["transmission_error_loaded_p2p_urad"] = s["transmission_error_loaded_p2p_urad"]
        out["load_share_max"] = s["load_share_max"]
    return out, lt
