"""The scenario's pydantic schema: the project's interface contract (docs/scenario.md), block by block.

Units are in the key names (`_mm`, `_deg`, `_rpm`, `_nm`, `_n`, `_s`, ...). The schema is the one edge where user
units meet the code: everything downstream reads the validated model and converts once (see `wormsim.physics.units`).

Every model forbids unknown keys, so a misspelt field is an error, not a silent default; a value assigned after
loading is validated too (ScenarioError, one line naming the field: wormsim.scenario.messages).
"""

from __future__ import annotations

from typing import Annotated, Any, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator

from wormsim.exceptions import ScenarioError
from wormsim.scenario.messages import describe_errors, unit_hint


class _Strict(BaseModel):
    """allow_inf_nan=False: every float field refuses .inf / .nan (YAML reads `.inf` as a float).
    validate_assignment: `sc.gear.axial_module_mm = -3` is refused at the assignment (ScenarioError, one line), as
    the same value in a file is."""

    model_config = ConfigDict(extra="forbid", validate_default=True, allow_inf_nan=False, validate_assignment=True)

    def __setattr__(self, name: str, value: Any) -> None:
        before, fields_set = dict(self.__dict__), set(self.__pydantic_fields_set__)
        try:
            super().__setattr__(name, value)
        except ValidationError as err:  # a cross-field rule fails after the field was set: put the block back
            self.__dict__.clear()
            self.__dict__.update(before)
            object.__setattr__(self, "__pydantic_fields_set__", fields_set)
            raise ScenarioError(describe_errors(err, type(self).__name__.lower(), type(self), Scenario)) from None


MODULE_MIN_MM = 0.05  # the finest worm gears have modules of a few tenths of a millimetre
FLANK_CONTACTS_MAX = 64  # contact.flank_contacts as a number: MuJoCo contacts per tooth flank
DEFAULT_FLANK_CONTACTS = 4  # contact.flank_contacts' default (docs/decisions/0049-four-contacts-per-flank-default.md)
PositiveFloat = Annotated[float, Field(gt=0)]
NonNegFloat = Annotated[float, Field(ge=0)]
FrictionGroup = Literal["I", "II", "III"]


# ----------------------------------------------------------------------------- gear, materials


