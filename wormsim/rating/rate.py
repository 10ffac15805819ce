"""The load-capacity rating of a scenario's gear at its nominal load: ISO/TS 14521 / DIN 3996 method B and AGMA 6034,
as publicly reproduced (wormsim.rating.iso14521, wormsim.rating.agma6034), every intermediate factor recorded with
its symbol and source. SI geometry from meshgen is converted once here to the units of the public formulas."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from wormsim.physics import gear_theory
from wormsim.physics.geometry import derive
from wormsim.rating import agma6034 as agma
from wormsim.rating import iso14521 as iso
from wormsim.rating import plastic
from wormsim.rating.materials import (
    PLASTIC_MODULUS_MAX_GPA,
    THETA_SLIM_C,
    WHEEL_MATERIALS,
    Z_OIL,
    WheelMaterial,
)
from wormsim.scenario import Rating, Scenario, ScenarioError

MM_PER_M = 1e3

# the rating keys of docs/rating.md (rating.json; the contact3d summary when `rating:` is given)
RATING_KEYS = (
    "contact_stress_mean_iso_mpa",
    "friction_iso",
    "efficiency_iso",
    "sliding_speed_m_s",
    "safety_pitting",
    "safety_wear",
    "safety_root",
    "safety_deflection",
    "safety_temperature",
    "oil_temperature_c",
    "agma_rated_tangential_force_n",
    "agma_friction",
    "agma_efficiency",
    "warnings",
    "sources",
)


@dataclass
class Factors:
    """Intermediate values in the order computed: (key, symbol, value, unit, meaning, source)."""

    rows: list[dict] = field(default_factory=list)
    sources: list[str] = field(default_factory=list)

    def add(self, key: str, symbol: str, value, unit: str, meaning: str, source: str):
        self.rows.append(
            {"key": key, "symbol": symbol, "value": value, "unit": unit, "meaning": meaning, "source": source}
        )
        if source and source not in self.sources:
            self.sources.append(source)
        return value


def rating_inputs(scenario: Scenario) -> Rating:
    return scenario.rating if scenario.rating is not None else Rating()


def wheel_material(scenario: Scenario, r: Rating, warnings: list[str]) -> WheelMaterial:
    """rating.wheel_material, or the default: POM for a wheel of E <= 10 GPa in materials.wheel, else CuSn12Ni2."""
    if r.wheel_material is not None:
        return WHEEL_MATERIALS[r.wheel_material]
    e_gpa = scenario.materials.wheel.youngs_modulus_gpa
    name = "POM" if e_gpa <= PLASTIC_MODULUS_MAX_GPA else "CuSn12Ni2"
    warnings.append(
        f"rating.wheel_material not given: taken as {name} (materials.wheel E = {e_gpa:g} GPa); set it to rate "
        "another wheel material"
    )
    return WHEEL_MATERIALS[name]


def worm_speed_rpm(scenario: Scenario, r: Rating, ratio: float) -> float:
    if r.worm_speed_rpm is not None:
        return r.worm_speed_rpm
    drive = scenario.drive
    if drive is None or drive.speed_rpm is None or drive.speed_rpm == 0:
        raise ScenarioError(
            "rating.worm_speed_rpm: the drive gives no speed (a torque drive or 0 rpm); allowed: "
            "0 < rating.worm_speed_rpm <= 100000"
        )
    return abs(drive.speed_rpm) * (1.0 if drive.on == "worm" else ratio)


def rate(scenario: Scenario) -> dict:
    """Rating of the scenario's gear: a dict with the rating keys, `factors` (every intermediate), `inputs`,
    `warnings`, `sources`, and `refused` (None, or why a method does not apply to the wheel material)."""
    if scenario.gear is None or scenario.drive is None:
        raise ScenarioError("gear: `wormsim rate` needs a gear: and a drive: block (model contact3d or torsional)")
    r = rating_inputs(scenario)
    warnings: list[str] = []
    f = Factors()
    geo = derive(scenario.gear)
    ratio = geo.ratio
    t2_nom = gear_theory.working_wheel_torque_of(scenario.drive, scenario.load, ratio)
    if t2_nom <= 0:
        raise ScenarioError(
            "load.torque_nm = 0: a rating needs the nominal load; allowed: load.torque_nm != 0 (or a torque drive "
            "on the wheel)"
        )
    n1 = worm_speed_rpm(scenario, r, ratio)
    mat = wheel_material(scenario, r, warnings)

    gm = _Mesh.of(geo)
    a, d1, d2, m_x, q, z2, u, b2h, gamma, x2 = gm.a, gm.d1, gm.d2, gm.m_x, gm.q, gm.z2, gm.u, gm.b2h, gm.gamma, gm.x2
    t2 = r.application_factor * t2_nom
    inputs = _inputs(scenario, r, mat, geo, gm, t2_nom, n1)
    v_gm = f.add(
        "sliding_speed_m_s", "v_gm", iso.sliding_speed_m_s(d1, n1, gamma), "m/s", "mean sliding speed", iso.PORT
    )
    out: dict = {k: None for k in RATING_KEYS}
    out["sliding_speed_m_s"] = v_gm
    out["refused"] = None
    _range_warnings(a, v_gm, warnings)
    if mat.kind == "plastic":
        out["refused"] = plastic.refusal_reason(mat.name)
        warnings.append(out["refused"])
        f.sources.append(plastic.SOURCE)
        return _finish(out, f, inputs, warnings)

    assert mat.youngs_modulus_mpa is not None and mat.poisson_ratio is not None
    assert mat.sigma_hlim_t_mpa is not None and mat.tau_flim_t_mpa is not None and mat.y_w is not None
    e1 = scenario.materials.worm.youngs_modulus_gpa * 1e3
    e_scen = scenario.materials.wheel.youngs_modulus_gpa * 1e3
    if abs(e_scen - mat.youngs_modulus_mpa) > 0.1 * mat.youngs_modulus_mpa:
        warnings.append(
            f"materials.wheel E = {e_scen / 1e3:g} GPa differs by more than 10 % from {mat.name}'s "
            f"{mat.youngs_modulus_mpa / 1e3:g} GPa, which the rating uses with that material's strength values"
        )
    e_red = f.add(
        "reduced_modulus_mpa", "E_red",
        iso.reduced_modulus_mpa(e1, scenario.materials.worm.poisson_ratio, mat.youngs_modulus_mpa, mat.poisson_ratio),
        "MPa", "reduced modulus of worm and wheel", iso.PORT,
    )  # fmt: skip

    # --- contact stress
    p_m = f.add(
        "p_m_star", "p_m*", iso.mean_contact_pressure_factor(x2, u, z2, b2h, m_x, q), "-",
        "dimensionless mean Hertz pressure (DIN 3996:1998 fit)", iso.PORT,
    )  # fmt: skip
    sigma_hm = f.add(
        "contact_stress_mean_iso_mpa", "sigma_Hm", iso.mean_contact_stress_mpa(p_m, t2, e_red, a), "MPa",
        "mean Hertz stress at T2 = K_A T2,nom", iso.PORT,
    )  # fmt: skip

    out["contact_stress_mean_iso_mpa"] = sigma_hm
    mu, eta = _friction(f, r, mat, v_gm, gm)
    out["friction_iso"], out["efficiency_iso"] = mu, eta
    out["safety_pitting"] = _pitting(f, r, mat, v_gm, a, sigma_hm)
    out["safety_wear"] = _wear(f, r, gm, sigma_hm, e_red, n1, v_gm, warnings)
    f_tm2, out["safety_root"] = _root(f, geo, mat, t2, d2, b2h, m_x, gamma)
    out["safety_deflection"] = _deflection(f, r, geo, f_tm2, gamma, mu, e1, m_x, warnings)
    out["oil_temperature_c"], out["safety_temperature"] = _temperature(f, r, a, n1, d1, t2, u, eta)

    _agma(out, f, geo, n1, t2, r, mat, warnings)
    return _finish(out, f, inputs, warnings)


@dataclass(frozen=True)
class _Mesh:
    """The geometry in the public formulas' units (mm); with the wheel's profile shift x2 the worm meshes on its mean
    diameter d_m1 = d1 + 2 x2 m_x at the lead angle gamma_m (DIN 3975-1; d1 and gamma when x2 = 0)."""

    a: float  # centre distance, mm
    d1: float  # the worm's mean diameter d_m1, mm
    d2: float
    m_x: float
    q: float
    z2: int
    u: float  # z2 / z1
    b2h: float  # face width, mm
    gamma: float  # gamma_m, rad
    x2: float

    @classmethod
    def of(cls, geo) -> _Mesh:
        return cls(
            geo.a * MM_PER_M,
            2.0 * geo.r_m1 * MM_PER_M,
            geo.d2 * MM_PER_M,
            geo.m_x * MM_PER_M,
            geo.q,
            geo.z2,
            geo.z2 / geo.z1,
            geo.face_width * MM_PER_M,
            geo.gamma_m,
            geo.x2,
        )


def _range_warnings(a: float, v_gm: float, warnings: list[str]) -> None:
    """Method B's recommended centre distances and ISO/TS 14521's sliding speeds."""
    if a < iso.METHOD_B_CENTRE_DISTANCE_MIN_MM:
        warnings.append(
            f"centre distance a = {a:.4g} mm < {iso.METHOD_B_CENTRE_DISTANCE_MIN_MM:g} mm: ISO/TS 14521 recommends "
            "method A (measurements) below it; method B is applied outside its recommended range"
        )
    if v_gm > iso.SLIDING_SPEED_MAX_M_S:
        warnings.append(
            f"sliding speed v_gm = {v_gm:.4g} m/s > {iso.SLIDING_SPEED_MAX_M_S:g} m/s: outside the validity of "
            "ISO/TS 14521"
        )


def _inputs(scenario: Scenario, r: Rating, mat: WheelMaterial, geo, gm: _Mesh, t2_nom: float, n1: float) -> dict:
    """The rating's `inputs`: the loads, the rating: block, the material and the geometry (mm)."""
    t2 = r.application_factor * t2_nom
    a, d1, d2, m_x, q, z2, b2h, gamma, x2 = gm.a, gm.d1, gm.d2, gm.m_x, gm.q, gm.z2, gm.b2h, gm.gamma, gm.x2
    return {
        "wheel_torque_nominal_nm": t2_nom,
        "application_factor": r.application_factor,
        "wheel_torque_rated_nm": t2,
        "worm_speed_rpm": n1,
        "life_h": r.life_h,
        "lubricant": r.lubricant,
        "oil_viscosity_40_mm2_s": r.oil_viscosity_40_mm2_s,
        "oil_viscosity_100_mm2_s": r.oil_viscosity_100_mm2_s,
        "oil_sump_temperature_given_c": r.oil_sump_temperature_c,
        "wheel_material": mat.name,
        "wheel_material_designation": mat.designation,
        "wheel_material_source": mat.source,
        "wheel_casting": r.wheel_casting,
        "ambient_c": r.ambient_c,
        "roughness_worm_um": r.roughness_worm_um,
        "centre_distance_mm": a,
        "worm_diameter_mm": geo.d1 * MM_PER_M,
        "worm_mean_diameter_mm": d1,
        "wheel_diameter_mm": d2,
        "axial_module_mm": m_x,
        "diameter_quotient": q,
        "worm_starts": geo.z1,
        "wheel_teeth": z2,
        "lead_angle_deg": math.degrees(geo.gamma),
        "lead_angle_mean_deg": math.degrees(gamma),
        "normal_pressure_angle_deg": math.degrees(geo.alpha_n),
        "face_width_mm": b2h,
        "profile_shift_x2": x2,
        "worm_youngs_modulus_gpa": scenario.materials.worm.youngs_modulus_gpa,
        "worm_poisson_ratio": scenario.materials.worm.poisson_ratio,
    }


