"""The reference of every summary.json key: unit, meaning, sign convention and the levels that write it.

One table (KEYS) that the run writer checks each summary against (wormsim.run: a key without an entry is named on
stderr) and that docs/outputs.md is generated from (`python -m tools.outputs_doc > docs/outputs.md`; a test keeps the
file
current). A level that writes a new key adds its entry here.

Force sign convention (FORCE_SIGNS), the same in summary.json, the time series (timeseries.npz), report.png and
recording.rrd: the force the worm exerts on the wheel, resolved at the pitch point on the line of centres in the
wheel's directions there (DIN 3975-2 F_t2, F_r2, F_a2).
"""

from __future__ import annotations

from dataclasses import dataclass

ALL = ("wedge", "torsional", "contact3d")
GEAR = ("torsional", "contact3d")
W, T, C = ("wedge",), ("torsional",), ("contact3d",)
GW = ALL  # the gear levels, and wedge when derived from gear: (no wedge: block)

FORCE_SIGNS = {
    "tangential": "F_t2 along the wheel's positive sense of rotation (right-hand rule about the wheel axis +z): "
    "positive when a right-hand worm turning positive drives the wheel (the project's interface contract, geometry "
    "frames)",
    "radial": "F_r2 along the line of centres, positive towards the wheel axis (the separating force of the mesh)",
    "axial": "F_a2 along the wheel axis times -1 for a right-hand worm (+1 left-hand), so that F_a2 = F_t2 "
    "tan(gamma + rho') holds with signs (DIN 3975-2): positive together with F_t2 when the worm drives",
}
FORCE_KEYS = (
    "`tangential_force_mean_n`, `radial_force_mean_n` and `axial_force_mean_n` are F_t2, F_r2 and F_a2 as DIN 3975-2 "
    "defines them at every level: the forces of one contact at the pitch point on the line of centres, F_t2 = 2 T2 / "
    "d2, F_a2 = F_t1 = 2 T1 / d1 and F_r2 = F_t2 tan(alpha_n) cos(rho') / cos(gamma + rho'), the forces a bearing "
    "calculation after DIN 3975 or ISO/TS 14521 takes. Wedge and torsional compute them so. contact3d takes F_t2 "
    "from the resultant contact force's tangential component (its mean is the contact torque over r2), F_r2 from "
    "each contact's force turned about the worm axis onto the line of centres, and F_a2 from the worm torque over "
    "r1. The 3D contacts sit around the worm at angles phi about its axis (force-weighted |phi| about 28 deg on the "
    "seeds) and above the worm's pitch radius, where the lead angle is smaller: the resultant contact force's "
    "radial component is below DIN's F_r2 by about <cos phi> (about 10 %) and its axial component below "
    "T1 / r1 (5-8 % on the seeds). Those resultant components, the forces on the wheel's own bearings, are "
    "`radial_force_resultant_mean_n` and `axial_force_resultant_mean_n` (contact3d only); with a `shafts:` block "
    "the bearing keys follow the resultant"
)
SIGN_NOTE = (
    "The time series `tangential_force_n`, `radial_force_n`, `axial_force_n` (and contact3d's "
    "`radial_force_line_of_centres_n`), the report's force panel and the recording's `/series/` carry these signs. "
    "The summary's `*_force_mean_n` are the magnitudes of the steady-window means of those series: in a forward run "
    "(the worm drives, positive speed) the series' means are positive and equal the summary's values."
)


@dataclass(frozen=True)
class Key:
    unit: str  # "-" dimensionless, "text", "bool", "list", "object"
    levels: tuple[str, ...]
    meaning: str
    sign: str = ""