class Gear(_Strict):
    """Worm gear data (DIN 3975 / ISO 1122 names). Exactly one module and one of lead angle / q."""

    profile: Literal["ZA", "ZN", "ZI", "ZK", "ZC"] = Field(
        "ZI",
        description=(
            "flank form (DIN 3975): ZI involute helicoid (seed 003); ZA straight in the axial section; ZN straight in "
            "the normal section; ZK disc with straight sides; ZC disc with a convex arc (Cavex); docs/flank_forms.md"
        ),
    )
    hand: Literal["right", "left"] = Field("right", description="thread hand of the worm")
    worm_starts: int = Field(1, ge=1, le=8, description="z1")
    wheel_teeth: int = Field(..., ge=10, le=200, description="z2")
    normal_module_mm: float | None = Field(
        None, ge=MODULE_MIN_MM, le=50, description="m_n; below 0.05 mm is no gear (a value in metres gets a hint)"
    )
    axial_module_mm: float | None = Field(None, ge=MODULE_MIN_MM, le=50, description="m_x (DIN 3975: m)")
    normal_pressure_angle_deg: float = Field(20.0, ge=5, le=30)
    lead_angle_deg: float | None = Field(None, gt=0, lt=45, description="gamma at the worm reference diameter")
    diameter_quotient: float | None = Field(None, gt=0, le=40, description="q = d1 / m_axial")
    face_width_mm: float | None = Field(
        None,
        gt=0,
        le=2000,
        description=(
            "wheel face width b2; default 0.75 * worm tip diameter (DIN 3975 guide); at most 1.2 worm tip diameters"
        ),
    )
    worm_length_mm: float | None = Field(
        None,
        gt=0,
        le=10000,
        description=(
            "threaded length; default covers the wheel's mesh zone; allowed 1 axial pitch to 4 x that default"
        ),
    )
    backlash_mm: float = Field(
        0.05, ge=0, le=50, description="circumferential, at the wheel reference circle; below 0.4 axial pitch"
    )
    addendum_coef: float = Field(1.0, gt=0, le=1.5, description="h_a / m_axial")
    dedendum_coef: float = Field(1.2, gt=0, le=2.0, description="h_f / m_axial")
    profile_shift_coefficient: float | None = Field(
        None,
        ge=-1.5,
        le=1.5,
        description=(
            "x2, the wheel's profile shift (DIN 3975): a = (d1 + d2) / 2 + x2 m_axial, wheel tip and root move out by "
            "x2 m_axial; the wheel is hobbed at that centre distance; default 0, ZC 0.5 (docs/geometry.md)"
        ),
    )
    wheel_outside_diameter_mm: float | None = Field(
        None,
        gt=0,
        le=20000,
        description="d_e2, the wheel rim's outside diameter; default d_a2 + m_axial; allowed d_a2 to d_a2 + 2 m_axial",
    )
    zn_section: Literal["thread", "space"] = Field(
        "thread", description="ZN: the straight line in the normal section of the thread (ZN1) or of the space (ZN2)"
    )
    tool_diameter_mm: float | None = Field(
        None, gt=0, le=2000, description="ZK, ZC: disc / grinding wheel diameter; default 100 (docs/flank_forms.md)"
    )
    profile_radius_mm: float | None = Field(
        None, gt=0, le=2000, description="ZC: the tool's arc profile radius; default 5.5 m_axial (docs/flank_forms.md)"
    )

    @model_validator(mode="after")
    def _one_of(self) -> "Gear":
        for a, b in (("normal_module_mm", "axial_module_mm"), ("lead_angle_deg", "diameter_quotient")):
            va, vb = getattr(self, a), getattr(self, b)
            if (va is None) == (vb is None):
                given = f"both given ({a} = {va:g}, {b} = {vb:g})" if va is not None else "neither given"
                raise ValueError(f"give exactly one of {a} / {b}: {given}")
        if self.dedendum_coef <= self.addendum_coef:
            raise ValueError("dedendum_coef must exceed addendum_coef (root clearance)")
        module = self.normal_module_mm if self.normal_module_mm is not None else self.axial_module_mm
        if self.face_width_mm is not None and module is not None and self.face_width_mm < module:
            raise ValueError(
                f"gear.face_width_mm = {self.face_width_mm:g}: narrower than one module ({module:g} mm); allowed: "
                f"face_width_mm >= the module{unit_hint('face_width_mm', self.face_width_mm)}"
            )
        return self


class Material(_Strict):
    """One part's material: a given material names all three keys; a part left out takes the default of the
    materials block (steel worm, bronze wheel)."""

    youngs_modulus_gpa: float = Field(..., gt=0, le=1000)
    poisson_ratio: float = Field(..., ge=0, lt=0.5)
    density_kg_m3: float = Field(..., gt=0, le=25000)


class Materials(_Strict):
    """Optional block: left out, or a part left out, takes these defaults (steel worm on a bronze wheel)."""

    worm: Material = Field(
        Material(youngs_modulus_gpa=210, poisson_ratio=0.3, density_kg_m3=7850),
        description="default steel: 210 GPa, 0.3, 7850 kg/m^3",
    )
    wheel: Material = Field(
        Material(youngs_modulus_gpa=100, poisson_ratio=0.34, density_kg_m3=8800),
        description="default tin bronze: 100 GPa, 0.34, 8800 kg/m^3",
    )


# ----------------------------------------------------------------------------- contact, drive, load