def _friction(f: Factors, r: Rating, mat: WheelMaterial, v_gm, gm: _Mesh) -> tuple:
    """Friction and efficiency: mu_zm = mu_0T Y_S Y_G Y_W Y_R and the mesh efficiencies; returns (mu_zm, eta_z)."""
    gamma, q, z2, x2, u, b2h, m_x, a = gm.gamma, gm.q, gm.z2, gm.x2, gm.u, gm.b2h, gm.m_x, gm.a
    grey = mat.kind == "grey_iron"
    h_star = f.add(
        "h_star", "h*", iso.film_thickness_factor(q, z2, x2, u, b2h, m_x), "-",
        "dimensionless mean film thickness (DIN 3996:1998 fit)", iso.PORT,
    )  # fmt: skip
    mu_0t = f.add(
        "mu_0t", "mu_0T", iso.base_friction(v_gm, r.lubricant, grey), "-",
        "base friction of the test gear" + (" (grey cast-iron fit)" if grey else f" (tin bronze, {r.lubricant} oil)"),
        iso.PORT,
    )  # fmt: skip
    y_s = f.add("y_s", "Y_S", iso.size_factor_friction(a), "-", "size factor of friction", iso.PORT)
    y_g = f.add("y_g", "Y_G", iso.geometry_factor_friction(h_star), "-", "geometry factor of friction", iso.PORT)
    y_w = f.add(
        "y_w", "Y_W", 1.0 if grey else mat.y_w, "-",
        "material factor of friction" + (" (the grey-iron fit is its own base: 1)" if grey else ""), mat.source,
    )  # fmt: skip
    y_r = f.add(
        "y_r", "Y_R", iso.roughness_factor_friction(r.roughness_worm_um), "-", "roughness factor of friction", iso.PORT
    )
    mu = f.add("friction_iso", "mu_zm", iso.mean_friction(mu_0t, y_s, y_g, y_w, y_r), "-", "mean friction", iso.PORT)
    f.add("rho_z_deg", "rho_z", math.degrees(math.atan(mu)), "deg", "friction angle atan(mu_zm)", iso.PORT)
    eta = f.add(
        "efficiency_iso", "eta_z", iso.efficiency_worm_driving(gamma, mu), "-", "mesh efficiency, worm driving",
        iso.PORT,
    )  # fmt: skip
    f.add(
        "efficiency_iso_wheel_driving", "eta_z'", iso.efficiency_wheel_driving(gamma, mu), "-",
        "mesh efficiency, wheel driving (0: self-locking)", iso.PORT,
    )  # fmt: skip
    return mu, eta


