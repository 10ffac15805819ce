"""AGMA 6034 (worm gearing rating) as reproduced in Shigley's Mechanical Engineering Design (ch. 15, worm gears)
and Mott's Machine Elements in Mechanical Design (section 10-13): one function per formula, inch units as in those
books (the names carry them: _in, _lbf, _ft_min). The caller converts at its edge.
"""

from __future__ import annotations

import math

SHIGLEY = "Shigley, Mechanical Engineering Design, ch. 15 (AGMA 6034 worm gearing)"
MOTT = "Mott, Machine Elements in Mechanical Design, section 10-13 (AGMA 6034)"

IN_PER_MM = 1.0 / 25.4
LBF_IN_N = 4.4482216152605  # N per lbf
FT_MIN_PER_M_S = 196.850393700787


def materials_factor(casting: str, gear_mean_diameter_in: float, centre_distance_in: float) -> float:
    """C_s (SHIGLEY, MOTT): 720 + 10.37 C^3 for a centre distance C <= 3 in; otherwise by casting and the wheel's
    mean diameter d: sand cast 1000 (d <= 2.5 in) else 1190 - 477 log10 d; chilled 1000 (d <= 8 in) else
    1412 - 456 log10 d; centrifugal 1000 (d <= 25 in) else 1251 - 180 log10 d."""
    if centre_distance_in <= 3.0:
        return 720.0 + 10.37 * centre_distance_in**3
    d = gear_mean_diameter_in
    if casting == "sand":
        return 1000.0 if d <= 2.5 else 1190.0 - 477.0 * math.log10(d)
    if casting == "chilled":
        return 1000.0 if d <= 8.0 else 1412.0 - 456.0 * math.log10(d)
    return 1000.0 if d <= 25.0 else 1251.0 - 180.0 * math.log10(d)


def ratio_factor(m_g: float) -> float:
    """C_m (SHIGLEY, MOTT): 3 < m_G <= 20: 0.02 sqrt(-m_G^2 + 40 m_G - 76) + 0.46; 20 < m_G <= 76:
    0.0107 sqrt(-m_G^2 + 56 m_G + 5145); m_G > 76: 1.1483 - 0.00658 m_G. Below 3 the formulas are not defined:
    the value at 3 is used (the caller warns)."""
    m = max(m_g, 3.0)
    if m <= 20.0:
        return 0.02 * math.sqrt(-(m**2) + 40.0 * m - 76.0) + 0.46
    if m <= 76.0:
        return 0.0107 * math.sqrt(-(m**2) + 56.0 * m + 5145.0)
    return 1.1483 - 0.00658 * m


def velocity_factor(v_s_ft_min: float) -> float:
    """C_v (SHIGLEY, MOTT), V_s the sliding speed in ft/min: < 700: 0.659 exp(-0.0011 V_s); 700-3000:
    13.31 V_s^-0.571; > 3000: 65.52 V_s^-0.774."""
    v = v_s_ft_min
    if v < 700.0:
        return 0.659 * math.exp(-0.0011 * v)
    if v <= 3000.0:
        return 13.31 * v**-0.571
    return 65.52 * v**-0.774


def effective_face_width_in(face_width_in: float, worm_diameter_in: float) -> float:
    """F_e = min(b2, 0.67 d_m1) (SHIGLEY, MOTT)."""
    return min(face_width_in, 0.67 * worm_diameter_in)


def rated_tangential_force_lbf(c_s: float, d_m_in: float, f_e_in: float, c_m: float, c_v: float) -> float:
    """W_t = C_s D_m^0.8 F_e C_m C_v [lbf], D_m the wheel's mean diameter (SHIGLEY, MOTT)."""
    return c_s * d_m_in**0.8 * f_e_in * c_m * c_v


def sliding_speed_ft_min(worm_diameter_in: float, n_w_rpm: float, lead_angle_rad: float) -> float:
    """V_s = pi n_W d_m / (12 cos(lambda)) ft/min (SHIGLEY)."""
    return math.pi * abs(n_w_rpm) * worm_diameter_in / (12.0 * math.cos(lead_angle_rad))


def friction(v_s_ft_min: float) -> float:
    """f (SHIGLEY): 0.15 at V_s = 0; 0.124 exp(-0.074 V_s^0.645) for 0 < V_s <= 10 ft/min;
    0.103 exp(-0.110 V_s^0.450) + 0.012 above."""
    v = v_s_ft_min
    if v <= 0.0:
        return 0.15
    if v <= 10.0:
        return 0.124 * math.exp(-0.074 * v**0.645)
    return 0.103 * math.exp(-0.110 * v**0.450) + 0.012


def efficiency_worm_driving(phi_n_rad: float, lead_angle_rad: float, f: float) -> float:
    """e_W = (cos phi_n - f tan lambda) / (cos phi_n + f cot lambda) (SHIGLEY)."""
    c = math.cos(phi_n_rad)
    return (c - f * math.tan(lead_angle_rad)) / (c + f / math.tan(lead_angle_rad))


# ----------------------------------------------------------------------------- housing heat balance (oil sump)


def housing_area_min_in2(centre_distance_in: float) -> float:
    """A_min = 43.2 C^1.7 in^2, AGMA's least lateral housing area for a centre distance C in inches (SHIGLEY)."""
    return 43.2 * centre_distance_in**1.7


def heat_transfer_coefficient(n_w_rpm: float, fan: bool = False) -> float:
    """h_CR = n_W/6494 + 0.13 (no fan on the worm shaft), n_W/3939 + 0.13 (fan), in ft lbf / (min in^2 F)
    (SHIGLEY)."""
    return abs(n_w_rpm) / (3939.0 if fan else 6494.0) + 0.13


# ft lbf / (min in^2 F) -> W / (m^2 K): 1 ft lbf/min = 0.0225969658 W, 1 in^2 = 6.4516e-4 m^2, 1 F = 5/9 K
HEAT_TRANSFER_SI = 0.0225969658 / 6.4516e-4 / (5.0 / 9.0)


def sump_temperature_c(ambient_c: float, loss_w: float, h_w_m2k: float, area_m2: float) -> float:
    """t_s = t_a + H_loss / (h_CR A) (SHIGLEY's housing heat balance, in SI)."""
    return ambient_c + loss_w / (h_w_m2k * area_m2)
