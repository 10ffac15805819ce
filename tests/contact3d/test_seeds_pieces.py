"""Validation of contact3d with contact.geometry pieces on the three seed gears, CI-sized: same gear, materials,
contact law and load as scenarios/*.yaml; shorter ramps and durations (>= 5 meshing periods in the steady window); resolution fine
enough that meshgen's piece bulge stays inside half the backlash (involute_41 needs `fine`).
seat_motor runs its worm at 1800 rpm instead of 36 rpm (a 0.6 Hz mesh would need 20 s of 2 us steps).

Checks per seed: ratio within 0.1 % of z2/z1; meshing frequency within max(1 %, one FFT bin) of
z1 n1 / 60; torque balance: mean tangential force x r2 within 2 % of the load torque; efficiency within
3 % of the wedge model's tan(g) / tan(g + rho'). Failing physics stays strict and is marked xfail with
the measured numbers (see docs/contact3d.md).
"""

from __future__ import annotations

import pytest

from tests.conftest import SCENARIOS as SCEN
from wormsim.contact3d.runner import simulate
from wormsim.scenario import load_scenario

CI = {
    "seat_motor": [
        "drive.speed_rpm=1800",
        "drive.ramp_s=0.02",
        "load.ramp_s=0.02",
        "simulation.duration_s=0.25",
        "simulation.resolution=medium",
    ],
    "screw_jack": [
        "drive.ramp_s=0.02",
        "load.ramp_s=0.02",
        "simulation.duration_s=0.35",
        "simulation.resolution=medium",
    ],
    "involute_41": [
        "drive.ramp_s=0.02",
        "load.ramp_s=0.02",
        "simulation.duration_s=0.3",
        "simulation.resolution=medium",
    ],
}
# contact.geometry pieces: involute_41's pieces need fine (coarser pieces leave gaps on its 82.5 mm face); the flanks'
# runs keep medium, the default (fine doubles the flanks' slices)
PIECES = {"involute_41": ["simulation.resolution=fine"]}
_CACHE: dict[str, dict] = {}


def run(name: str) -> dict:
    if name not in _CACHE:
        sc = load_scenario(SCEN / f"{name}.yaml", [*CI[name], *PIECES.get(name, []), "contact.geometry=pieces"])
        res = simulate(sc)
        _CACHE[name] = {"summary": res.summary, "scenario": sc}
    return _CACHE[name]


SEEDS = list(CI)


@pytest.mark.parametrize("name", SEEDS)
def test_ratio_within_0p1_percent(name):
    s = run(name)["summary"]
    assert abs(s["ratio"] / s["ratio_theory"] - 1) < 1e-3, s["ratio"]


# measured on this CI configuration (docs/contact3d.md): kept strict, marked as expected failures
# involute_41 (pieces, fine) failed this at the 1-2-5 default step 5e-5 s (F_t's meshing line 24.285 Hz, +0.59 %: the
# wheel's mesh mode ringing at ~0.8-2.3 kHz leaked into it); at the two-digit default 8.5e-5 s (decision 0043) it passes
MESH_XFAIL: dict[str, str] = {}
EFF_XFAIL = {
    "seat_motor": "efficiency 0.600 against tan(g)/tan(g+rho') = 0.620 at the pitch radius (-3.2 %; its default step "
    "6.4e-6 s): the contacts sit on the worm above its pitch radius (force-weighted 4.39 mm against r1 4.19 mm; the "
    "wheel is 58 % undercut), where the local lead angle is smaller; the same formula at each contact's own radius "
    "gives 0.610 (test below). Finer pieces resolve it further: coarse / medium / fine 0.605 / 0.600 / "
    "0.592. Not the rattle (driven-machine inertia 1e-4 kg m^2: 0.586, at its default step 4.6e-5 s) and not "
    "back-flank friction "
    "(back-flank contacts carry 0.0 % of |F_t|)",
}


# the tolerance for the meshing frequency: 0.5 % of z1 n1 / 60
MESH_FREQUENCY_REL = 0.005


def assert_mesh_frequency(s: dict, key: str, rel: float = MESH_FREQUENCY_REL) -> None:
    """s[key] within rel (0.5 %) of z1 n1 / 60 (seed 001: the meshing frequency), on a window of >= 5 mesh periods.
    The peak is interpolated between FFT bins (wormsim.results.metrics.dominant_frequency), so the check is tighter than
    one bin (17-20 % of f_mesh on these windows) and a wrong harmonic or a drifted peak fails."""
    w0, w1 = s["steady_window_s"]
    assert (w1 - w0) * s["mesh_frequency_theory_hz"] >= 5, ("steady window too short for the FFT", w0, w1)
    assert abs(s[key] / s["mesh_frequency_theory_hz"] - 1) <= rel, (
        s[key],
        s["mesh_frequency_theory_hz"],
        s["mesh_frequency_resolution_hz"],
    )