class Contact(_Strict):
    """Tooth contact. Every key optional; the stiffness defaults to the teeth's own compliance (docs/models.md,
    'Contact law')."""

    stiffness_n_per_m: float | None = Field(
        None,
        gt=0,
        le=1e13,
        description=(
            "ADAMS IMPACT K: one tooth pair's stiffness (contact line across the face width), an override of the "
            "teeth's computed stiffness, as the seeds' ADAMS penalty constants ran (docs/decisions/"
            "0034-contact-stiffness-override.md); unset: contact.stiffness_model"
        ),
    )
    stiffness_model: Literal["teeth", "hertz"] = Field(
        "teeth",
        description=(
            "without stiffness_n_per_m: teeth (the teeth's bending and the contact flattening, FE influence "
            "coefficients, wormsim.tooth.compliance) | hertz (Hertz line contact pi E* / 4 per length: rigid teeth, "
            "5-7x stiffer)"
        ),
    )
    exponent: float = Field(1.5, ge=1, le=3, description="ADAMS IMPACT e")
    damping_n_s_per_m: float | None = Field(None, ge=0, le=1e10, description="ADAMS IMPACT C")
    penetration_depth_m: float = Field(1e-5, gt=0, le=0.01, description="ADAMS IMPACT d (full damping depth)")
    friction: float | None = Field(None, ge=0, le=1, description="one Coulomb coefficient")
    friction_static: float | None = Field(None, ge=0, le=1)
    friction_dynamic: float | None = Field(None, ge=0, le=1)
    friction_group: FrictionGroup | None = Field(None, description="seed 000 rho(Vs) material group")
    transition_velocity_m_s: float = Field(1e-3, gt=0, le=10, description="static -> dynamic friction blend speed")
    geometry: Literal["flanks", "pieces"] = Field(
        "flanks",
        description=(
            "contact3d: flanks (contacts found on the exact flanks, one per face slice: the working flanks) | pieces "
            "(MuJoCo collides convex pieces: also tips, edges, teeth jumping; slower, facet ripple; docs/contact3d.md)"
        ),
    )
    slices: int | None = Field(
        None,
        ge=2,
        le=256,
        description=(
            "flanks: slices across the face width (default: coarse 8, a quick look; medium from the gear, a slice's "
            "stiffness at most 1/5 of the mesh stiffness's fluctuation, a multiple of 8, at least 32: seat motor, "
            "screw jack and involute_41 32; fine twice medium's; at most 16 with simulation.mass_scaling, which keeps means only; "
            "docs/contact3d.md)"
        ),
    )

    flank_contacts: Literal["tooth", "slice"] | int = Field(
        DEFAULT_FLANK_CONTACTS,
        description=(
            "flanks: the MuJoCo contacts: N (1-64: N per tooth flank, each merging ceil(slices / N) adjacent slices "
            "with their spring resultant, moment arms and friction power; default 4: against per slice means and "
            "efficiency within 0.01 %, F_t p2p within 9 % (4-start-z41 -8.9 %), 0.3-0.9x the CPU per simulated "
            "second) | slice (one per face slice) | tooth (one per tooth flank: F_t p2p up to +32 %); "
            "docs/contact3d.md, 'One contact per tooth flank'"
        ),
    )

    @field_validator("flank_contacts", mode="before")
    @classmethod
    def _flank_contacts(cls, v: Any) -> Any:
        """One message for the three forms (slice, tooth, N)."""
        if v in ("tooth", "slice"):
            return v
        n = v if isinstance(v, int) and not isinstance(v, bool) else None
        if isinstance(v, str) and v.strip().isdigit():
            n = int(v)
        if n is None or not 1 <= n <= FLANK_CONTACTS_MAX:
            raise ValueError(
                f"should be 'slice', 'tooth' or a whole number of contacts per tooth flank, 1-{FLANK_CONTACTS_MAX}"
            )
        return n

    @model_validator(mode="after")
    def _friction(self) -> "Contact":
        given = [
            self.friction is not None,
            self.friction_group is not None,
            self.friction_static is not None or self.friction_dynamic is not None,
        ]
        if sum(given) > 1:
            raise ValueError("give one of friction / friction_group / friction_static+friction_dynamic")
        if (self.friction_static is None) != (self.friction_dynamic is None):
            raise ValueError("friction_static and friction_dynamic go together")
        if (
            self.friction_static is not None
            and self.friction_dynamic is not None
            and self.friction_dynamic > self.friction_static
        ):
            raise ValueError("friction_dynamic must not exceed friction_static")
        if self.geometry == "pieces" and self.slices is not None:
            raise ValueError(
                f"contact.slices = {self.slices} applies to contact.geometry flanks only (pieces: one contact per "
                f"piece pair); allowed: contact.slices unset with contact.geometry pieces"
            )
        return self


class Drive(_Strict):
    on: Literal["worm", "wheel"] = Field("worm", description="driven shaft (wheel = back-driving)")
    speed_rpm: float | None = Field(
        None, gt=-100000, lt=100000, description="speed-controlled drive, STEP ramp from 0 over ramp_s"
    )
    torque_nm: float | None = Field(None, gt=-1e6, lt=1e6, description="torque drive, same STEP ramp")
    ramp_s: float = Field(0.0, ge=0, le=3600, description="STEP ramp time of the drive")

    @model_validator(mode="after")
    def _one_of(self) -> "Drive":
        if (self.speed_rpm is None) == (self.torque_nm is None):
            raise ValueError("give exactly one of speed_rpm / torque_nm")
        return self