def _pitting(f: Factors, r: Rating, mat: WheelMaterial, v_gm, a, sigma_hm) -> float:
    """Pitting: S_H = sigma_HG / sigma_Hm."""
    z_h = f.add("z_h", "Z_h", iso.pitting_life_factor(r.life_h), "-", "life factor (pitting)", iso.PORT)
    z_v = f.add("z_v", "Z_v", iso.pitting_speed_factor(v_gm), "-", "speed factor (pitting)", iso.PORT)
    z_s = f.add("z_s", "Z_s", iso.pitting_size_factor(a), "-", "size factor (pitting)", iso.PORT)
    z_u = f.add(
        "z_u", "Z_u", 1.0, "-", "ratio factor (pitting): its formula is not in the public reproductions; taken as 1",
        "input default (not public)",
    )  # fmt: skip
    z_oil = f.add(
        "z_oil", "Z_oil", Z_OIL[r.lubricant], "-", "lubricant factor (pitting)",
        "MITCalc Gear4 oil-type table, as reproduced in a public web port of the workbook",
    )  # fmt: skip
    given = r.wheel_pitting_strength_mpa
    sigma_hlim = f.add(
        "sigma_hlim_t_mpa", "sigma_HlimT", mat.sigma_hlim_t_mpa if given is None else given, "MPa", "pitting strength",
        mat.source if given is None else "rating.wheel_pitting_strength_mpa (input)",
    )  # fmt: skip
    sigma_hg = f.add(
        "sigma_hg_mpa", "sigma_HG", iso.pitting_limit_mpa(sigma_hlim, z_h, z_v, z_s, z_u, z_oil), "MPa",
        "permissible mean Hertz stress", iso.PORT,
    )  # fmt: skip
    return f.add("safety_pitting", "S_H", sigma_hg / sigma_hm, "-", "sigma_HG / sigma_Hm", iso.PORT)


