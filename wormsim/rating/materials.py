"""Worm-wheel materials for the load-capacity rating, each row with its source.

The strength values are those of DIN 3996's wheel-material table (sigma_HlimT pitting strength, tau_FlimT tooth-root
shear strength, W_ML wear material/lubricant factor, Y_W friction material factor), as the MITCalc worm-gear
workbook (Gear4, material sheet) lists them; a public web port of that workbook reproduces the sheet row by row
(MITCALC_SOURCE). The CuSn12-C-GZ row is confirmed independently by a KISSsoft DIN 3996 report printed in a public
forum thread (KISSSOFT_SOURCE: E 88300 MPa, nu 0.35, tau_Flim 92 MPa, sigma_Hlim 425 MPa, W_ML 1.6).

POM has no row of DIN 3996: it is listed as a plastic, which the rating refuses with its reason
(wormsim.rating.plastic), so no strength value of it is needed or given.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

MITCALC_SOURCE = (
    "MITCalc worm-gear workbook (Gear4_01.xlsb, wheel-material sheet: DIN 3996 values), as reproduced row by row "
    "in a public web port of the workbook (WORM_WHEEL_MATERIALS)"
)
KISSSOFT_SOURCE = "KISSsoft DIN 3996 report, CuSn12-C-GZ wheel, printed at https://szfco.com/thread-98189-3-1.html"

Lubricant = Literal["mineral", "pao", "peg"]
LUBRICANT_INDEX = {"mineral": 0, "pao": 1, "peg": 2}


@dataclass(frozen=True)
class WheelMaterial:
    name: str
    designation: str
    kind: Literal["bronze", "al_bronze", "grey_iron", "nodular_iron", "plastic"]
    youngs_modulus_mpa: float | None
    poisson_ratio: float | None
    sigma_hlim_t_mpa: float | None  # pitting strength sigma_HlimT
    tau_flim_t_mpa: float | None  # tooth-root shear strength tau_FlimT
    w_ml: tuple[float, float, float] | None  # wear factor W_ML for mineral / PAO / PEG oil
    y_w: float | None  # friction material factor Y_W
    source: str


WHEEL_MATERIALS: dict[str, WheelMaterial] = {
    m.name: m
    for m in (
        WheelMaterial(
            "CuSn12Ni2", "CuSn12Ni2-C-GZ (centrifugal cast, DIN EN 1982)", "bronze",
            98100.0, 0.35, 520.0, 100.0, (1.0, 1.0, 1.75), 0.95, MITCALC_SOURCE,
        ),
        WheelMaterial(
            "CuSn12", "CuSn12-C-GZ (centrifugal cast, DIN EN 1982)", "bronze",
            88300.0, 0.35, 425.0, 92.0, (1.6, 1.6, 2.25), 1.0, f"{MITCALC_SOURCE}; {KISSSOFT_SOURCE}",
        ),
        WheelMaterial(
            "CuAl10Fe5Ni5", "CuAl10Fe5Ni5-C-GZ (centrifugal cast, DIN EN 1982)", "al_bronze",
            122600.0, 0.35, 660.0, 128.0, (1.0, 1.0, 1.0), 1.1, MITCALC_SOURCE,
        ),
        WheelMaterial(
            "GJS-400", "EN-GJS-400-15 (DIN EN 1563)", "nodular_iron",
            175000.0, 0.3, 490.0, 115.0, (1.0, 1.0, 1.0), 1.0, MITCALC_SOURCE,
        ),
        WheelMaterial(
            "GJL-250", "EN-GJL-250 (DIN EN 1561)", "grey_iron",
            98100.0, 0.3, 350.0, 70.0, (1.0, 1.0, 1.0), 1.05, MITCALC_SOURCE,
        ),
        WheelMaterial(
            "POM", "polyoxymethylene (acetal)", "plastic",
            None, None, None, None, None, None,
            "plastic: no DIN 3996 row; rated by wormsim.rating.plastic (refusal with the reason)",
        ),
    )
}  # fmt: skip

WHEEL_MATERIAL_NAMES = tuple(WHEEL_MATERIALS)
PLASTIC_MODULUS_MAX_GPA = 10.0  # a wheel this soft is taken as a plastic when rating.wheel_material is not given

# Z_oil (pitting lubricant factor), c_alpha (pressure-viscosity coefficient, m^2/N) per lubricant:
# MITCalc Gear4 oil-type table (Tables!B26:E28), as reproduced in the same public web port
Z_OIL = {"mineral": 0.89, "pao": 0.94, "peg": 1.0}
# permissible oil sump temperature theta_Slim (C) per lubricant: docs of the BSI/MITCalc reproductions, collected in
# the public rating formulas of docs/rating.md ("Temperature")
THETA_SLIM_C = {"mineral": 90.0, "pao": 100.0, "peg": 110.0}