class Load(_Strict):
    on: Literal["worm", "wheel"] = Field("wheel", description="loaded shaft (the other one)")
    torque_nm: float = Field(0.0, gt=-1e6, lt=1e6, description="resisting torque")
    start_s: float = Field(0.0, ge=0, le=1e6, description="STEP ramp of the load starts here (may lie past the end)")
    ramp_s: float = Field(0.0, ge=0, le=3600, description="STEP ramp time of the load")
    inertia_kg_m2: float = Field(
        0.0,
        ge=0,
        le=1e6,
        description=("driven-machine inertia rigidly on the loaded shaft (contact3d: joint armature; 0 = bare gear)"),
    )


class Simulation(_Strict):
    duration_s: float = Field(1.0, gt=0, le=3600)
    timestep_s: float | None = Field(
        None, gt=0, le=0.01, description="default documented; the summary states the one used"
    )
    resolution: Literal["coarse", "medium", "fine"] = Field(
        "medium",
        description=(
            "contact3d's level of detail: flanks' slices across the face (coarse 8, medium the convergence rule, fine "
            "twice medium's; docs/contact3d.md) and the pieces' facets"
        ),
    )
    integrator: Literal["implicitfast", "rk4", "euler", "implicit", "discrete"] = "implicitfast"
    record_every: int = Field(
        1,
        ge=1,
        le=100000,
        description=(
            "store every n-th step in the time series (forces, torques and powers: the mean over those n steps)"
        ),
    )
    speculative: bool = Field(
        False,
        description=("contact3d: MuJoCo's speculative contacts (sweep fast geoms over the step against tunnelling)"),
    )
    mesh_stiffness_samples: int = Field(
        64, ge=8, le=4096, description="torsional: k(theta) samples per mesh cycle (tooth contact analysis)"
    )
    backdrive_probe: bool = Field(
        False,
        description=(
            "contact3d, worm driving: after the run, a second run of duration_s with the wheel speed-driven and the "
            "worm loaded, measuring self-locking and the back-driving efficiency (summary backdrive_measured_*)"
        ),
    )
    mass_scaling: Annotated[float, Field(ge=1, le=1e8)] | Literal["auto"] = Field(
        1.0,
        description=(
            "1 <= S <= 1e8 or auto; contact3d, quasi-static runs only: both shafts' inertias (and load.inertia_kg_m2) times this factor, so the "
            "stable timestep grows by its square root; auto: the largest factor that keeps the kinetic energy below 1 % "
            "of the drive's work; 1 = off. Refused for dynamic runs (docs/contact3d.md, 'Mass scaling')"
        ),
    )

    @field_validator("mass_scaling", mode="before")
    @classmethod
    def _scaling(cls, v):
        """One message for both forms (the union would give one per member)."""
        if v == "auto" or (isinstance(v, int | float) and not isinstance(v, bool) and 1 <= v <= 1e8):
            return v
        raise ValueError("allowed: 1 <= simulation.mass_scaling <= 1e8 (1 = off), or auto")


# ----------------------------------------------------------------------------- wedge (seed 000)


class WedgeMotor(_Strict):
    """Kloss induction-motor force curve of seed 000 (forces reduced to the worm pitch radius)."""

    peak_force_n: float = Field(2178.0, gt=0, le=1e8)
    synchronous_speed_m_s: float = Field(7.85, gt=0, le=1000)
    peak_force_speed_m_s: float = Field(6.5, gt=0, le=1000)
    nominal_force_n: float = Field(
        990.0,
        gt=0,
        le=1e8,
        description="rated force Ft1 = M_n / R1 for the dynamic factor Kd1; seed 000: 2178 N / (Mmax/Mn = 2.2)",
    )
    nominal_speed_m_s: float = Field(
        7.59, gt=0, le=1000, description="rated speed n_n R1 (Ft2 uses rho there); seed 000: 2900 rpm at R1 = 25 mm"
    )

    @model_validator(mode="after")
    def _order(self) -> "WedgeMotor":
        if self.peak_force_speed_m_s >= self.synchronous_speed_m_s:
            raise ValueError("peak_force_speed_m_s must be below synchronous_speed_m_s")
        if self.nominal_speed_m_s >= self.synchronous_speed_m_s:
            raise ValueError("nominal_speed_m_s must be below synchronous_speed_m_s")
        return self


