"""`wormsim init [PATH]`: write a commented scenario template a drive engineer fills in (docs/scenario.md has every
key). The template is a 2-start ZA worm gear, 30 teeth, axial module 3 mm, q 11, steel on bronze, 1500 rpm, 60 N m;
it runs as written at every level (tests/test_api.py)."""

from __future__ import annotations

import re
from pathlib import Path

from wormsim.errors import ScenarioError

TEMPLATE = """\
# wormsim scenario: fill in your gear, then
#   wormsim run {path} --out out/{name}                      # 3D tooth contact (contact3d)
#   wormsim run {path} --out out/{name}_t --set model=torsional   # seconds: 2-DOF torsional
#   wormsim run {path} --out out/{name}_w --set model=wedge       # instant: reduced wedge
# Units are in the key names (mm, deg, rpm, N m, s). Every key: docs/scenario.md; every output: docs/outputs.md.
name: {name}                  # lower case, digits, _ or -; used in outputs
description: 2-start ZA worm gear, steel on bronze
model: contact3d              # contact3d | torsional | wedge

gear:                         # DIN 3975 names
  profile: ZA                 # ZA (straight-sided axial profile) | ZI (involute helicoid)
  hand: right                 # right | left
  worm_starts: 2              # z1
  wheel_teeth: 30             # z2; ratio z2 / z1
  axial_module_mm: 3.0        # m_x (or normal_module_mm: m_n, not both)
  diameter_quotient: 11       # q = d1 / m_x (or lead_angle_deg: gamma at d1, not both)
  normal_pressure_angle_deg: 20
  face_width_mm: 24           # wheel face width b2 (default: 0.75 x worm tip diameter)
  backlash_mm: 0.1            # circumferential, at the wheel reference circle

materials:                    # optional; these are the defaults (steel worm, bronze wheel)
  worm:  {{youngs_modulus_gpa: 210, poisson_ratio: 0.3,  density_kg_m3: 7850}}
  wheel: {{youngs_modulus_gpa: 100, poisson_ratio: 0.34, density_kg_m3: 8800}}

contact:                      # optional: stiffness from the teeth's compliance, damping 10 % of critical
  friction: 0.04              # one Coulomb coefficient; or friction_static + friction_dynamic, or friction_group

drive:
  on: worm                    # worm (forward) | wheel (back-driving: torsional, contact3d)
  speed_rpm: 1500             # speed-controlled (or torque_nm: a torque drive)
  ramp_s: 0.02                # STEP ramp from rest

load:
  on: wheel                   # the other shaft
  torque_nm: 60               # resisting torque on the wheel
  start_s: 0.0
  ramp_s: 0.02

simulation:
  duration_s: 0.1             # simulated time; contact3d takes minutes per 0.1 s, torsional seconds
"""


def scenario_name(path: Path) -> str:
    """A valid scenario name from the file name: lower case, other characters as _."""
    name = re.sub(r"[^a-z0-9_-]+", "_", path.stem.lower()).strip("_")
    return name or "my_gear"


def write_template(path: str | Path = "my_gear.yaml") -> Path:
    """Write the template to `path` (a new file; an existing one is refused: ScenarioError, exit 2)."""
    from wormsim.output import check_writable_file, write_text_atomic

    path = Path(path)
    if path.exists():
        raise ScenarioError(f"{path}: exists; give a new file name (wormsim init never overwrites)")
    check_writable_file(path)
    write_text_atomic(path, TEMPLATE.format(path=path, name=scenario_name(path)))
    return path