def _wear(f: Factors, r: Rating, gm: _Mesh, sigma_hm, e_red, n1, v_gm, warnings: list[str]) -> float | None:
    """Wear: S_W = delta_Wlim,n / delta_Wn, None without rating.wear_intensity (J_W's tables are not public)."""
    u, gamma, a, m_x = gm.u, gm.gamma, gm.a, gm.m_x
    s_star = f.add("s_star", "s*", iso.sliding_path_factor(u, gamma), "-", "sliding path factor", iso.PORT)
    n_l = f.add("n_l", "N_L", iso.wheel_load_cycles(r.life_h, n1, u), "-", "wheel revolutions over the life", iso.PORT)
    s_wm = f.add(
        "s_wm_mm", "s_Wm", iso.wear_sliding_path_mm(s_star, sigma_hm, a, e_red, n_l), "mm", "wear sliding path",
        iso.PORT,
    )  # fmt: skip
    d_wlim = f.add(
        "wear_limit_mm", "delta_Wlim,n", iso.wear_limit_mm(m_x, gamma), "mm", "permissible flank wear (default)",
        iso.PORT,
    )  # fmt: skip
    if v_gm <= iso.WEAR_SLIDING_SPEED_MIN_M_S:
        warnings.append(
            f"sliding speed v_gm = {v_gm:.3g} m/s <= {iso.WEAR_SLIDING_SPEED_MIN_M_S} m/s: the wear method applies "
            "above it only"
        )
    if r.wear_intensity is not None:
        j_w = f.add("j_w", "J_W", r.wear_intensity, "-", "wear intensity (input)", "rating.wear_intensity")
        d_wn = f.add("wear_depth_mm", "delta_Wn", j_w * s_wm, "mm", "flank wear over the life", iso.PORT)
        return f.add("safety_wear", "S_W", d_wlim / d_wn, "-", "delta_Wlim,n / delta_Wn", iso.PORT)
    else:
        warnings.append(
            "safety_wear not given: the wear intensity J_W comes from DIN 3996 tables that are not public; give "
            "rating.wear_intensity"
        )
    return None