class WedgeLoad(_Strict):
    force_n: float = Field(-5000.0, gt=-1e7, lt=1e7, description="F2 on the driven body (negative resists)")
    initial_force_n: float = Field(0.0, gt=-1e7, lt=1e7, description="F2 before start_s; STEP to force_n over ramp_s")
    start_s: float = Field(0.0, ge=0, le=1e6, description="may lie past the end (a load that never starts)")
    ramp_s: float = Field(0.0, ge=0, le=3600)


class Wedge(_Strict):
    lead_angle_deg: float = Field(4.76, gt=0, lt=45)
    driving_mass_kg: float = Field(11.8, gt=0, le=1e6)
    driven_mass_kg: float = Field(100.0, gt=0, le=1e8)
    friction_group: FrictionGroup | None = "III"
    friction: float | None = Field(None, ge=0, le=1, description="constant coefficient; rho = atan(friction)")
    motor: WedgeMotor = WedgeMotor()
    load: WedgeLoad = WedgeLoad()
    monitor: Literal["three_regime", "seed"] = Field(
        "three_regime",
        description="three_regime: tractive/inverse/locked with events; seed: seed 000's literal two-regime switch",
    )
    initial_speed_m_s: float = Field(0.0, ge=0, le=1000)
    rtol: float = Field(1e-8, gt=0, le=1e-2)

    @model_validator(mode="after")
    def _friction(self) -> "Wedge":
        if self.friction is not None and self.friction_group is not None and "friction_group" in self.model_fields_set:
            raise ValueError("give one of friction_group / friction")
        if self.friction is not None:
            object.__setattr__(self, "friction_group", None)  # not a user assignment: no re-validation
        return self


# ----------------------------------------------------------------------------- assembly and manufacturing errors


class Errors(_Strict):
    """Assembly errors and manufacturing deviations of the gear pair, every key 0 by default.
    Their geometry, limits and signs: meshgen.displaced and docs/errors.md. The limits that depend on the gear
    (backlash, tooth depth, face width, threaded length) are checked against the derived geometry (exit 2)."""

    center_distance_mm: float = Field(
        0.0, ge=-100, le=100, description="a - a_nominal; a larger centre distance is positive"
    )
    shaft_angle_deg: float = Field(
        0.0,
        ge=-10,
        le=10,
        description=(
            "deviation of the shaft angle from 90 deg, a rotation of the wheel axis about the line of centres "
            "(right-hand rule about the line from the worm axis to the wheel centre)"
        ),
    )
    wheel_axial_offset_mm: float = Field(
        0.0, ge=-100, le=100, description="the wheel mid-plane off the worm axis, along the wheel axis"
    )
    worm_axial_offset_mm: float = Field(
        0.0, ge=-100, le=100, description="the worm shifted along its own axis (a phase only)"
    )
    wheel_runout_mm: NonNegFloat = Field(
        0.0, le=10, description="eccentricity of the wheel's pitch circle to its axis of rotation"
    )
    wheel_runout_phase_deg: float = Field(
        0.0,
        ge=-360,
        le=360,
        description=(
            "wheel-frame polar angle of the pitch-circle centre, from the line of centres towards the worm at theta2 = 0"
        ),
    )
    worm_runout_mm: NonNegFloat = Field(
        0.0, le=10, description="eccentricity of the worm's thread axis to its axis of rotation"
    )
    wheel_pitch_deviation_um: list[Annotated[float, Field(ge=-10000, le=10000)]] = Field(
        default_factory=list,
        max_length=200,
        description=(
            "per wheel tooth from tooth 0: the tooth shifted along the reference circle, positive in the wheel's positive "
            "sense (single pitch deviation f_pt,k = entry k - entry k-1); missing teeth 0"
        ),
    )

    def is_zero(self) -> bool:
        """No deviation at all (the phase alone, without a runout, is none)."""
        return not (
            self.center_distance_mm
            or self.shaft_angle_deg
            or self.wheel_axial_offset_mm
            or self.worm_axial_offset_mm
            or self.wheel_runout_mm
            or self.worm_runout_mm
            or any(self.wheel_pitch_deviation_um)
        )


# ----------------------------------------------------------------------------- shafts on bearings


