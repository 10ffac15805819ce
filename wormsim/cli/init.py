"""`wormsim init [PATH]`: write a commented scenario template a drive engineer fills in (docs/scenario.md has every
key). The template is README.md's (tests/test_readme.py keeps the two the same): a 2-start ZA worm gear, 30 teeth,
axial module 3 mm, q 11, steel on bronze, 1500 rpm, 60 N m, torsional for 0.5 s; it runs as written at every level
(tests/tools/test_api_doc.py)."""

from __future__ import annotations

import re
from pathlib import Path

from wormsim.exceptions import ScenarioError

TEMPLATE = """\
# {path}: a 2-start ZA worm gear. Units are in the key names; docs/scenario.md lists every key.
#   wormsim check {path}                        # validate; prints the defaults and the derived sizes
#   wormsim run {path} --out out/{name}           # torsional: a few seconds
#   wormsim run {path} --out out/{name}_3d --set model=contact3d --set simulation.duration_s=0.2  # minutes
name: {name}
model: torsional            # wedge | torsional | contact3d (or --set model=... on the command line)
gear:
  profile: ZA               # ZA | ZN | ZI | ZK | ZC (docs/flank_forms.md): ZA straight axial profile, ZN straight
                            # normal profile (zn_section), ZI involute helicoid, ZK disc tool (tool_diameter_mm),
                            # ZC concave arc (profile_radius_mm)
  hand: right               # right | left
  worm_starts: 2            # z1
  wheel_teeth: 30           # z2: ratio z2 / z1 = 15
  axial_module_mm: 3.0      # or normal_module_mm (exactly one)
  diameter_quotient: 11     # q = d1 / m_x (or lead_angle_deg: exactly one)
  normal_pressure_angle_deg: 20
  face_width_mm: 25         # b2; default 0.75 x the worm tip diameter
  backlash_mm: 0.1          # circumferential, at the wheel reference circle
materials:                  # E, Poisson, density; these are the defaults: steel worm, bronze wheel
  worm:  {{youngs_modulus_gpa: 210, poisson_ratio: 0.30, density_kg_m3: 7850}}
  wheel: {{youngs_modulus_gpa: 100, poisson_ratio: 0.34, density_kg_m3: 8800}}
contact:
  friction: 0.04            # Coulomb mu on the flanks (or friction_static + friction_dynamic)
drive:
  on: worm                  # worm | wheel (back-driving)
  speed_rpm: 1500           # or torque_nm: a torque drive
  ramp_s: 0.05              # STEP ramp from rest
load:
  on: wheel                 # the other shaft
  torque_nm: 60             # resisting torque on the wheel
  ramp_s: 0.05
simulation:
  duration_s: 0.5           # at contact3d, 0.2 s is a quick look
"""


def scenario_name(path: Path) -> str:
    """A valid scenario name from the file name: lower case, other characters as _."""
    name = re.sub(r"[^a-z0-9_-]+", "_", path.stem.lower()).strip("_")
    return name or "my_gear"


def write_template(path: str | Path = "my_gear.yaml") -> Path:
    """Write the template to `path` (a new file; an existing one is refused: ScenarioError, exit 2)."""
    from wormsim.runfolder.writer import check_writable_file, write_text_atomic

    path = Path(path)
    if path.exists():
        raise ScenarioError(f"{path}: exists; give a new file name (wormsim init never overwrites)")
    check_writable_file(path)
    write_text_atomic(path, TEMPLATE.format(path=path, name=scenario_name(path)))
    return path