@pytest.mark.parametrize(
    "name",
    [
        pytest.param(n, marks=pytest.mark.xfail(reason=MESH_XFAIL[n], strict=True)) if n in MESH_XFAIL else n
        for n in SEEDS
    ],
)
def test_mesh_frequency(name):
    assert_mesh_frequency(run(name)["summary"], "mesh_frequency_hz")


# involute_41 (pieces): 24.333 Hz, +0.79 %, at 5e-5 s (the mesh-mode ringing above); passes at 8.5e-5 s (decision 0043)
RADIAL_MESH_XFAIL: dict[str, str] = {}


@pytest.mark.parametrize(
    "name",
    [
        pytest.param(n, marks=pytest.mark.xfail(reason=RADIAL_MESH_XFAIL[n], strict=True))
        if n in RADIAL_MESH_XFAIL
        else n
        for n in SEEDS
    ],
)
def test_mesh_frequency_in_the_radial_force(name):
    """Not the issue's criterion (that is the tangential force, above) but the same FFT on the radial force,
    which follows the number of teeth in contact directly and is less exposed to the mesh-mode vibration."""
    assert_mesh_frequency(run(name)["summary"], "mesh_frequency_radial_hz")


@pytest.mark.parametrize("name", SEEDS)
def test_torque_balance_within_2_percent(name):
    r = run(name)
    s, sc = r["summary"], r["scenario"]
    from meshgen.geometry import derive

    r2 = derive(sc.gear).r2
    assert abs(s["tangential_force_mean_n"] * r2 / sc.load.torque_nm - 1) < 0.02, s["tangential_force_mean_n"]


@pytest.mark.parametrize(
    "name",
    [
        pytest.param(n, marks=pytest.mark.xfail(reason=EFF_XFAIL[n], strict=True)) if n in EFF_XFAIL else n
        for n in SEEDS
    ],
)
def test_efficiency_within_3_percent_of_wedge(name):
    s = run(name)["summary"]
    assert abs(s["efficiency"] / s["efficiency_theory"] - 1) < 0.03, (s["efficiency"], s["efficiency_theory"])


RADIAL_XFAIL = {
    "seat_motor": "line-of-centres radial force 237.6 N against DIN 3975's 229.1 N (+3.7 %; the plain resultant gives "
    "225 N, -1.8 %): with alpha_n 10 deg the radial force is the smallest component, and the 58 % "
    "undercut wheel leaves contacts whose normals are not the pitch-point normal turned about the worm "
    "axis; not explained further",
}


@pytest.mark.parametrize(
    "name",
    [
        pytest.param(n, marks=pytest.mark.xfail(reason=RADIAL_XFAIL[n], strict=True)) if n in RADIAL_XFAIL else n
        for n in SEEDS
    ],
)
def test_radial_force_on_the_line_of_centres_is_din_3975(name):
    """Each contact's force turned about the worm axis onto the line of centres, summed, against DIN 3975's
    F_r2 = F_t2 tan(alpha_n) cos(rho') / cos(gamma + rho') within 3 % (radial_force_mean_n, wormsim.contact3d.metrics.din_forces). The plain
    resultant's radial component is lower (screw jack about -13 %): the contacts sit around the worm at +-20-30 deg."""
    s = run(name)["summary"]
    assert abs(s["radial_force_mean_n"] / s["radial_force_theory_n"] - 1) < 0.03, (
        s["radial_force_mean_n"],
        s["radial_force_theory_n"],
        s["radial_force_resultant_mean_n"],
    )


@pytest.mark.parametrize("name", SEEDS)
def test_efficiency_within_3_percent_of_wedge_at_the_contact_radius(name):
    """The wedge formula evaluated where the contacts are: at each contact's worm radius r the lead angle is
    tan(gamma_r) = tan(gamma) r1 / r; eta_r = tan(gamma_r) / tan(gamma_r + rho') averaged with the contact forces
    (wormsim.contact3d.metrics.contact_radius_check). Not a looser check: it moves the theory to the contact, not the bound."""
    s = run(name)["summary"]
    assert abs(s["efficiency"] / s["efficiency_theory_at_contact_radius"] - 1) < 0.03, (
        s["efficiency"],
        s["efficiency_theory_at_contact_radius"],
        s["worm_contact_radius_mean_m"],
    )