_F = "see Force signs"
KEYS: dict[str, Key] = {
    # ------------------------------------------------------------------ every run
    "status": Key("text", ALL, '"ok" or "failed" (a failed run writes only the keys up to `steps`)'),
    "message": Key("text", ALL, "why the run failed (empty when ok); the same line as on stderr"),
    "model": Key("text", ALL, "fidelity level: wedge, torsional or contact3d"),
    "scenario": Key("text", ALL, "the scenario's `name`"),
    "wall_time_s": Key("s", ALL, "wall-clock time of the simulation (without writing the files)"),
    "sim_time_s": Key("s", ALL, "simulated time reached"),
    "steps": Key("-", ALL, "integrator steps taken"),
    "warnings": Key(
        "list",
        ALL,
        "results that need care, one line each (also on stderr and in report.png's header; "
        "wormsim.results.run_warnings): a tangential-force fluctuation above half its mean, contact force outside the "
        "wheel flanks, a steady window "
        "of fewer than 5 mesh periods or no meshing line near z1 n1 / 60, a contact pressure above the wheel "
        "material's pitting strength (wedge, torsional: the rating's mean contact stress sigma_Hm), a runaway "
        "(1.5 x the speed command, or a torque drive still accelerating), "
        "power flowing from the wheel into a worm-driven pair (overhauling), a pair that does not turn, a held "
        "back-drive whose worm creeps above 0.1 % of its free speed; a ratio, F_t2, F_r2 or efficiency more than 10 % "
        "from its hand formula; with "
        "`rating:`, the rating's warnings follow (a root stress above its limit among them); empty when none",
    ),
    "ignored_inputs": Key(
        "list",
        ALL,
        "the blocks and keys given that this level does not use, one line each (also printed on stderr); empty "
        "when every input is used",
    ),
    "steady_window_s": Key(
        "s",
        ALL,
        "[t0, t1] of the steady window the means are taken over (gear levels: after the ramps, once the driven "
        "speed settles within 2 %, trimmed to whole mesh periods; wedge: the last 10 % of the run)",
    ),
    # ------------------------------------------------------------------ self-locking and back-driving (every level)
    "self_locking": Key(
        "bool",
        ALL,
        "static self-locking: rho' at rest >= gamma (the load cannot start the pair from standstill); rho' from the "
        "friction at zero sliding speed (friction_static, friction, or the group's rho(0)). Wedge from a wedge: "
        "block: rho = atan(mu) (seed 000)",
    ),
    "self_locking_dynamic": Key(
        "bool",
        ALL,
        "dynamic self-locking: rho' while sliding >= gamma (a back-driven pair brakes itself to rest); rho' from "
        "the mean friction applied over the steady window (wedge: at the steady sliding speed)",
    ),
    "efficiency_backdrive": Key(
        "-",
        ALL,
        "back-driving efficiency tan(gamma - rho') / tan(gamma) with the sliding friction (DIN 3975-2); 0 when "
        "self_locking_dynamic",
    ),
    "locked": Key(
        "bool",
        GEAR,
        "the wheel could not back-drive the self-locking pair (rho' at rest >= gamma): a speed-driven wheel stalled, "
        "the mesh held and the run ended there with status ok (the means are over the run up to then); a "
        "torque-driven wheel held with the worm sliding slower than contact.transition_velocity_m_s over the run's "
        "last fifth; false in every other run (wormsim.physics.locking)",
    ),
    "holding_torque_nm": Key(
        "N m",
        GEAR,
        "with `locked`: the largest |wheel drive torque| the mesh held (a stalled speed drive pushed up to it; a "
        "torque drive's command; what was held, not a breaking limit); null when not locked",
    ),
    "creep_speed_rpm": Key(
        "rpm", GEAR, "with `locked`: the worm's mean |speed| while the wheel was held; null when not locked"
    ),
    "friction_angle_static_deg": Key("deg", ALL, "rho' at rest used for `self_locking`"),
    "friction_angle_dynamic_deg": Key(
        "deg", ALL, "rho' while sliding used for `self_locking_dynamic` and `efficiency_backdrive`"
    ),
    "lead_angle_deg": Key("deg", ALL, "lead angle gamma at the worm reference diameter"),
    "worm_deflection_mesh_um": Key(
        "um",
        C,
        "shafts: the worm axis's displacement at the mesh point across the axis, the magnitude of its mean "
        "over the steady window (wormsim.contact3d.shafts)",
    ),
    "worm_deflection_mesh_max_um": Key("um", C, "shafts: the largest worm axis displacement at the mesh point"),
    "worm_bearing_radial_mean_n": Key(
        "list",
        C,
        "shafts: the worm bearings' radial forces [N], one per bearing (bearings_mm order), the magnitude "
        "of the mean force vector over the steady window",
    ),
    "worm_bearing_radial_max_n": Key("list", C, "shafts: the worm bearings' largest radial forces [N]"),
    "worm_bearing_axial_mean_n": Key("N", C, "shafts: the worm's locating bearing's axial force, |mean|"),
    "worm_bearing_axial_max_n": Key("N", C, "shafts: the worm's locating bearing's largest axial force"),
    "wheel_deflection_mesh_um": Key(
        "um",
        C,
        "shafts: the wheel axis's displacement at the mesh point across the axis, the magnitude of its mean "
        "over the steady window (wormsim.contact3d.shafts)",
    ),
    "wheel_deflection_mesh_max_um": Key("um", C, "shafts: the largest wheel axis displacement at the mesh point"),
    "wheel_bearing_radial_mean_n": Key(
        "list",
        C,
        "shafts: the wheel bearings' radial forces [N], one per bearing (bearings_mm order), the magnitude "
        "of the mean force vector over the steady window",
    ),
    "wheel_bearing_radial_max_n": Key("list", C, "shafts: the wheel bearings' largest radial forces [N]"),
    "wheel_bearing_axial_mean_n": Key("N", C, "shafts: the wheel's locating bearing's axial force, |mean|"),
    "wheel_bearing_axial_max_n": Key("N", C, "shafts: the wheel's locating bearing's largest axial force"),
    "contact_stress_mean_iso_mpa": Key(
        "MPa", C, "rating: ISO/TS 14521 method B mean contact stress sigma_Hm with p_m* (docs/rating.md)"
    ),
    "friction_iso": Key("-", C, "rating: mean tooth friction mu_zm = mu_0T Y_S Y_G Y_W Y_R (ISO/TS 14521 method B)"),
    "efficiency_iso": Key("-", C, "rating: the mesh efficiency of method B from friction_iso, worm driving"),
    "sliding_speed_m_s": Key("m/s", C, "rating: sliding speed v_g at the reference diameter"),
    "safety_pitting": Key("-", C, "rating: pitting safety S_H (method B)"),
    "safety_wear": Key("-", C, "rating: wear safety S_W (given only with rating.wear_intensity)"),
    "safety_root": Key("-", C, "rating: tooth root safety S_F from tau_F (method B)"),
    "safety_deflection": Key("-", C, "rating: worm deflection safety S_delta = 0.04 sqrt(m_x) / delta_m"),
    "safety_temperature": Key("-", C, "rating: temperature safety S_T (sump temperature limit over oil_temperature_c)"),
    "oil_temperature_c": Key(
        "degC",
        C,
        "rating: oil temperature at the rated load: splash-lubrication heat balance, or rating.oil_sump_temperature_c",
    ),
    "agma_rated_tangential_force_n": Key(
        "N", C, "rating: AGMA 6034 rated tangential force W_t = C_s D_m^0.8 F_e C_m C_v"
    ),
    "agma_friction": Key("-", C, "rating: AGMA 6034 friction coefficient at the sliding speed"),
    "agma_efficiency": Key("-", C, "rating: AGMA 6034 efficiency, worm driving"),
    "sources": Key("list", C, "rating: the public sources of the rating's formulas and tables"),
    "root_stress_max_mpa": Key(
        "MPa",
        C,
        "rating.root_stress fe: the largest max principal stress at the wheel tooth's root fillet over the positions",
    ),
    "root_stress_range_mpa": Key(
        "MPa", C, "rating.root_stress fe: the range of the root stress over the mesh cycle (fatigue)"
    ),
    "safety_pitting_sim": Key(
        "-", C, "rating: sigma_HG over the simulated mean Hertz pressure times sqrt(K_A) (method C)"
    ),
    "safety_root_sim": Key(
        "-",
        C,
        "rating.root_stress fe: the root stress limit over root_stress_max_mpa (rating.root_stress_limit_mpa, else "
        "2 tau_FlimT of the wheel material)",
    ),
    "backdrive_measured_self_locking": Key(
        "bool",
        C,
        "simulation.backdrive_probe: the wheel, speed-driven at the run's wheel speed, could not turn the worm "
        "(loaded with T2 efficiency_backdrive / ratio): the lock guard stopped it, or the worm turned below half "
        "the wheel command times the ratio",
    ),
    "backdrive_measured_efficiency": Key(
        "-", C, "simulation.backdrive_probe: worm power out / wheel power in of the back-driven run (0 when locked)"
    ),
    "backdrive_measured_message": Key("text", C, "simulation.backdrive_probe: the lock diagnosis or the worm speed"),
    "backdrive_probe_wheel_speed_rpm": Key("rpm", C, "simulation.backdrive_probe: the wheel's speed command"),
    "backdrive_probe_worm_torque_nm": Key("N m", C, "simulation.backdrive_probe: the worm's load torque"),
    # ------------------------------------------------------------------ gear levels: drive
    "ratio": Key(
        "-",
        GW,
        "mean worm speed / mean wheel speed over the steady window (from the angle increments); null when the pair "
        "does not turn (power_flow none)",
    ),
    "ratio_theory": Key("-", GW, "z2 / z1"),
    "tangential_force_mean_n": Key("N", GW, "F_t2 on the wheel, magnitude of its steady-window mean", _F),
    "tangential_force_p2p_n": Key("N", GW, "peak-to-peak (max - min) of F_t2 over the steady window", _F),
    "tangential_force_theory_n": Key("N", GW, "T_load / r2 (DIN 3975-2); null when the load is on the worm"),
    "radial_force_mean_n": Key(
        "N",
        GW,
        "F_r2 as DIN 3975-2 defines it (see Force keys), magnitude of its steady-window mean; contact3d: each "
        "contact's force turned about the worm axis onto the line of centres",
        _F,
    ),
    "axial_force_mean_n": Key(
        "N",
        GW,
        "F_a2 as DIN 3975-2 defines it, F_a2 = F_t1 = 2 T1 / d1 (see Force keys), magnitude of its steady-window mean; "
        "contact3d: worm_torque_mean_nm / r1",
        _F,
    ),
    "radial_force_resultant_mean_n": Key(
        "N",
        C,
        "the resultant contact force's component along the line of centres, magnitude of its steady-window mean: "
        "what the wheel's bearings carry radially (see Force keys)",
        _F,
    ),
    "axial_force_resultant_mean_n": Key(
        "N",
        C,
        "the resultant contact force's component along the wheel axis, magnitude of its steady-window mean: what "
        "the wheel's locating bearing carries (see Force keys)",
        _F,
    ),
    "worm_torque_mean_nm": Key("N m", GW, "magnitude of the mean torque applied to the worm shaft (drive or load)"),
    "wheel_torque_mean_nm": Key("N m", GW, "magnitude of the mean torque applied to the wheel shaft (drive or load)"),
    "worm_speed_mean_rpm": Key("rpm", GW, "mean worm speed over the steady window (angle increment / time)"),
    "wheel_speed_mean_rpm": Key("rpm", GW, "mean wheel speed over the steady window (angle increment / time)"),
    "efficiency": Key(
        "-",
        GW,
        "output power / input power, means over the steady window, in the direction of `power_flow` (an overhauling "
        "load that drives a worm-driven pair: worm power out / wheel power in, and the run warns); null when the "
        "pair does not turn",
    ),
    "power_flow": Key(
        "text",
        GW,
        '"worm to wheel", "wheel to worm" (back-driving, or an overhauling load) or "none" (a shaft slower than '
        "0.01 rpm at the worm: ratio, efficiency and efficiency_theory are null, and the run warns)",
    ),
    "efficiency_theory": Key(
        "-",
        GW,
        "tan(gamma) / tan(gamma + rho') (tan(gamma - rho') / tan(gamma) back-driving), rho' = atan(mu / cos "
        "alpha_n) with `friction_coefficient_mean` (DIN 3975-2)",
    ),
    "friction_coefficient_mean": Key("-", GW, "mean Coulomb coefficient mu applied over the steady window"),
    "friction": Key("text", GW, "the friction law used (constant, static -> dynamic, or a seed 000 group)"),
    "transmission_error_p2p_urad": Key(
        "urad", GEAR, "peak-to-peak of the loaded transmission error theta2 - theta1 z1 / z2 over the steady window"
    ),
    "wheel_speed_fluctuation": Key("-", GEAR, "wheel speed peak-to-peak / mean wheel speed over the steady window"),
    "wheel_speed_std_rpm": Key("rpm", GEAR, "standard deviation of the wheel speed samples over the steady window"),
    # ------------------------------------------------------------------ gear levels: meshing frequency
    "mesh_frequency_hz": Key(
        "Hz",
        GEAR,
        "the meshing line: the largest peak of the meshing signal's spectrum over the steady window within +-25 % of "
        "z1 n1 / 60 (n1 the measured mean worm speed; contact3d: F_t2, torsional: see mesh_frequency_source), "
        "refined on the continuous spectrum; never a meshing harmonic or the contact mode's ringing, which lie "
        "outside the band (wormsim.results.metrics.mesh_line). A window of fewer than 5 mesh periods warns",
    ),
    "mesh_frequency_theory_hz": Key("Hz", GW, "z1 n1 / 60 with n1 the mean worm speed"),
    "mesh_frequency_resolution_hz": Key(
        "Hz", GEAR, "FFT bin width 1 / T_window: the lines of a window of few mesh periods are this wide or wider"
    ),
    "mesh_frequency_line_found": Key(
        "bool",
        GEAR,
        "the band's largest value is an interior peak; false: it sits at the band's edge, no meshing line near "
        "z1 n1 / 60 (the run warns)",
    ),
    "steady_window_mesh_cycles": Key(
        "-", GEAR, "mesh periods in the steady window, T_window z1 n1 / 60 (fewer than 5: the run warns)"
    ),
    **{
        f"tangential_force_harmonic{k}_n": Key(
            "N", GEAR, f"amplitude of F_t2 at {k} x mesh_frequency_hz over the steady window (Hann window)"
        )
        for k in range(1, 5)
    },
    **{
        f"transmission_error_harmonic{k}_urad": Key(
            "urad", GEAR, f"amplitude of the transmission error at {k} x mesh_frequency_hz over the steady window"
        )
        for k in range(1, 5)
    },
    "mesh_frequency_source": Key("text", T, "the signal the torsional meshing frequency is taken from"),
    "mesh_frequency_radial_hz": Key("Hz", C, "the meshing line of F_r2, the same search"),
    "force_peak_full_band_hz": Key("Hz", GEAR, "dominant FFT peak of F_t2 over the whole band"),
    "teeth_in_contact_mean": Key("-", GEAR, "mean number of wheel teeth in contact"),
    # ------------------------------------------------------------------ contact3d: contacts and forces
    "contacts_mean": Key("-", C, "mean number of MuJoCo contacts between worm and wheel"),
    "max_penetration_um": Key("um", C, "largest contact penetration over the steady window"),
    "radial_force_theory_n": Key("N", C, "F_r2 = |F_t2| tan(alpha_n) cos(rho') / cos(gamma + rho') (DIN 3975-2)"),
    "worm_contact_radius_mean_m": Key("m", C, "force-weighted mean radius of the contacts on the worm"),
    "efficiency_theory_at_contact_radius": Key(
        "-", C, "efficiency_theory with the lead angle at worm_contact_radius_mean_m instead of r1"
    ),
    "startup_time_s": Key("s", C, "end of the drive and load ramps"),
    "startup_tangential_force_peak_n": Key("N", C, "largest |F_t2| sample up to the steady window"),
    "startup_penetration_max_um": Key("um", C, "largest penetration up to the steady window"),
    "tangential_force_max_n": Key("N", C, "largest |F_t2| sample over the steady window"),
    # ------------------------------------------------------------------ contact3d: pattern and Hertz stress
    "contact_pattern_centroid_face_mm": Key(
        "mm",
        GEAR,
        "centroid of the contact pattern along the wheel axis, 0 at the mid-plane (contact3d flanks: loaded; "
        "torsional with errors: kinematic)",
    ),
    "contact_pattern_centroid_radius_mm": Key("mm", GEAR, "centroid of the contact pattern, radius on the wheel"),
    "contact_pattern_extent_face_mm": Key("mm", GEAR, "width of the contact pattern across the face"),
    "contact_pattern_source": Key("text", GEAR, "loaded (contact3d flanks) or kinematic (marking film) pattern"),
    "contact_pressure_max_mpa": Key(
        "MPa",
        C,
        "largest Hertz line-contact pressure over the steady window (flanks): the peak of the line load averaged over "
        "one axial module of contact line, not one slice's contact (wormsim.tooth.hertz (4); docs/contact3d.md)",
    ),
    "contact_pressure_mean_mpa": Key("MPa", C, "mean Hertz pressure of the loaded contact lines (flanks)"),
    "contact_pressure_max_face_mm": Key(
        "mm",
        C,
        "face position of the largest pressure (0 at the mid-plane; the slice at the averaging window's centre)",
    ),
    "contact_pressure_max_radius_mm": Key("mm", C, "wheel radius of the largest pressure"),
    # ------------------------------------------------------------------ contact3d: what the run used
    "timestep_s": Key("s", GEAR, "integrator step used (torsional: the output/solver step)"),
    "timestep_stable_limit_s": Key("s", C, "stability limit of the contact law's stiffness with the shaft inertias"),
    "timestep_source": Key("text", C, "where timestep_s comes from (scenario or the documented default)"),
    "worm_turn_per_step_max_rad": Key("rad", C, "largest worm rotation in one step"),
    "speculative": Key("bool", C, "simulation.speculative used"),
    "resolution": Key("text", C, "simulation.resolution used"),
    "integrator": Key("text", C, "MuJoCo integrator used"),
    "record_every": Key("-", C, "steps per stored sample"),
    "contact_pair_stiffness_n_per_m": Key("N/m", C, "stiffness of one contact pair of the contact law"),
    "contact_stiffness_source": Key("text", C, "teeth, scenario or hertz (as mesh_stiffness_source)"),
    "contact_exponent_reported": Key("-", C, "contact law exponent e"),
    "contacts_per_pair_ref": Key("-", C, "contacts per tooth pair the stiffness is divided over"),
    "contact_damping_requested_n_s_per_m": Key("N s/m", GEAR, "contact.damping_n_s_per_m as given (or its default)"),
    "contact_damping_used_n_s_per_m": Key("N s/m", GEAR, "damping applied (capped at a damping ratio)"),
    "contact_damping_ratio": Key("-", GEAR, "damping used / critical damping of the mesh mode"),
    "friction_impratio": Key("-", C, "MuJoCo impratio used for the friction cone"),
    "window_teeth": Key("-", C, "wheel teeth modelled around the mesh"),
    "collision_geoms": Key("-", C, "MuJoCo collision geoms (0 with contact.geometry flanks)"),
    "contact_geometry": Key("text", C, "flanks or pieces"),
    "flank_slices": Key("-", C, "face slices per flank (flanks; null for pieces)"),
    "flank_contacts": Key("text", C, "slice, tooth or N (contacts per tooth flank; flanks; null for pieces)"),
    "step_wall_us": Key("us", C, "wall time per step"),
    "piece_error_um": Key("object", C, "deviation of the convex pieces from the exact flanks (max, rms, ...)"),
    "mass_scaling": Key("-", C, "inertia factor applied (1 = off)"),
    "mass_scaling_requested": Key("-", C, "simulation.mass_scaling as given (a number or auto)"),
    "kinetic_energy_share": Key("-", C, "kinetic energy / drive work over the steady window (measured)"),
    "kinetic_energy_share_estimate": Key("-", C, "the same, estimated before the run"),
    "mass_scaling_mesh_mode_hz": Key("Hz", C, "mesh mode frequency with the scaled inertias"),
    # ------------------------------------------------------------------ errors: kinematic TCA (torsional, contact3d)
    "transmission_error_kinematic_p2p_urad": Key("urad", GEAR, "unloaded transmission error p2p (with errors:)"),
    "transmission_error_kinematic_flank": Key("text", GEAR, "flank the kinematic TE rides on (forward / reverse)"),
    "transmission_error_kinematic_samples": Key("-", GEAR, "worm angles analysed"),
    "transmission_error_kinematic_period_deg": Key("deg", GEAR, "worm angle over which the errors repeat"),
    "backlash_measured_mm": Key("mm", GEAR, "smallest circumferential play at the reference circle (with errors:)"),
    "backlash_measured_mean_mm": Key("mm", GEAR, "mean play over the analysed angles"),
    "backlash_measured_max_mm": Key("mm", GEAR, "largest play over the analysed angles"),
    # ------------------------------------------------------------------ torsional
    "mesh_deflection_mean_um": Key("um", T, "mean mesh deflection along the line of action"),
    "solver": Key("text", T, "time integration used"),
    "solver_rhs_evaluations": Key("-", T, "right-hand-side evaluations"),
    "solve_wall_s": Key("s", T, "wall time of the time integration"),
    "mesh_stiffness_wall_s": Key("s", T, "wall time of the tooth contact analysis"),
    "worm_inertia_kg_m2": Key("kg m^2", T, "worm shaft inertia used"),
    "wheel_inertia_kg_m2": Key("kg m^2", T, "wheel shaft inertia used"),
    "inertia_source": Key("text", T, "how the inertias are estimated"),
    "mesh_natural_frequency_hz": Key("Hz", T, "natural frequency of the mesh mode"),
    "drive_kv_nm_s": Key("N m s", T, "speed servo gain of a speed-driven shaft (null for a torque drive)"),
    "drive_peak_torque_nm": Key(
        "N m",
        GEAR,
        "the speed drive's peak torque where it is enforced, a wheel back-driving a pair that self-locks at rest: 3 x "
        "its rated torque, the expected torque at the full load plus the start-up ramp's acceleration torque "
        "(wormsim.physics.gear_theory.servo_peak_torque_nm); the servo pushes no harder. Null elsewhere (an unlimited "
        "speed servo, a torque drive) and for a step command (drive.ramp_s 0)",
    ),
    "backlash_angle_rad": Key("rad", T, "wheel-angle play of the mesh"),
    "mesh_stiffness_samples": Key("-", T, "k(theta) samples per mesh cycle"),
    "mesh_stiffness_source": Key(
        "text",
        GEAR,
        "where the tooth pair's stiffness comes from: teeth (the teeth's compliance, bending and contact flattening: "
        "the default), scenario (contact.stiffness_n_per_m, an override) or hertz (contact.stiffness_model: hertz)",
    ),
    "mesh_stiffness_mean_n_per_m": Key(
        "N/m",
        GEAR,
        "mean mesh stiffness over a mesh cycle along the line of action at r2 cos(alpha_n) cos(gamma) (the TCA with "
        "the run's stiffness per contact length; with the teeth's: bending included)",
    ),
    "mesh_stiffness_per_width_n_per_mm_um": Key(
        "N/(mm um)", GEAR, "mesh_stiffness_mean_n_per_m per mm of face width b2 (ISO 6336-1's unit of c_gamma)"
    ),
    "transmission_error_loaded_p2p_urad": Key(
        "urad",
        GEAR,
        "loaded transmission error p2p over a mesh cycle from the loaded tooth contact analysis of the teeth's "
        "compliance at the working wheel torque on the working flank (quasi-static; null unless "
        "mesh_stiffness_source is teeth, and with errors:)",
    ),
    "load_share_max": Key(
        "-",
        GEAR,
        "largest share of the load on one wheel tooth over a mesh cycle, from the same loaded tooth contact analysis "
        "(null unless mesh_stiffness_source is teeth, and with errors:)",
    ),
    "mesh_stiffness_min_n_per_m": Key("N/m", T, "smallest mesh stiffness over a mesh cycle"),
    "mesh_stiffness_max_n_per_m": Key("N/m", T, "largest mesh stiffness over a mesh cycle"),
    "contact_line_length_mean_mm": Key("mm", T, "mean total contact line length"),
    "mesh_stiffness_loaded_tca_mean_n_per_m": Key("N/m", T, "mean secant stiffness of the loaded TCA (with errors:)"),
    "loaded_tca_wall_s": Key("s", T, "wall time of the loaded TCA (with errors:)"),
    # ------------------------------------------------------------------ wedge (seed 000)
    "speed_steady_m_s": Key("m/s", W, "worm pitch-line speed x1' over the steady window"),
    "S1_peak_n": Key("N", W, "largest |S1| (internal reduced force on the worm side), signed", "seed 000"),
    "S2_peak_n": Key("N", W, "largest |S2| (internal reduced force on the wheel side), signed", "negative resists"),
    "S1_peak_time_s": Key("s", W, "time of S1_peak_n"),
    "S2_peak_time_s": Key("s", W, "time of S2_peak_n"),
    "S1_steady_n": Key("N", W, "mean S1 over the steady window"),
    "S2_steady_n": Key("N", W, "mean S2 over the steady window", "negative resists"),
    "Kd1": Key("-", W, "dynamic factor |S1 peak| / Ft1 (seed 000)"),
    "Kd2": Key("-", W, "dynamic factor |S2 peak| / Ft2 (seed 000)"),
    "Ft1_n": Key("N", W, "the motor's rated force (wedge.motor.nominal_force_n)"),
    "Ft2_n": Key("N", W, "Ft1 / tan(gamma + rho(Vs_n)) at the rated speed"),
    "efficiency_forward": Key("-", W, "tan(gamma) / tan(gamma + rho) at the steady speed (seed 000)"),
    "efficiency_backward": Key("-", W, "tan(gamma - rho) / tan(gamma); 0 when self-locking at rest (seed 000)"),
    "efficiency_backward_sliding": Key("-", W, "tan(gamma - rho) / tan(gamma) at the steady sliding speed"),
    "efficiency_self_locking": Key("-", W, "tan(rho - gamma) / tan(gamma) when rho > gamma, else 0 (seed 000)"),
    "rho_steady_deg": Key("deg", W, "friction angle at the steady sliding speed"),
    "rho_static_deg": Key("deg", W, "friction angle at rest"),
    "stalled": Key("bool", W, "the drive never moved"),
    "locked_at_end": Key("bool", W, "the pair stands locked at the end"),
    "x1_end_m": Key("m", W, "worm pitch-line travel at the end"),
    "min_speed_m_s": Key("m/s", W, "smallest x1'"),
    "max_speed_m_s": Key("m/s", W, "largest x1'"),
    "regimes": Key("list", W, "regimes visited in order: tractive, inverse, locked, unloaded"),
    "regime_timeline": Key("list", W, "[{regime, start_s, end_s}, ...]"),
    "monitor": Key("text", W, "regime monitor: three_regime or seed"),
    "wedge_source": Key("text", W, "the wedge: block (seed 000) or derived from gear:, drive:, load:"),
    "driving_mass_kg": Key("kg", W, "derived: m1 = I1 / r1^2, the worm shaft reduced to its pitch radius"),
    "driven_mass_kg": Key("kg", W, "derived: m2 = I2 / r2^2, the wheel shaft (and load inertia) at its pitch radius"),
    "motor_peak_force_n": Key("N", W, "derived: peak force of the Kloss curve standing in for the speed drive"),
    "motor_synchronous_speed_m_s": Key("m/s", W, "derived: synchronous pitch-line speed of that curve"),
}