class ShaftSupport(_Strict):
    """One shaft on two bearings (wormsim.contact3d.shafts): positions, stiffnesses, the worm's bending."""

    bearings_mm: list[Annotated[float, Field(ge=-10000, le=10000)]] = Field(
        ...,
        min_length=2,
        max_length=2,
        description="the two bearing centres along the shaft axis, from the mesh point (one each side: [-l1, l2])",
    )
    locating_bearing: int = Field(0, ge=0, le=1, description="index of the bearing that takes the axial force")
    radial_stiffness_n_per_um: float | None = Field(
        None, gt=0, le=1e6, description="radial stiffness of each bearing; omitted = rigid"
    )
    axial_stiffness_n_per_um: float | None = Field(
        None, gt=0, le=1e6, description="axial stiffness of the locating bearing; omitted = rigid"
    )
    bending: bool = Field(
        False, description="worm: the shaft bends between the bearings (root-diameter section, worm material)"
    )

    @model_validator(mode="after")
    def _straddle(self) -> "ShaftSupport":
        b0, b1 = self.bearings_mm
        if not b0 < 0 < b1:
            raise ValueError(
                f"bearings_mm = {self.bearings_mm}: one bearing each side of the mesh point; allowed: "
                f"bearings_mm[0] < 0 < bearings_mm[1] (mm along the shaft axis)"
            )
        return self


class Shafts(_Strict):
    """The worm and the wheel on compliant bearings, the worm shaft bending (absent: rigid hinges)."""

    worm: ShaftSupport | None = None
    wheel: ShaftSupport | None = None

    @model_validator(mode="after")
    def _wheel_rigid_section(self) -> "Shafts":
        if self.wheel is not None and self.wheel.bending:
            raise ValueError(
                "shafts.wheel.bending = true: only the worm shaft bends (the wheel's shaft section is not given); "
                "allowed: shafts.wheel.bending = false"
            )
        return self


# ----------------------------------------------------------------------------- rating (wormsim.rating, docs/rating.md)


class Rating(_Strict):
    """Load-capacity rating (`wormsim rate`, and the contact3d summary when given). Every key optional; the formulas,
    tables and their sources: docs/rating.md."""

    life_h: float = Field(25000.0, gt=0, le=1e6, description="required life L_h (ISO/TS 14521 reference 25000 h)")
    application_factor: float = Field(1.0, ge=1, le=4, description="K_A: the nominal wheel torque times this")
    lubricant: Literal["mineral", "pao", "peg"] = Field("mineral", description="oil base: friction, Z_oil, theta_Slim")
    oil_viscosity_40_mm2_s: float = Field(320.0, gt=0, le=10000, description="ISO VG of the oil (reported)")
    oil_viscosity_100_mm2_s: float | None = Field(None, gt=0, le=10000, description="oil viscosity at 100 C (reported)")
    oil_sump_temperature_c: float | None = Field(
        None,
        ge=-60,
        le=250,
        description=(
            "given oil temperature (injection lubrication with a cooler; REXS temperature_lubricant): the rating "
            "uses it for theta_S instead of the splash-lubrication heat balance"
        ),
    )
    wheel_material: Literal["CuSn12Ni2", "CuSn12", "CuAl10Fe5Ni5", "GJS-400", "GJL-250", "POM"] | None = Field(
        None,
        description=(
            "wheel material (table with sources: docs/rating.md); default POM when materials.wheel has E <= 10 GPa, "
            "else CuSn12Ni2 (with a warning)"
        ),
    )
    wheel_pitting_strength_mpa: float | None = Field(
        None,
        gt=0,
        le=5000,
        description=(
            "sigma_HlimT of the wheel instead of rating.wheel_material's (REXS endurance_limit_flank); the material's "
            "other values stay"
        ),
    )
    wheel_casting: Literal["sand", "chilled", "centrifugal"] = Field("sand", description="AGMA C_s casting method")
    ambient_c: float = Field(20.0, ge=-60, le=80, description="ambient temperature theta_0")
    roughness_worm_um: float = Field(0.5, gt=0, le=10, description="worm flank Ra1 (friction factor Y_R)")
    root_stress: Literal["none", "fe"] = Field("none", description="fe: FE root stress of the wheel tooth")
    worm_speed_rpm: float | None = Field(
        None, gt=0, le=100000, description="rated worm speed n1; default |drive speed| (needed for a torque drive)"
    )
    wear_intensity: float | None = Field(
        None,
        gt=0,
        le=1e-3,
        description="J_W (wear intensity; its DIN 3996 table is not public): safety_wear is given only with it",
    )
    worm_bearing_span_mm: float | None = Field(
        None,
        gt=0,
        le=100000,
        description="worm bearing distance l1 + l2, mesh point midway; default 2 x the worm threaded length",
    )
    root_stress_limit_mpa: float | None = Field(
        None,
        gt=0,
        le=10000,
        description=(
            "permissible max principal root stress for safety_root_sim; default 2 tau_FlimT of rating.wheel_material "
            "(Tresca; none for POM)"
        ),
    )
    fe_positions: int = Field(6, ge=1, le=64, description="FE root stress: mesh positions over one mesh cycle")
    fe_mesh_density: int = Field(
        1,
        ge=1,
        le=4,
        description="FE root stress: mesh density d (elements 1.5 m_x / d, fillet rho_f / d; 1 default, 2 the h/2 mesh)",
    )


