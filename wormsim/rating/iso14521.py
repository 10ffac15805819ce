"""ISO/TS 14521 / DIN 3996 method B, as publicly reproduced: one function per formula.

The standards' own texts are not public. Each formula here is taken from a public reproduction, named in its
docstring:

* PORT: a public third-party port of the MITCalc worm-gear workbook (DIN 3996:1998 method B), whose formulas are
  collected, with units, in the project's rating reference (docs/rating.md lists them);
* BSI: the BSI product page of PD ISO/TS 14521:2020 (scope and validity limits).

Units are those of the public formulas and are in the argument names: lengths in mm, forces in N, stresses and
moduli in MPa (N/mm^2), torques in N m, speeds in min^-1 and m/s. The caller (wormsim.rating.rate) converts the SI
geometry once at its edge.
"""

from __future__ import annotations

import math

PORT = "DIN 3996 method B as reproduced in a public port of the MITCalc worm-gear workbook"
BSI = "BSI product page of PD ISO/TS 14521:2020 (scope and validity)"

# validity limits (BSI)
SLIDING_SPEED_MAX_M_S = 25.0
WEAR_SLIDING_SPEED_MIN_M_S = 0.1
METHOD_B_CENTRE_DISTANCE_MIN_MM = 50.0


def reduced_modulus_mpa(e1_mpa: float, nu1: float, e2_mpa: float, nu2: float) -> float:
    """E_red = 2 / ((1 - nu1^2)/E1 + (1 - nu2^2)/E2) (PORT)."""
    return 2.0 / ((1.0 - nu1**2) / e1_mpa + (1.0 - nu2**2) / e2_mpa)


def mean_contact_pressure_factor(x2: float, u: float, z2: int, b2h_mm: float, m_x_mm: float, q: float) -> float:
    """p_m* (DIN 3996:1998) = 1.03 (0.4 + x2/u + 0.01 z2 - 0.083 b2H/m_x + sqrt(2q - 1)/6.9
    + (q + 50(u + 1)/u)/(15.9 + 37.5 q)) (PORT)."""
    return 1.03 * (
        0.4
        + x2 / u
        + 0.01 * z2
        - 0.083 * b2h_mm / m_x_mm
        + math.sqrt(2.0 * q - 1.0) / 6.9
        + (q + 50.0 * (u + 1.0) / u) / (15.9 + 37.5 * q)
    )


def mean_contact_stress_mpa(p_m_star: float, t2_nm: float, e_red_mpa: float, a_mm: float) -> float:
    """sigma_Hm = (4/pi) sqrt(p_m* T2 1000 E_red / a^3) (PORT)."""
    return 4.0 / math.pi * math.sqrt(p_m_star * t2_nm * 1000.0 * e_red_mpa / a_mm**3)


def film_thickness_factor(q: float, z2: int, x2: float, u: float, b2h_mm: float, m_x_mm: float) -> float:
    """h* (DIN 3996:1998) = 0.018 + q/(7.86 (q + z2)) + 1/z2 + x2/110 - u/36300 + b2H/(370.4 m_x)
    - sqrt(2q - 1)/213.9 (PORT)."""
    return (
        0.018
        + q / (7.86 * (q + z2))
        + 1.0 / z2
        + x2 / 110.0
        - u / 36300.0
        + b2h_mm / (370.4 * m_x_mm)
        - math.sqrt(2.0 * q - 1.0) / 213.9
    )


def sliding_speed_m_s(d_m1_mm: float, n1_rpm: float, gamma_m_rad: float) -> float:
    """v_gm = d_m1 n1 / (19098 cos(gamma_m)) (PORT)."""
    return d_m1_mm * abs(n1_rpm) / (19098.0 * math.cos(gamma_m_rad))


