"""Plastic worm wheels (POM): why the rating gives no safety factor for them.

DIN 3996 / ISO/TS 14521 method B and AGMA 6034 rate bronze and cast-iron wheels: their strength values, friction fits
and wear data come from tests of those materials. A plastic wheel lives or dies by its tooth temperature, and its
root and flank strengths fall with that temperature: VDI 2736 rates plastic gears that way. The public reproduction
of VDI 2736 (the open GEARpie project, CLASSES/VDI2736.py, MIT licence) covers cylindrical gears only: its bulk
temperature theta = theta_0 + P_V (k / (b z (v m)^0.75) + R_lambdaG / A) uses heat-transfer constants (k_F 6300,
k_R 895 for plastic on steel) fitted to spur and helical pairs. No public source carries these constants, or the
temperature-dependent strength curves of POM, over to a worm wheel meshing with a steel worm (line contact with
sliding along the lines, one wheel tooth in a sliding contact for most of the revolution). Applying them would be
a guess, and applying the bronze formulas would be wrong, so the rating refuses the safety factors for a plastic
wheel and says why; the material-independent quantities (sliding speed, and with `--fe` the FE root stress) are
still given.
"""

from __future__ import annotations

SOURCE = "VDI 2736 (plastic gears) as reproduced for cylindrical gears by GEARpie (CLASSES/VDI2736.py, MIT)"


def refusal_reason(material: str) -> str:
    return (
        f"wheel material {material} is a plastic: ISO/TS 14521 / DIN 3996 and AGMA 6034 rate bronze and cast-iron "
        "wheels only, and the public plastic-gear method (VDI 2736, reproduced for cylindrical gears by GEARpie) has "
        "no published heat-transfer constants or temperature-dependent strengths for a worm wheel; no safety factor "
        "is given for it (docs/rating.md, 'Plastic wheels')"
    )