def _root(f: Factors, geo, mat: WheelMaterial, t2, d2, b2h, m_x, gamma) -> tuple:
    """Tooth root (the wheel tooth's root thickness from the mid-plane section: s_f2 = s2 + 2 h_f tan(alpha_x)):
    returns (F_tm2, S_F = tau_FG / tau_F)."""
    f_tm2 = f.add(
        "f_tm2_n", "F_tm2", iso.wheel_tangential_force_n(t2, d2), "N", "wheel tangential force at T2", iso.PORT
    )
    s_f2 = f.add(
        "s_f2_mm", "s_f2", (geo.wheel_tooth_thickness + 2.0 * geo.h_f * math.tan(geo.alpha_x)) * MM_PER_M, "mm",
        "wheel tooth root thickness, mid-plane: s2 + 2 h_f2 tan(alpha_x) (straight axial flanks)",
        "DIN 3975 mid-plane section (meshgen geometry)",
    )  # fmt: skip
    y_eps = f.add("y_eps", "Y_eps", iso.ROOT_CONTACT_RATIO_FACTOR, "-", "contact ratio factor (root)", iso.PORT)
    y_f = f.add("y_f", "Y_F", iso.root_form_factor(m_x, s_f2), "-", "form factor (root)", iso.PORT)
    y_gam = f.add("y_gamma", "Y_gamma", iso.root_lead_factor(gamma), "-", "lead factor (root)", iso.PORT)
    y_k = f.add(
        "y_k", "Y_K", 1.0, "-", "rim thickness factor: 1 for a solid wheel or a sufficient rim (input default)",
        "input default",
    )  # fmt: skip
    tau_f = f.add(
        "tau_f_mpa", "tau_F", iso.root_shear_stress_mpa(f_tm2, b2h, m_x, y_eps, y_f, y_gam, y_k), "MPa",
        "nominal tooth-root shear stress", iso.PORT,
    )  # fmt: skip
    tau_fg = f.add(
        "tau_fg_mpa", "tau_FG", mat.tau_flim_t_mpa, "MPa",
        "permissible root shear stress = tau_FlimT (life and size factors taken as 1: not public)", mat.source,
    )  # fmt: skip
    return f_tm2, f.add("safety_root", "S_F", tau_fg / tau_f, "-", "tau_FG / tau_F", iso.PORT)