def base_friction(v_gm_m_s: float, lubricant: str, grey_iron: bool) -> float:
    """mu_0T, the test-gear base friction (PORT): tin-bronze wheel, mineral oil 0.028 + 0.026/(v + 0.17)^0.76,
    PAO 0.026 + 0.017/(v + 0.17)^0.92, PEG 0.020 + 0.020/(v + 0.2)^0.97; grey cast-iron wheel
    0.055 + 0.015/(v + 0.2)^0.87 (the only fit given for grey iron, any oil)."""
    v = v_gm_m_s
    if grey_iron:
        return 0.055 + 0.015 / (v + 0.2) ** 0.87
    if lubricant == "mineral":
        return 0.028 + 0.026 / (v + 0.17) ** 0.76
    if lubricant == "pao":
        return 0.026 + 0.017 / (v + 0.17) ** 0.92
    return 0.020 + 0.020 / (v + 0.2) ** 0.97


def size_factor_friction(a_mm: float) -> float:
    """Y_S = sqrt(100 / a), a clamped to 65..250 mm (PORT)."""
    return math.sqrt(100.0 / min(max(a_mm, 65.0), 250.0))


def geometry_factor_friction(h_star: float) -> float:
    """Y_G = sqrt(0.07 / h*), at most 2 (PORT)."""
    return min(math.sqrt(0.07 / h_star), 2.0)


def roughness_factor_friction(ra1_um: float) -> float:
    """Y_R = (Ra1 / 0.5)^0.25, Ra1 the worm flank's mean roughness in um (PORT)."""
    return (ra1_um / 0.5) ** 0.25


def mean_friction(mu_0t: float, y_s: float, y_g: float, y_w: float, y_r: float) -> float:
    """mu_zm = mu_0T Y_S Y_G Y_W Y_R (PORT)."""
    return mu_0t * y_s * y_g * y_w * y_r


def efficiency_worm_driving(gamma_m_rad: float, mu: float) -> float:
    """eta_z = tan(gamma_m) / tan(gamma_m + rho_z), rho_z = atan(mu_zm) (PORT)."""
    return math.tan(gamma_m_rad) / math.tan(gamma_m_rad + math.atan(mu))


def efficiency_wheel_driving(gamma_m_rad: float, mu: float) -> float:
    """eta_z' = tan(gamma_m - rho_z) / tan(gamma_m), 0 when gamma_m <= rho_z (self-locking) (PORT)."""
    rho = math.atan(mu)
    return max(math.tan(gamma_m_rad - rho), 0.0) / math.tan(gamma_m_rad)


def pitting_life_factor(life_h: float) -> float:
    """Z_h = (25000 / L_h)^(1/6), at most 1.6 (PORT)."""
    return min((25000.0 / life_h) ** (1.0 / 6.0), 1.6)


def pitting_speed_factor(v_gm_m_s: float) -> float:
    """Z_v = sqrt(5 / (4 + v_gm)) (PORT)."""
    return math.sqrt(5.0 / (4.0 + v_gm_m_s))


def pitting_size_factor(a_mm: float) -> float:
    """Z_s = sqrt(3000 / (2900 + a)) (PORT)."""
    return math.sqrt(3000.0 / (2900.0 + a_mm))


def pitting_limit_mpa(sigma_hlim_t_mpa: float, z_h: float, z_v: float, z_s: float, z_u: float, z_oil: float) -> float:
    """sigma_HG = sigma_HlimT Z_h Z_v Z_s Z_u Z_oil (PORT)."""
    return sigma_hlim_t_mpa * z_h * z_v * z_s * z_u * z_oil


def sliding_path_factor(u: float, gamma_m_rad: float) -> float:
    """s* = 0.78 + 0.21 u + 5.6 / tan(gamma_m) (PORT)."""
    return 0.78 + 0.21 * u + 5.6 / math.tan(gamma_m_rad)


def wheel_load_cycles(life_h: float, n1_rpm: float, u: float) -> float:
    """N_L = L_h n1 60 / u (PORT)."""
    return life_h * abs(n1_rpm) * 60.0 / u