# ----------------------------------------------------------------------------- scenario


class Scenario(_Strict):
    """A validated scenario (the YAML file as Python objects; units in the key names, docs/scenario.md).

    Blocks: `gear`, `materials`, `contact`, `drive`, `load`, `simulation`, `errors` (gear levels) and `wedge` (seed
    000's reduced model). Build one with load_scenario(path) or Scenario.model_validate(dict); change one with
    attribute assignment (validated) or `sc.model_copy(update=...)` (not validated: prefer load_scenario's
    overrides).
    """

    name: str = Field(..., pattern=r"^[a-z0-9_-]+$", description="case name, used in outputs")
    description: str = Field("", description="free text")
    model: Literal["contact3d", "torsional", "wedge"] = Field(
        "contact3d", description="fidelity level: 3D tooth contact (MuJoCo), 2-DOF torsional, or 1-DOF wedge (seed 000)"
    )
    gear: Gear | None = None
    materials: Materials = Field(
        Materials(), description="optional: steel worm on a bronze wheel when left out (defaults in the block)"
    )
    contact: Contact = Contact()
    drive: Drive | None = None
    load: Load = Load()
    simulation: Simulation = Simulation()
    wedge: Wedge | None = None
    errors: Errors = Errors()
    shafts: Shafts | None = None
    rating: Rating | None = None

    @model_validator(mode="after")
    def _blocks(self) -> "Scenario":
        # torsional and wedge have rigid shafts: a shafts: block is ignored there (ignored_inputs says so)
        if self.shafts is not None and self.model == "contact3d" and self.contact.geometry != "flanks":
            raise ValueError(
                "shafts: the shafts on bearings are modelled by contact3d with contact.geometry flanks; allowed: "
                "model contact3d with contact.geometry flanks, or no shafts: block"
            )
        if self.shafts is not None and self.simulation.mass_scaling != 1:
            raise ValueError(
                f"simulation.mass_scaling = {self.simulation.mass_scaling}: the shafts' masses and bearing modes are "
                f"not scaled; allowed: simulation.mass_scaling = 1 with a shafts: block"
            )
        if self.model != "contact3d" and self.simulation.mass_scaling != 1:
            raise ValueError(
                f"simulation.mass_scaling = {self.simulation.mass_scaling}: only model contact3d scales "
                f"masses (torsional runs the 20 s seat motor in seconds without it); allowed: "
                f"simulation.mass_scaling = 1 with model {self.model}"
            )
        if self.model == "contact3d" and self.simulation.speculative and self.contact.geometry == "flanks":
            raise ValueError(
                "simulation.speculative = true: MuJoCo's speculative contacts act on its collision of convex pieces, "
                "not on the contacts found on the exact flanks; allowed: simulation.speculative = false with "
                "contact.geometry flanks, or contact.geometry pieces"
            )
        if self.simulation.backdrive_probe and (
            self.model != "contact3d" or self.drive is None or self.drive.on != "worm"
        ):
            raise ValueError(
                "simulation.backdrive_probe = true: measures back-driving after a forward contact3d run; allowed: "
                "model contact3d with drive.on worm (a run with drive.on wheel measures it itself; torsional and "
                "wedge state it from rho' and gamma)"
            )
        if self.model == "wedge":
            if self.wedge is None:
                _derivable_wedge(self)
            if not self.errors.is_zero():
                raise ValueError(
                    "errors: the wedge model has no gear geometry to displace; use model: torsional or "
                    "contact3d, or set every errors key to 0"
                )
        else:
            if self.gear is None:
                raise ValueError(f"model: {self.model} needs a gear: block")
            if self.drive is None:
                raise ValueError(f"model: {self.model} needs a drive: block")
            if self.drive.on == self.load.on:
                raise ValueError("drive.on and load.on must name different shafts")
        return self