# the time series (timeseries.npz, the recording's /series/): name -> (levels, meaning); the unit is in the name
SERIES: dict[str, tuple[tuple[str, ...], str]] = {
    "t_s": (ALL, "sample time; every series is sampled on it"),
    "worm_angle_rad": (GEAR, "worm rotation about its axis"),
    "wheel_angle_rad": (GEAR, "wheel rotation about its axis"),
    "worm_speed_rpm": (ALL, "worm speed (wedge derived: x1' / r1)"),
    "wheel_speed_rpm": (ALL, "wheel speed (wedge derived: x2' / r2)"),
    "worm_torque_nm": (GEAR, "torque applied to the worm shaft by its drive or load (signed about its axis)"),
    "wheel_torque_nm": (GEAR, "torque applied to the wheel shaft by its drive or load (signed about its axis)"),
    "drive_command": (GEAR, "the drive's command: speed in rad/s or torque in N m, after the STEP ramp"),
    "tangential_force_n": (ALL, "F_t2 on the wheel (Force signs)"),
    "radial_force_n": (ALL, "F_r2 on the wheel (Force signs; wedge derived: from DIN 3975-2)"),
    "axial_force_n": (ALL, "F_a2 on the wheel (Force signs)"),
    "friction_coefficient": (ALL, "Coulomb coefficient mu applied (wedge derived: tan(rho') cos(alpha_n))"),
    "transmission_error_rad": (GEAR, "theta2 - hand theta1 z1 / z2 (loaded)"),
    "teeth_in_contact": (GEAR, "wheel teeth in contact"),
    "contacts": (C, "MuJoCo contacts between worm and wheel (mean over the sample's steps)"),
    "max_penetration_m": (C, "largest contact penetration"),
    "wheel_contact_torque_nm": (C, "contact torque on the wheel about its axis"),
    "worm_power_w": (C, "power into the worm shaft from its drive or load (mean over the sample's steps)"),
    "wheel_power_w": (C, "power into the wheel shaft from its drive or load (mean over the sample's steps)"),
    "tangential_force_abs_max_n": (C, "largest |F_t2| within the sample's steps"),
    "radial_force_line_of_centres_n": (C, "each contact's force turned onto the line of centres, summed (Force signs)"),
    "worm_contact_radius_m": (C, "force-weighted radius of the contacts on the worm"),
    "efficiency_theory_at_contact_radius": (C, "efficiency_theory with the lead angle at the contact radius"),
    "mesh_torque_worm_nm": (T, "torque the mesh puts on the worm"),
    "mesh_deflection_m": (T, "mesh deflection along the line of action"),
    "mesh_stiffness_n_per_m": (T, "mesh stiffness k(theta) used"),
    "transmission_error_kinematic_rad": (T, "unloaded transmission error of the displaced flanks (with errors:)"),
    "x1_m": (W, "worm pitch-line travel"),
    "v1_m_s": (W, "worm pitch-line speed x1'"),
    "a1_m_s2": (W, "worm pitch-line acceleration x1''"),
    "x2_m": (W, "wheel pitch-line travel x1 tan(gamma)"),
    "v2_m_s": (W, "wheel pitch-line speed"),
    "vs_m_s": (W, "sliding speed x1' / cos(gamma)"),
    "F1_n": (W, "motor force on body 1 (worm)"),
    "F2_n": (W, "load force on body 2 (wheel); negative resists"),
    "S1_n": (W, "internal reduced force, worm side (= F_a2)"),
    "S2_n": (W, "internal reduced force, wheel side (= -F_t2)"),
    "rho_deg": (W, "friction angle applied"),
    "regime_code": (W, "0 locked, 1 tractive, 2 inverse, 3 unloaded"),
    "worm_deflection_mesh_x_m": (C, "shafts: the worm axis's displacement at the mesh point along the carrier's x"),
    "worm_deflection_mesh_y_m": (C, "shafts: the worm axis's displacement at the mesh point along the carrier's y"),
    "worm_bearing0_radial_x_n": (C, "shafts: worm bearing 0's radial force, carrier x"),
    "worm_bearing0_radial_y_n": (C, "shafts: worm bearing 0's radial force, carrier y"),
    "worm_bearing1_radial_x_n": (C, "shafts: worm bearing 1's radial force, carrier x"),
    "worm_bearing1_radial_y_n": (C, "shafts: worm bearing 1's radial force, carrier y"),
    "worm_bearing_axial_n": (C, "shafts: the worm's locating bearing's axial force"),
    "wheel_deflection_mesh_x_m": (C, "shafts: the wheel axis's displacement at the mesh point along the carrier's x"),
    "wheel_deflection_mesh_y_m": (C, "shafts: the wheel axis's displacement at the mesh point along the carrier's y"),
    "wheel_bearing0_radial_x_n": (C, "shafts: wheel bearing 0's radial force, carrier x"),
    "wheel_bearing0_radial_y_n": (C, "shafts: wheel bearing 0's radial force, carrier y"),
    "wheel_bearing1_radial_x_n": (C, "shafts: wheel bearing 1's radial force, carrier x"),
    "wheel_bearing1_radial_y_n": (C, "shafts: wheel bearing 1's radial force, carrier y"),
    "wheel_bearing_axial_n": (C, "shafts: the wheel's locating bearing's axial force"),
}


def level_summary(level: str, *parts: dict) -> dict:
    """The one summary builder of every level (wedge, torsional, contact3d): the key groups the level measured from
    its series and values, merged in order (a later group's key replaces an earlier one's), each key checked against
    KEYS: a key without an entry, or whose entry does not name the level, raises KeyError (a level that writes a new
    key adds its entry here first)."""
    out: dict = {}
    for part in parts:
        out.update(part)
    bad = [k for k in out if k not in KEYS or level not in KEYS[k].levels]
    if bad:
        raise KeyError(
            f"{level} summary keys without an entry for {level} in wormsim.results.summary_keys.KEYS: {', '.join(bad)}"
        )
    return out


def undocumented(summary: dict) -> list[str]:
    """The summary's keys without an entry in KEYS (wormsim.run names them on stderr; a test keeps this empty)."""
    return [k for k in summary if k not in KEYS]