def _deflection(f: Factors, r: Rating, geo, f_tm2, gamma, mu, e1, m_x, warnings: list[str]) -> float:
    """Worm deflection: S_delta = delta_lim / delta_m."""
    span = r.worm_bearing_span_mm if r.worm_bearing_span_mm is not None else 2.0 * geo.worm_length * MM_PER_M
    if r.worm_bearing_span_mm is None:
        warnings.append(
            f"rating.worm_bearing_span_mm not given: taken as 2 x the threaded length = {span:.4g} mm (the mesh "
            "point midway)"
        )
    l1 = l2 = f.add("l1_mm", "l1 = l2", span / 2.0, "mm", "bearing distances from the mesh point", "input")
    i_w = f.add(
        "worm_second_moment_mm4", "I", iso.worm_second_moment_mm4(2.0 * geo.r_f1 * MM_PER_M), "mm^4",
        "worm shaft second moment (1.1 d_f1)", iso.PORT,
    )  # fmt: skip
    d_m = f.add(
        "worm_deflection_mm", "delta_m",
        iso.worm_deflection_mm(l1, l2, f_tm2, gamma, math.atan(mu), geo.alpha_n, e1, i_w), "mm",
        "worm deflection at the mesh", iso.PORT,
    )  # fmt: skip
    d_lim = f.add("deflection_limit_mm", "delta_lim", iso.deflection_limit_mm(m_x), "mm", "0.04 sqrt(m_x)", iso.PORT)
    return f.add("safety_deflection", "S_delta", d_lim / d_m, "-", "delta_lim / delta_m", iso.PORT)


def _temperature(f: Factors, r: Rating, a, n1, d1, t2, u, eta) -> tuple:
    """Losses and oil sump temperature (splash lubrication, AGMA housing heat balance): returns (theta_S, S_T)."""
    p_v0 = f.add("idle_loss_w", "P_V0", iso.idle_loss_w(a, n1), "W", "no-load loss", iso.PORT)
    p_vd = f.add("seal_loss_w", "P_VD", 2.0 * iso.seal_loss_w(d1, n1), "W", "two worm shaft seals", iso.PORT)
    p_vz = f.add("mesh_loss_w", "P_Vz", iso.mesh_loss_w(t2, n1, u, eta), "W", "mesh loss at T2", iso.PORT)
    c_in = a * agma.IN_PER_MM
    area = f.add(
        "housing_area_m2", "A", agma.housing_area_min_in2(c_in) * 6.4516e-4, "m^2",
        "housing area, AGMA least area 43.2 C^1.7 in^2", agma.SHIGLEY,
    )  # fmt: skip
    h_cr = f.add(
        "heat_transfer_w_m2k", "h_CR", agma.heat_transfer_coefficient(n1) * agma.HEAT_TRANSFER_SI, "W/(m^2 K)",
        "housing heat transfer, no fan", agma.SHIGLEY,
    )  # fmt: skip
    if r.oil_sump_temperature_c is not None:
        theta_s = f.add(
            "oil_temperature_c", "theta_S", r.oil_sump_temperature_c, "C",
            "oil temperature as given (injection lubrication)", "rating.oil_sump_temperature_c (input)",
        )  # fmt: skip
    else:
        theta_s = f.add(
            "oil_temperature_c", "theta_S", agma.sump_temperature_c(r.ambient_c, p_v0 + p_vd + p_vz, h_cr, area), "C",
            "oil sump temperature, splash lubrication", agma.SHIGLEY,
        )  # fmt: skip
    theta_lim = f.add(
        "theta_slim_c", "theta_Slim", THETA_SLIM_C[r.lubricant], "C", "permissible sump temperature", iso.PORT
    )
    return theta_s, f.add("safety_temperature", "S_T", theta_lim / theta_s, "-", "theta_Slim / theta_S", iso.PORT)