def _derivable_wedge(sc: "Scenario") -> None:
    """model: wedge without a wedge: block derives the reduced model from gear:, drive:, load: (wormsim.wedge.derive):
    the worm driven at a speed, the load a torque on the wheel."""
    if sc.gear is None or sc.drive is None:
        missing = " and ".join(b for b, v in (("gear:", sc.gear), ("drive:", sc.drive)) if v is None)
        raise ValueError(
            f"model: wedge needs a wedge: block (seed 000's reduced model) or gear: and drive: blocks to derive it "
            f"from; {missing} missing"
        )
    if sc.drive.on != "worm" or sc.drive.speed_rpm is None or sc.drive.speed_rpm <= 0:
        raise ValueError(
            f"model: wedge derived from gear: drives the worm at a speed (its motor is a Kloss curve on the worm); "
            f"given drive.on = {sc.drive.on}"
            + (f", drive.torque_nm = {sc.drive.torque_nm:g}" if sc.drive.torque_nm is not None else "")
            + (f", drive.speed_rpm = {sc.drive.speed_rpm:g}" if sc.drive.speed_rpm is not None else "")
            + "; allowed: drive.on worm with drive.speed_rpm > 0, or model torsional / contact3d"
        )
    if sc.load.on != "wheel":
        raise ValueError("model: wedge derived from gear: loads the wheel; allowed: load.on wheel")


def ignored_inputs(sc: Scenario) -> list[str]:
    """The blocks and keys the user gave that the scenario's level does not use, one line each (wormsim.run prints
    them on stderr and writes them to summary.json `ignored_inputs`)."""
    given = sc.model_fields_set
    out = []
    if sc.model == "wedge" and sc.wedge is not None:
        blocks = [b for b in ("gear", "drive", "load", "contact", "materials") if b in given]
        if blocks:
            out.append(
                f"{', '.join(b + ':' for b in blocks)} ignored: the wedge: block gives the whole reduced model "
                "(remove wedge: to derive it from gear:, drive:, load:)"
            )
    elif sc.model == "wedge":
        rigid = [f"contact.{k}" for k in WEDGE_IGNORES_CONTACT if k in sc.contact.model_fields_set]
        if sc.gear is not None and "backlash_mm" in sc.gear.model_fields_set:
            rigid.append("gear.backlash_mm")
        if rigid:
            out.append(f"{', '.join(rigid)} ignored: the wedge is rigid and without backlash")
        if sc.drive is not None and sc.drive.ramp_s > 0:
            out.append(
                f"drive.ramp_s = {sc.drive.ramp_s:g} ignored: the derived wedge starts its Kloss motor curve at once"
            )
    elif sc.wedge is not None:
        out.append(f"wedge: ignored: model {sc.model} uses gear:, drive:, load:")
    if sc.shafts is not None and sc.model != "contact3d":
        out.append(f"shafts: ignored: model {sc.model} has rigid shafts (the shafts on bearings run at contact3d)")
    if sc.model != "wedge" or sc.wedge is None:
        by_level: dict[tuple[str, ...], list[str]] = {}
        for k, levels in LEVEL_KEYS.items():
            block, key = k.split(".")
            reported = sc.model == "wedge" and block == "contact"  # named above with the rigid wedge
            if sc.model not in levels and not reported and key in getattr(sc, block).model_fields_set:
                by_level.setdefault(levels, []).append(k)
        for levels, keys in by_level.items():
            out.append(f"{', '.join(keys)} ignored: used by model {' / '.join(levels)} only")
    return out


# keys only some levels use (given at another level, the run names them)
LEVEL_KEYS: dict[str, tuple[str, ...]] = {
    "contact.geometry": ("contact3d",),
    "contact.slices": ("contact3d",),
    "contact.flank_contacts": ("contact3d",),
    "contact.exponent": ("contact3d",),
    "simulation.resolution": ("contact3d",),
    "simulation.integrator": ("contact3d",),
    "simulation.speculative": ("contact3d",),
    "simulation.record_every": ("contact3d",),
    "simulation.mesh_stiffness_samples": ("torsional",),
}


WEDGE_IGNORES_CONTACT = (
    "stiffness_n_per_m",
    "stiffness_model",
    "exponent",
    "damping_n_s_per_m",
    "penetration_depth_m",
    "geometry",
    "slices",
    "flank_contacts",
)


def json_schema() -> dict:
    return Scenario.model_json_schema()