def wear_sliding_path_mm(s_star: float, sigma_hm_mpa: float, a_mm: float, e_red_mpa: float, n_l: float) -> float:
    """s_Wm = s* sigma_Hm a / E_red N_L (PORT)."""
    return s_star * sigma_hm_mpa * a_mm / e_red_mpa * n_l


def wear_limit_mm(m_x_mm: float, gamma_m_rad: float) -> float:
    """delta_Wlim,n = 0.3 m_x cos(gamma_m), the default wear limit (PORT)."""
    return 0.3 * m_x_mm * math.cos(gamma_m_rad)


def wheel_tangential_force_n(t2_nm: float, d_m2_mm: float) -> float:
    """F_tm2 = 2000 T2 / d_m2."""
    return 2000.0 * t2_nm / d_m2_mm


def root_shear_stress_mpa(
    f_tm2_n: float, b2h_mm: float, m_x_mm: float, y_eps: float, y_f: float, y_gamma: float, y_k: float
) -> float:
    """tau_F = F_tm2 / (b2H m_x) Y_eps Y_F Y_gamma Y_K (PORT, and the same form in a second public source)."""
    return f_tm2_n / (b2h_mm * m_x_mm) * y_eps * y_f * y_gamma * y_k


def root_form_factor(m_x_mm: float, s_f2_mm: float) -> float:
    """Y_F = 2.9 m_x / s_f2, s_f2 the wheel tooth's root thickness (PORT)."""
    return 2.9 * m_x_mm / s_f2_mm


def root_lead_factor(gamma_m_rad: float) -> float:
    """Y_gamma = 1 / cos(gamma_m) (PORT)."""
    return 1.0 / math.cos(gamma_m_rad)


ROOT_CONTACT_RATIO_FACTOR = 0.5  # Y_eps (PORT)


def worm_deflection_mm(
    l1_mm: float,
    l2_mm: float,
    f_tm2_n: float,
    gamma_m_rad: float,
    rho_z_rad: float,
    alpha_0_rad: float,
    e1_mpa: float,
    i_mm4: float,
) -> float:
    """delta_m = l1^2 l2^2 F_tm2 sqrt(tan^2(gamma + rho_z) + tan^2(alpha_0)/cos^2(gamma)) / (3 E1 I (l1 + l2))
    (PORT): the worm as a simply supported shaft under the resultant of its tangential and radial mesh forces."""
    resultant = math.sqrt(
        math.tan(gamma_m_rad + rho_z_rad) ** 2 + math.tan(alpha_0_rad) ** 2 / math.cos(gamma_m_rad) ** 2
    )
    return l1_mm**2 * l2_mm**2 * f_tm2_n * resultant / (3.0 * e1_mpa * i_mm4 * (l1_mm + l2_mm))


def worm_second_moment_mm4(d_f1_mm: float) -> float:
    """I = pi (1.1 d_f1)^4 / 64: the worm shaft as a round bar of about 1.1 times its root diameter (PORT)."""
    return math.pi * (1.1 * d_f1_mm) ** 4 / 64.0


def deflection_limit_mm(m_x_mm: float) -> float:
    """delta_lim = 0.04 sqrt(m_x) (PORT)."""
    return 0.04 * math.sqrt(m_x_mm)


def idle_loss_w(a_mm: float, n1_rpm: float) -> float:
    """P_V0 = 8.9e-5 a n1^(4/3) W, the no-load loss (PORT)."""
    return 8.9e-5 * a_mm * abs(n1_rpm) ** (4.0 / 3.0)


def seal_loss_w(d_m1_mm: float, n1_rpm: float) -> float:
    """P_VD = 1.178e-5 d_m1^2 n1 W per shaft seal (PORT)."""
    return 1.178e-5 * d_m1_mm**2 * abs(n1_rpm)


def mesh_loss_w(t2_nm: float, n1_rpm: float, u: float, eta_z: float) -> float:
    """P_Vz = 0.1 T2 n1 / u (1/eta_z - 1) W (PORT)."""
    return 0.1 * t2_nm * abs(n1_rpm) / u * (1.0 / eta_z - 1.0)