def _agma(out: dict, f: Factors, geo, n1: float, t2: float, r: Rating, mat: WheelMaterial, warnings: list[str]):
    """AGMA 6034 allowable tangential force, friction and efficiency (bronze wheels only)."""
    d1_in = 2.0 * geo.r_m1 * MM_PER_M * agma.IN_PER_MM  # the worm's mean diameter d_m1 (d1 unshifted)
    d2_in = geo.d2 * MM_PER_M * agma.IN_PER_MM
    c_in = geo.a * MM_PER_M * agma.IN_PER_MM
    v_s = f.add(
        "agma_sliding_speed_ft_min", "V_s", agma.sliding_speed_ft_min(d1_in, n1, geo.gamma_m), "ft/min",
        "sliding speed", agma.SHIGLEY,
    )  # fmt: skip
    fr = out["agma_friction"] = f.add("agma_friction", "f", agma.friction(v_s), "-", "friction", agma.SHIGLEY)
    out["agma_efficiency"] = f.add(
        "agma_efficiency", "e_W", agma.efficiency_worm_driving(geo.alpha_n, geo.gamma_m, fr), "-",
        "efficiency, worm driving", agma.SHIGLEY,
    )  # fmt: skip
    if mat.kind not in ("bronze", "al_bronze"):
        warnings.append(
            f"agma_rated_tangential_force_n not given: AGMA 6034's materials factor C_s is for bronze wheels, not "
            f"{mat.name}"
        )
        return
    m_g = geo.ratio
    if m_g <= 3.0:
        warnings.append(f"AGMA ratio factor C_m is defined for m_G > 3; m_G = {m_g:g} takes the value at 3")
    c_s = f.add(
        "agma_c_s", "C_s", agma.materials_factor(r.wheel_casting, d2_in, c_in), "-",
        f"materials factor ({r.wheel_casting} cast)", agma.SHIGLEY,
    )  # fmt: skip
    c_m = f.add("agma_c_m", "C_m", agma.ratio_factor(m_g), "-", "ratio correction factor", agma.SHIGLEY)
    c_v = f.add("agma_c_v", "C_v", agma.velocity_factor(v_s), "-", "velocity factor", agma.SHIGLEY)
    f_e = f.add(
        "agma_f_e_in", "F_e", agma.effective_face_width_in(geo.face_width * MM_PER_M * agma.IN_PER_MM, d1_in), "in",
        "effective face width", agma.SHIGLEY,
    )  # fmt: skip
    w_t = agma.rated_tangential_force_lbf(c_s, d2_in, f_e, c_m, c_v) * agma.LBF_IN_N
    out["agma_rated_tangential_force_n"] = f.add(
        "agma_rated_tangential_force_n", "W_t", w_t, "N", "AGMA allowable wheel tangential force", agma.SHIGLEY
    )
    f.add(
        "agma_load_ratio", "W_t / F_t2", w_t / (2.0 * t2 / geo.d2), "-",
        "allowable over rated tangential force (> 1: within AGMA's rating)", agma.SHIGLEY,
    )  # fmt: skip


def _finish(out: dict, f: Factors, inputs: dict, warnings: list[str]) -> dict:
    out["warnings"] = warnings
    out["sources"] = f.sources
    out["inputs"] = inputs
    out["factors"] = f.rows
    return out
