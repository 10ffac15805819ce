"""The contact3d MuJoCo model: worm + wheel on one hinge each, coupled only through tooth contact.

Built with mujoco.MjSpec from the template `models/worm_pair.xml` (see models/README.md):

- bodies in the assembly frame of docs/geometry.md (wheel axis z through the origin, worm axis parallel
  to x at y = -a), placed by meshgen.assembly; one hinge each, no gear or equality constraint;
- collision geoms: meshgen's convex pieces (meshgen.pieces). All worm pieces; for the wheel only an
  ACTIVE WINDOW of `window_teeth` tooth slots around the line of centres, which wormsim.contact3d.runner
  re-poses by whole pitches as the wheel turns (tooth k lives in slot k mod W), so the cost does not
  grow with z2. Contype/conaffinity let worm pieces meet wheel pieces only;
- visual-only geoms: the smooth watertight meshes (whole worm, whole wheel); with contact.geometry flanks a
  cylinder of each part's tip radius and length stands in (the flank contacts' geoms; no run reads the mesh);
- inertias: axial moments of the visual meshes times the materials' densities (trimesh mass
  properties; a solid cylinder r_f..r_a as a fallback if a mesh is not watertight);
- drive: speed -> `velocity` actuator (kv chosen for a 0.1 % speed droop at the expected torque, integrated
  implicitly by implicitfast), torque -> `motor`; the command follows ADAMS STEP over drive.ramp_s;
- load: `motor` on the other shaft, resisting (sign opposite to the expected motion), STEP from
  load.start_s over load.ramp_s; a driven-machine inertia load.inertia_kg_m2 is the loaded hinge's armature
  (rigid on the shaft) and counts in that shaft's effective mass of the contact law;
- contact law: wormsim.contact3d.law (solref/solimp per collision geom; body_invweight0 set to A_hat);
- timestep: chosen before the model is built (wormsim.contact3d.timestep.timestep_for) and written once;
- a contact sensor (worm against the wheel's subtree, reduce="netforce") gives the resultant tooth force
  every step, which wormsim.contact3d.runner averages over each record interval.
"""

from __future__ import annotations

import functools
import math
from dataclasses import astuple, dataclass, field, replace
from pathlib import Path

import mujoco
import numpy as np

from meshgen import assembly, wheel
from meshgen.cache import cached
from meshgen.displaced import Deviations, wheel_mount, worm_mount
from meshgen.geometry import GearGeometry
from meshgen.kinematic_tca import KinematicTCA
from meshgen.pieces import GearSet
from wormsim.contact3d import mass_scaling, shafts
from wormsim.contact3d.backlash import check_backlash, check_conjugate_interference
from wormsim.contact3d.law import (
    ContactLaw,
    contact_law,
    flank_impedance,
    friction_damping_n_s_per_m,
    friction_impratio,
    keep_friction_rows,
    pair_stiffness_n_per_m,
)
from wormsim.contact3d.mass_scaling import ScalingCheck, floor_2_digits
from wormsim.contact3d.timestep import DEFAULT_FRACTION, SHAFTS_SOURCE, timestep_for
from wormsim.physics import gear_theory as gt
from wormsim.physics.friction import mu_law
from wormsim.physics.geometry import derive, gear_set, solid_set
from wormsim.physics.locking import stall_torque_nm, wheel_start_rad
from wormsim.physics.plan import GearPlan, gear_plan
from wormsim.runtime.data import data_dir
from wormsim.scenario import Load, Materials, Scenario, ScenarioError, Simulation
from wormsim.tooth.grid import SLICES_MASS_SCALED, FlankGrid, default_slices, flank_grid
from wormsim.tooth.window import slot_quat, window_size, window_teeth_at

TEMPLATE = data_dir("models") / "worm_pair.xml"  # models/, shipped as package data
SOLVER_TOLERANCE = 1e-8  # MuJoCo's Newton tolerance (opt.tolerance; docs/contact3d.md, "Solver")
MESH_SENSOR_DATA = 1 | 2 | 4 | 16  # contact sensor fields found, force, torque, pos (mjtConDataField bits)
INTEGRATORS = {
    "implicitfast": mujoco.mjtIntegrator.mjINT_IMPLICITFAST,
    "rk4": mujoco.mjtIntegrator.mjINT_RK4,
    "euler": mujoco.mjtIntegrator.mjINT_EULER,
    "implicit": mujoco.mjtIntegrator.mjINT_IMPLICIT,
    "discrete": mujoco.mjtIntegrator.mjINT_DISCRETE,
}


@dataclass
class BuiltModel:
    """A compiled model and what the runner needs to drive, re-pose and read it."""

    model: mujoco.MjModel
    spec: mujoco.MjSpec
    geometry: GearGeometry
    law: ContactLaw
    worm_body: int
    wheel_body: int
    worm_dof: int
    wheel_dof: int
    drive_actuator: int
    load_actuator: int
    worm_geoms: np.ndarray  # collision geom ids
    wheel_slot_geoms: np.ndarray  # (W, n_pieces) collision geom ids
    slot_bodies: np.ndarray  # (W,) body ids of the window slots (children of the wheel)
    window_teeth: int
    tooth0_angle_rad: float  # angle of tooth 0's centre in the wheel frame at theta2 = 0
    direction: int  # +1/-1: expected sign of (load shaft speed) / (drive command)
    drive_sign: int  # sign of the drive command
    pieces: GearSet
    timestep_s: float  # the model's timestep (model.opt.timestep), chosen before the build
    timestep_source: str
    meta: dict = field(default_factory=dict)
    tooth_shift_rad: np.ndarray | None = None  # (z2,) pitch deviations f_k / r2 (errors:, meshgen.displaced)
    kinematic_tca: KinematicTCA | None = None  # of the displaced pair (errors: only)
    deviations: Deviations | None = None  # the errors: block in SI (None for the perfect pair)
    plan: Prepared | None = None  # what the build was derived from (prepare), handed down to the run


@dataclass(frozen=True)
class Inertias:
    """Shaft masses and axial moments (from the visual meshes and the densities) and the driven machine's
    inertia load.inertia_kg_m2 on the loaded shaft (the hinge's armature)."""

    worm_mass_kg: float
    worm_inertia_kg_m2: float
    wheel_mass_kg: float
    wheel_inertia_kg_m2: float
    worm_load_inertia_kg_m2: float
    wheel_load_inertia_kg_m2: float


@dataclass(frozen=True)
class Prepared:
    """The run's plan, derived once from the scenario before the model is built and handed down: the gear-level
    plan (wormsim.physics.plan.GearPlan: geometry, the drive and load with their commands, ramps and working flank,
    the friction values, the working loads), pieces, inertias, the shafts' supports, the contact law, the flank
    grid; build_model adds the timestep and the window. After it is built no contact3d helper reads the scenario."""

    geometry: GearGeometry
    pieces: GearSet
    inertias: Inertias
    law: ContactLaw
    inv_mass_worm: float  # arm1^2 / (I1 + J1): the worm's share of A_hat
    inv_mass_wheel: float  # arm2^2 / (I2 + J2)
    gear: GearPlan  # the gear-level plan (wormsim.physics.plan.gear_plan)
    scaling: ScalingCheck  # simulation.mass_scaling: the factor used and its checks (inertias x it)
    normal_force_n: float = 0.0  # nominal_normal_force_n: the whole mesh's normal force at the working load
    grid: FlankGrid | None = None  # contact.geometry flanks: the flank grid of law.contacts_per_pair slices
    mu_law: tuple = ()  # the friction law mu(Vs) (wormsim.physics.friction.MuLaw)
    e_star_pa: float = 0.0  # the pair's effective modulus (gear_theory.effective_modulus_pa)
    timestep_s: float = 0.0  # the model's timestep (build_model: timestep_for's or the one given)
    window_teeth: int = 0  # the wheel tooth slots with collision (build_model)
    wheel_torque_nm: float = 0.0  # T2 the friction rows are sized for: the working one, a held stall's when larger
    servo_peak_torque_nm: float | None = None  # a speed drive's peak torque (gear_theory.servo_peak_torque_nm)
    supports: dict = field(default_factory=dict)  # part -> its Support (wormsim.contact3d.shafts.support) or None

    @property
    def duty(self) -> gt.Duty:
        """The drive and load, their commands, ramps and working flank (gear_theory.Duty)."""
        return self.gear.duty

    @property
    def flanks(self) -> bool:
        """contact.geometry flanks (the exact flanks; else the convex pieces)."""
        return self.gear.contact.geometry == "flanks"

    @property
    def worm_speed_rad_s(self) -> float | None:
        """The commanded worm speed (gear_theory.worm_speed_command_rad_s); None for a torque drive."""
        return self.gear.worm_speed_rad_s

    @property
    def drive_torque_nm(self) -> float:
        """The drive's torque at the full load (gear_theory.expected_drive_torque_of)."""
        return self.gear.drive_torque_nm

    @property
    def servo_gain_nm_s(self) -> float | None:
        """A speed drive's kv (gear_theory.servo_gain_of); None for a torque drive."""
        return self.gear.servo_gain_nm_s

    @property
    def servo_band_rad_s(self) -> float:
        """The speed servo's band peak / kv (wormsim.contact3d.flank_loop.servo_command); 0: no limit (a torque
        drive, a step command)."""
        kv, peak = self.servo_gain_nm_s, self.servo_peak_torque_nm
        return peak / kv if kv and peak is not None else 0.0

    @property
    def stick_velocity_m_s(self) -> float:
        """The friction law's stick state (wormsim.physics.locking.stick_velocity_m_s); 0: none."""
        return self.gear.stick_velocity_m_s

    @property
    def transition_velocity_m_s(self) -> float:
        """contact.transition_velocity_m_s."""
        return self.gear.transition_velocity_m_s

    @property
    def commands(self) -> gt.Commands:
        """The drive and load commands over time (duty.commands)."""
        return self.duty.commands

    @property
    def drive_on(self) -> str:
        """drive.on: the shaft the drive turns."""
        return self.duty.drive.on

    @property
    def speed_driven(self) -> bool:
        """drive.speed_rpm given (the lock guard watches the drive's speed)."""
        return self.duty.speed_driven

    @property
    def ramps_end_s(self) -> float:
        """Both commands at full value (duty.ramps_end_s)."""
        return self.duty.ramps_end_s

    @property
    def lock_start_s(self) -> float:
        """The lock guard's start (duty.lock_check_start_s)."""
        return self.duty.lock_check_start_s


Plan = Prepared


# ----------------------------------------------------------------------------- geometry helpers


def _mat2quat(R: np.ndarray) -> np.ndarray:
    q = np.zeros(4)
    mujoco.mju_mat2Quat(q, np.ascontiguousarray(R, dtype=float).ravel())
    return q


def _axial_inertia(mesh, density: float, r_in: float, r_out: float, length: float) -> tuple[float, float]:
    """(mass, I_zz) about the part's axis z: mesh volume integrals if watertight, else a hollow cylinder."""
    if mesh is not None and getattr(mesh, "is_watertight", False) and mesh.volume > 0:
        m = mesh.copy()
        m.density = density
        mp = m.mass_properties
        return float(mp["mass"]), float(mp["inertia"][2, 2])
    mass = density * math.pi * (r_out**2 - r_in**2) * length
    return mass, 0.5 * mass * (r_out**2 + r_in**2)


def _on_gear_set(gs: GearSet, what: str, fn, *args):
    """fn(*args) of gs's meshes, on disk (meshgen.cache) under the gear set's cache key (geometry, resolution,
    meshgen's code version), `what`, the arguments, fn's source and trimesh's version: trimesh's mass properties
    cost 0.6-0.8 s per run, and reading them from the cache keeps trimesh unimported (meshgen.lazymesh). A gear set
    without a key (built elsewhere) is computed directly."""
    key = gs.info.get("cache_key")
    compute = functools.partial(fn, *args)
    if key is None:
        return compute()
    parts = {"gearset": key, "what": what, "args": [a for a in args if isinstance(a, (int, float))], "code": _code(fn)}
    return cached("gearsetprops", parts, compute)


@functools.cache
def _code(fn) -> str:
    import inspect
    from importlib.metadata import version

    return inspect.getsource(fn) + version("trimesh")


def _visual_inertia(gs: GearSet, part: str, density: float, r_in: float, r_out: float, length: float):
    """_axial_inertia of gs.<part> (worm_visual / wheel_visual), cached (_on_gear_set)."""
    return _on_gear_set(gs, part, _axial_inertia, getattr(gs, part), density, r_in, r_out, length)


def visual_vertex_normals(gs: GearSet, part: str) -> np.ndarray:
    """trimesh's vertex normals of gs.<part> (worm_visual / wheel_visual) for the recording, cached (_on_gear_set)."""
    return _on_gear_set(gs, f"{part}_normals", _vertex_normals, getattr(gs, part))


def _vertex_normals(mesh) -> np.ndarray:
    import trimesh

    return np.asarray(trimesh.Trimesh(vertices=mesh.vertices, faces=mesh.faces, process=False).vertex_normals)


def nominal_normal_force_n(wheel_torque_nm: float, geo: GearGeometry) -> float:
    """Whole-mesh normal force at the working load (gear_theory.normal_force_n of the working wheel torque,
    gear_theory.working_wheel_torque_of). Sets the friction rows' hardness (wormsim.contact3d.law (3)); with T2 = 0
    impratio fell to 1 and a self-locking pair crept back at ~110 rpm instead of 0.2 rpm
    (docs/stability_backlash_locking.md)."""
    return gt.normal_force_n(wheel_torque_nm, geo.r2, geo.alpha_n, geo.gamma_m)


def nominal_sliding_speed_m_s(worm_speed_rad_s: float | None, geo: GearGeometry) -> float:
    """Vs = omega1 r1 / cos(gamma) at a speed-controlled drive's full worm speed
    (gear_theory.worm_speed_command_rad_s); 0 for a torque drive (None: speed not known before the run)."""
    if worm_speed_rad_s is None:
        return 0.0
    return worm_speed_rad_s * geo.r_m1 / math.cos(geo.gamma_m)


def expected_direction(geo: GearGeometry) -> int:
    """+1/-1: sign of the driven shaft's speed per sign of the drive command (docs/outputs.md, Force signs): a positive
    worm rotation drives the wheel positive for a right-hand worm (and back-driving the same way)."""
    return geo.hand


def flank_slices(scenario: Scenario, geo: GearGeometry | None = None) -> int:
    """contact.geometry flanks: slices across the face (contact.slices, else wormsim.tooth.grid.default_slices)."""
    if scenario.contact.slices:
        return int(scenario.contact.slices)
    return default_slices(geo if geo is not None else derive(scenario.gear), scenario.simulation.resolution)


def _slabs_per_flank(gs: GearSet) -> int:
    """n_ref: wheel-tooth pieces across the face width on one flank (meshgen may split a tooth
    into flank pieces; a piece spanning both flanks counts once per flank)."""
    if gs.resolution.wheel_slabs:
        return int(gs.resolution.wheel_slabs)
    zs = [round(float(np.mean(p.vertices[:, 2])), 9) for p in gs.wheel_tooth_pieces]
    return len(set(zs))


def _pieces_angle(pieces) -> float:
    """Angle of the pieces' mean centroid in the wheel frame (tests: tooth 0's pieces sit on wheel.tooth_angle)."""
    c = np.mean([p.centroid for p in pieces], axis=0)
    return math.atan2(c[1], c[0])


# ----------------------------------------------------------------------------- before the build


def shaft_inertias(scenario: Scenario, geo: GearGeometry, gs: GearSet) -> Inertias:
    """inertias_of the scenario's materials and load."""
    return inertias_of(scenario.materials, scenario.load, geo, gs)


def inertias_of(mats: Materials, load: Load, geo: GearGeometry, gs: GearSet) -> Inertias:
    """The shafts' Inertias: the visual meshes' (cached, _visual_inertia) and the driven machine's on the loaded
    shaft."""
    m1, I1 = _visual_inertia(gs, "worm_visual", mats.worm.density_kg_m3, 0.0, geo.r1, geo.worm_length)
    m2, I2 = _visual_inertia(gs, "wheel_visual", mats.wheel.density_kg_m3, 0.0, geo.r2, geo.face_width)
    j_load = load.inertia_kg_m2
    J1, J2 = (j_load, 0.0) if load.on == "worm" else (0.0, j_load)
    return Inertias(m1, I1, m2, I2, J1, J2)


def prepare(scenario: Scenario, gs: GearSet | None = None) -> Prepared:
    """Geometry, pieces (built or cached unless given), inertias and the contact law with its friction hardness:
    everything the timestep and the model need, without compiling anything."""
    if scenario.gear is None or scenario.drive is None:
        raise ScenarioError("model: contact3d needs gear: and drive: blocks")
    flanks = scenario.contact.geometry == "flanks"  # the flank contacts need the solid meshes only, no pieces
    geo, gs = (derive(scenario.gear), gs) if gs is not None else (solid_set if flanks else gear_set)(scenario)
    # n_ref: the pieces across the face width, or with contact.geometry flanks the flank contacts' slices
    slabs = flank_slices(scenario, geo) if flanks else max(1, _slabs_per_flank(gs))
    return _prepare(gear_plan(scenario, geo), gs, slabs)


def _prepare(gp: GearPlan, gs: GearSet, slabs: int) -> Prepared:
    """prepare's derivations from the gear-level plan, the pieces and the slices."""
    geo, contact, mats = gp.geometry, gp.contact, gp.materials
    flanks = contact.geometry == "flanks"
    ine = inertias_of(mats, gp.duty.load, geo, gs)
    supports = {part: shafts.support(gp.shafts, mats, geo, part) for part in ("worm", "wheel")}
    mu0, mu1 = gp.mu_static, gp.mu_nominal
    # the drive and load, once (wormsim.physics.plan): their commands, the worm's speed, the working and the
    # drive's torques
    w1, t_drive, t2 = gp.worm_speed_rad_s, gp.drive_torque_nm, gp.working_wheel_torque_nm
    arm1, arm2 = gt.mesh_arms_m(geo.r_m1, geo.r2, geo.alpha_n, geo.gamma_m)
    # driven-machine inertia J on the loaded shaft (joint armature) belongs to that shaft's effective mass
    I1 = ine.worm_inertia_kg_m2 + ine.worm_load_inertia_kg_m2
    I2 = ine.wheel_inertia_kg_m2 + ine.wheel_load_inertia_kg_m2
    # simulation.mass_scaling (wormsim.contact3d.mass_scaling): every inertia x S before the law takes them
    k_pair, _ = pair_stiffness_n_per_m(contact, geo, mats)
    scaling = mass_scaling.resolve(
        gp.simulation.mass_scaling,
        gp.duty,
        ratio=geo.ratio,
        z1=geo.z1,
        worm_speed_rad_s=w1,
        drive_torque_nm=t_drive,
        pair_stiffness_n_per_m=k_pair,
        inv_mass_hat=arm1**2 / I1 + arm2**2 / I2,
        inertias_kg_m2=(I1, I2),
        segments_per_turn=0 if flanks else gs.resolution.worm_segments_per_turn or 0,
    )
    S = scaling.factor
    # a stalling speed drive's peak torque (gear_theory.servo_peak_applies), its ramp's share with the inertias the
    # model has (x S)
    drv = gp.duty.drive
    peak = None
    if gt.servo_peak_applies(gp.duty.speed_driven, gp.backdrive_self_locks):
        j_drive = gt.drive_inertia_kg_m2(drv.on, geo.ratio, S * I1, S * I2)
        peak = gt.servo_peak_torque_nm(t_drive, j_drive, gp.duty.commands.drive_target, drv.ramp_s)
    held = gp.backdrive_self_locks
    if held:  # the mesh holds the stalled wheel servo's torque (wormsim.physics.locking): the friction rows' hardness
        t2 = max(t2, stall_torque_nm(t_drive, peak))
    f_n, v_s = nominal_normal_force_n(t2, geo), nominal_sliding_speed_m_s(w1, geo)
    if held:  # the worm stands: no sliding speed to size the friction rows' damping by (law (4): c_f = c_c)
        v_s = 0.0
    a1, a2 = arm1**2 / (S * I1), arm2**2 / (S * I2)
    if S != 1:  # the scaled inertias
        ine = Inertias(*(S * v for v in astuple(ine)))
        if flanks and not contact.slices:
            slabs = min(slabs, SLICES_MASS_SCALED)  # a scaled run keeps means only (tooth.grid.SLICES_MASS_SCALED)
    law = contact_law(contact, mats, geo, slabs, a1 + a2, flank_impedance(slabs) if flanks else None)  # the law, once
    mu_max = max(mu0, mu1)
    if flanks:  # the flank contacts' own friction-row damping, law (4)
        law = replace(
            law,
            friction_damping_n_s_per_m=friction_damping_n_s_per_m(law, mu_max, f_n, v_s),
        )
    law = replace(law, impratio=friction_impratio(law, mu_max, f_n, contact.transition_velocity_m_s))
    if flanks:  # the flank rows' added mass per tooth pair, the friction rows as at IMPEDANCE: law (5)
        law = keep_friction_rows(law)
    grid = flank_grid(geo, law.contacts_per_pair) if flanks else None
    return Prepared(
        geo,
        gs,
        ine,
        law,
        a1,
        a2,
        gp,
        scaling,
        f_n,
        grid,
        mu_law=mu_law(contact),
        e_star_pa=gt.effective_modulus_pa(mats),
        wheel_torque_nm=t2,
        servo_peak_torque_nm=peak,
        supports=supports,
    )


# ----------------------------------------------------------------------------- build


def build_model(
    scenario: Scenario,
    gs: GearSet | None = None,
    check_backlash_vs_pieces: bool = True,
    window_teeth: int | None = None,
    timestep_s: float | None = None,
) -> BuiltModel:
    """The compiled contact3d model of the scenario's plan (prepare, build). check_backlash_vs_pieces=False skips
    wormsim.contact3d.backlash's checks (only to measure what happens below their limit). window_teeth: wheel tooth
    slots with collision (default window_size; geo.z2 = every tooth, for a standalone file that the viewer can turn
    without re-posing). timestep_s: the timestep to build with (default: timestep_for's)."""
    return build(prepare(scenario, gs), check_backlash_vs_pieces, window_teeth, timestep_s)


def build(
    p: Prepared, check_backlash_vs_pieces: bool = True, window_teeth: int | None = None, timestep_s: float | None = None
) -> BuiltModel:
    """The compiled contact3d model of a plan (build_model)."""
    gp, geo, gs, law = p.gear, p.geometry, p.pieces, p.law
    sim = gp.simulation
    if p.flanks:
        check_backlash_vs_pieces = False  # no pieces collide (wormsim.contact3d.flank_step)
    # backlash against the pieces' residual bulge (wormsim.contact3d.backlash (2)): exit 2 before the teeth start jammed
    backlash_meta = (
        check_backlash(geo, gs.piece_error_um, sim.resolution) if check_backlash_vs_pieces and gs.piece_error_um else {}
    )
    h, h_source = (
        timestep_for(sim.timestep_s, p.worm_speed_rad_s, law, p.scaling.factor)
        if timestep_s is None
        else (timestep_s, "given to build_model")
    )
    dev, kin = gp.displaced if gp.displaced is not None else (None, None)  # the errors: block; None: the perfect pair
    shift = dev.tooth_angle_shift(geo, np.arange(geo.z2)) if dev is not None and any(dev.tooth_shift) else None
    spec, W, worm_names, slot_names, sups, drive_sign = _spec(p, window_teeth, dev, shift, h)
    model = spec.compile()
    if sups is not None and timestep_s is None and sim.timestep_s is None:  # a default step: the shafts' modes too
        lim = shafts.stable_limit_s(model)  # inf where the shafts are rigid
        h_shafts = floor_2_digits(DEFAULT_FRACTION * lim) if math.isfinite(lim) else h
        if h_shafts < h:
            h, h_source = h_shafts, SHAFTS_SOURCE
            spec, W, worm_names, slot_names, sups, drive_sign = _spec(p, window_teeth, dev, shift, h)
            model = spec.compile()
    meta = {"flank_contacts": gp.contact.flank_contacts, **backlash_meta}
    # a torque-driven wheel starts on its loaded flank (wormsim.physics.locking.wheel_start_rad): the hinge's
    # initial angle
    meta["wheel_start_rad"] = wheel_start_rad(
        p.duty.drive, p.flanks, geo.backlash, geo.r2, dev is None and sups is None
    )
    jw = model.jnt_qposadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, "wheel_hinge")]
    model.qpos0[jw] += meta["wheel_start_rad"]
    if sups is not None:  # the shafts' joints (wormsim.contact3d.shafts): the kernel takes the poses from the data
        meta.update(shafts.model_meta(model, sups, p.normal_force_n, geo, h))

    def oid(kind: mujoco.mjtObj, name: str) -> int:
        return mujoco.mj_name2id(model, kind, name)

    slot_geoms = np.array([[oid(mujoco.mjtObj.mjOBJ_GEOM, n) for n in row] for row in slot_names], dtype=int).reshape(
        W, -1
    )  # (W, 0) with contact.geometry flanks
    slot_bodies = np.array([oid(mujoco.mjtObj.mjOBJ_BODY, f"slot{i}") for i in range(W)])
    _set_inv_mass_hat(model, law, p.inv_mass_worm, p.inv_mass_wheel, slot_bodies)
    bm = BuiltModel(
        model=model,
        spec=spec,
        geometry=geo,
        law=law,
        worm_body=oid(mujoco.mjtObj.mjOBJ_BODY, "worm"),
        wheel_body=oid(mujoco.mjtObj.mjOBJ_BODY, "wheel"),
        worm_dof=int(model.jnt_dofadr[oid(mujoco.mjtObj.mjOBJ_JOINT, "worm_hinge")]),
        wheel_dof=int(model.jnt_dofadr[oid(mujoco.mjtObj.mjOBJ_JOINT, "wheel_hinge")]),
        drive_actuator=oid(mujoco.mjtObj.mjOBJ_ACTUATOR, "drive"),
        load_actuator=oid(mujoco.mjtObj.mjOBJ_ACTUATOR, "load"),
        worm_geoms=np.array([oid(mujoco.mjtObj.mjOBJ_GEOM, n) for n in worm_names], dtype=int),
        wheel_slot_geoms=slot_geoms,
        slot_bodies=slot_bodies,
        window_teeth=W,
        tooth0_angle_rad=wheel.tooth_angle(geo, 0),
        direction=p.duty.direction,
        drive_sign=drive_sign,
        pieces=gs,
        timestep_s=h,
        timestep_source=h_source,
        meta=meta,
        tooth_shift_rad=shift,
        kinematic_tca=kin,
        deviations=dev,
        plan=replace(p, timestep_s=h, window_teeth=W),
    )
    if check_backlash_vs_pieces:
        # the model itself at the rigid-conjugate pose (wormsim.contact3d.backlash.check_conjugate_interference): exit 2
        meta["conjugate_interference_m"] = check_conjugate_interference(bm, sim.resolution, p.normal_force_n)
    return bm


def _spec(p: Prepared, window_teeth: int | None, dev: Deviations | None, shift: np.ndarray | None, h: float):
    """The model's MjSpec from the template: bodies, the shafts' mounts, geoms, actuators, options, the sensor.
    Returns (spec, W, worm geom names, slot geom names, the shafts' mounts or None, the drive command's sign)."""
    gp, geo, law = p.gear, p.geometry, p.law
    spec = mujoco.MjSpec.from_file(str(TEMPLATE))
    spec.modelname = gp.name
    _place_bodies(spec, geo, p.inertias, dev)
    sups = shafts.mount(spec, p.supports, geo) if gp.shafts is not None else None  # bearings, bending
    worm_names, slot_names, W = _add_geoms(spec, geo, p.pieces, law, gp.mu_static, window_teeth, shift, p.flanks)
    _, drive_sign = _add_actuators(spec, p.duty, p.servo_gain_nm_s)
    spec.joint(f"{p.duty.load.on}_hinge").armature = max(
        p.inertias.worm_load_inertia_kg_m2, p.inertias.wheel_load_inertia_kg_m2
    )  # x mass_scaling
    _set_options(spec, gp.simulation, law, h)
    if sups is not None:
        shafts.set_solver(spec, sups)  # CG where shaft joints move (wormsim.contact3d.shafts.SOLVER)
    _add_mesh_sensor(spec)
    return spec, W, worm_names, slot_names, sups, drive_sign


def _place_bodies(spec: mujoco.MjSpec, geo: GearGeometry, ine: Inertias, dev: Deviations | None = None) -> None:
    """Worm and wheel bodies in the assembly frame (meshgen.assembly) with their masses and inertias; with assembly
    errors (dev) displaced as _place_displaced puts them."""
    worm_b, wheel_b = spec.body("worm"), spec.body("wheel")
    Tw = np.asarray(assembly.worm_to_assembly(0.0, geo), dtype=float)
    Tg = np.asarray(assembly.wheel_to_assembly(0.0), dtype=float)
    if not np.allclose(Tg, np.eye(4), atol=1e-12):
        raise RuntimeError("meshgen.assembly: the wheel frame must coincide with the assembly frame at theta2 = 0")
    worm_b.pos = Tw[:3, 3]
    worm_b.quat = _mat2quat(Tw[:3, :3])
    if dev is not None:
        _place_displaced(spec, geo, dev)
    # transverse moments of a solid cylinder of the part's length, Izz / 2 + m L^2 / 12: irrelevant on a hinge,
    # but they must satisfy the triangle inequality with a margin that survives the 6 digits of a written MJCF
    for body, mass, izz, length in (
        (worm_b, ine.worm_mass_kg, ine.worm_inertia_kg_m2, geo.worm_length),
        (wheel_b, ine.wheel_mass_kg, ine.wheel_inertia_kg_m2, geo.face_width),
    ):
        body.explicitinertial = True
        body.mass = mass
        body.ipos = [0, 0, 0]
        ixx = izz / 2 + mass * length**2 / 12
        body.inertia = [ixx, ixx, izz]


def _place_displaced(spec: mujoco.MjSpec, geo: GearGeometry, dev: Deviations) -> None:
    """Assembly errors: move and tilt the bodies and put each hinge on its axis of rotation, off the part's
    own axis by the runout, as meshgen.displaced (1), (2) gives them: body -> assembly = M Rz(theta) E, i.e. the body
    at M E and the hinge at E^-1's origin in the body frame."""
    for part, (M, E) in (("worm", worm_mount(geo, dev)), ("wheel", wheel_mount(geo, dev))):
        X = M @ E
        body = spec.body(part)
        body.pos = X[:3, 3]
        body.quat = _mat2quat(X[:3, :3])
        spec.joint(f"{part}_hinge").pos = -E[:3, 3]


def _add_mesh(spec: mujoco.MjSpec, name: str, mesh) -> None:
    me = spec.add_mesh()
    me.name = name
    me.uservert = np.asarray(mesh.vertices, dtype=np.float32).ravel()
    me.userface = np.asarray(mesh.faces, dtype=np.int32).ravel()
    me.inertia = mujoco.mjtMeshInertia.mjMESH_INERTIA_CONVEX


def _add_geoms(
    spec: mujoco.MjSpec,
    geo: GearGeometry,
    gs: GearSet,
    law: ContactLaw,
    mu0: float,
    window_teeth: int | None,
    tooth_shift_rad: np.ndarray | None = None,
    flanks: bool = False,
) -> tuple[list[str], list[list[str]], int]:
    """Visual meshes, the worm's collision pieces and the wheel's window of W slots (one rigid child body per
    slot, no joint: re-posing a slot moves its body, so MuJoCo's per-body bounding-volume hierarchy, built at
    compile time in the body frame, stays valid). Returns (worm geom names, slot geom names, W). flanks
    (contact.geometry flanks): no collision pieces; the visual geoms carry the flank contacts' law."""
    worm_b, wheel_b = spec.body("worm"), spec.body("wheel")

    def set_contact(g: mujoco.MjsGeom) -> None:
        g.solref = law.solref
        g.solimp = law.solimp
        g.friction = [mu0, 0.0, 0.0]
        g.margin = 0.0

    if not flanks:
        _add_mesh(spec, "worm_visual", gs.worm_visual)
        _add_mesh(spec, "wheel_visual", gs.wheel_visual)
    stand_in = {"worm_visual": (geo.r_a1, geo.worm_length / 2), "wheel_visual": (geo.r_a2, geo.face_width / 2)}
    for b, name, rgba in (
        (worm_b, "worm_visual", (0.55, 0.6, 0.7, 1)),
        (wheel_b, "wheel_visual", (0.85, 0.65, 0.3, 1)),
    ):
        g = b.add_geom(default=spec.find_default("visual"))
        g.name, g.rgba = name, rgba
        if flanks:
            # the flank contacts' geoms (wormsim.contact3d.flank_step): friction, solref; a cylinder of the part's tip
            # radius and length about its axis stands in for the smooth mesh, which no flank run reads (the contacts
            # come from the kernel, the bodies' inertias are explicit, the recording draws the meshes itself) and
            # whose compile (60k vertices for the screw jack) cost every run 0.7 s
            g.type = mujoco.mjtGeom.mjGEOM_CYLINDER
            g.size = [*stand_in[name], 0.0]
            set_contact(g)
        else:
            g.meshname = name
    worm_names = []
    for i, piece in enumerate([] if flanks else gs.worm_pieces):
        _add_mesh(spec, f"worm_piece_{i}", piece)
        g = worm_b.add_geom(default=spec.find_default("worm_collision"))
        g.name = g.meshname = f"worm_piece_{i}"
        set_contact(g)
        worm_names.append(g.name)
    for j, piece in enumerate([] if flanks else gs.wheel_tooth_pieces):
        _add_mesh(spec, f"tooth_piece_{j}", piece)
    W = window_size(geo) if window_teeth is None else int(min(max(window_teeth, 1), geo.z2))
    n_pieces = 0 if flanks else len(gs.wheel_tooth_pieces)
    slot_names = [[""] * n_pieces for _ in range(W)]
    for k in window_teeth_at(0.0, geo.z2, W, wheel.tooth_angle(geo, 0)):
        s = int(k % W)
        sb = wheel_b.add_body()
        sb.name = f"slot{s}"
        sb.quat = slot_quat(int(k), geo.z2, tooth_shift_rad)
        sb.explicitinertial = True
        sb.mass = 1e-9
        sb.inertia = [1e-15, 1e-15, 1e-15]
        for j in range(n_pieces):
            g = sb.add_geom(default=spec.find_default("wheel_collision"))
            g.name = f"slot{s}_piece{j}"
            g.meshname = f"tooth_piece_{j}"
            set_contact(g)
            slot_names[s][j] = g.name
    return worm_names, slot_names, W


def _add_actuators(spec: mujoco.MjSpec, duty: gt.Duty, kv: float | None) -> tuple[float | None, int]:
    """Drive (speed: velocity servo of gain kv, Prepared.servo_gain_nm_s; torque: motor) and load (motor) on their
    hinges; the driven machine's inertia is the loaded hinge's armature. Returns (kv or None, drive sign)."""
    drv, load = duty.drive, duty.load
    a = spec.add_actuator()
    a.name, a.target, a.trntype = "drive", f"{drv.on}_hinge", mujoco.mjtTrn.mjTRN_JOINT
    if drv.speed_rpm is not None:
        a.set_to_velocity(kv=kv)
        drive_sign = int(np.sign(drv.speed_rpm)) or 1
    else:
        a.set_to_motor()
        drive_sign = int(np.sign(drv.torque_nm)) or 1
    a.ctrllimited = False
    lo = spec.add_actuator()
    lo.name, lo.target, lo.trntype = "load", f"{load.on}_hinge", mujoco.mjtTrn.mjTRN_JOINT
    lo.set_to_motor()
    lo.ctrllimited = False
    spec.joint(f"{load.on}_hinge").armature = load.inertia_kg_m2
    return kv, drive_sign


def _set_options(spec: mujoco.MjSpec, sim: Simulation, law: ContactLaw, timestep_s: float) -> None:
    """The timestep, the solver's tolerance, impratio and the simulation: block's integrator and speculative
    contacts."""
    o = spec.option
    o.timestep = timestep_s
    o.tolerance = SOLVER_TOLERANCE
    o.impratio = law.impratio  # friction rows' hardness, wormsim.contact3d.law (3)
    if sim.speculative:
        o.enableflags |= int(mujoco.mjtEnableBit.mjENBL_SPECULATIVE)
    o.integrator = INTEGRATORS[sim.integrator]


def _add_mesh_sensor(spec: mujoco.MjSpec) -> None:
    """Contact sensor: worm against the wheel's subtree (XBODY: the wheel and its slots), net force."""
    sen = spec.add_sensor()
    sen.name, sen.type = "mesh_force", mujoco.mjtSensor.mjSENS_CONTACT
    sen.objtype, sen.objname = mujoco.mjtObj.mjOBJ_BODY, "worm"
    sen.reftype, sen.refname = mujoco.mjtObj.mjOBJ_XBODY, "wheel"
    sen.intprm[0] = MESH_SENSOR_DATA
    sen.intprm[1] = 3  # reduce = netforce
    sen.intprm[2] = 1  # num


def _set_inv_mass_hat(
    model: mujoco.MjModel, law: ContactLaw, a_worm: float, a_wheel: float, slot_bodies: np.ndarray
) -> None:
    """Make MuJoCo's diagonal approximation of a worm-wheel contact row equal A_hat (wormsim.contact3d.law (1)):
    body_invweight0[worm] + body_invweight0[slot body] = A_hat."""
    wb = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "worm")
    gb = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "wheel")
    model.body_invweight0[wb, 0] = a_worm
    model.body_invweight0[gb, 0] = a_wheel
    model.body_invweight0[slot_bodies, 0] = a_wheel
    assert abs(a_worm + a_wheel - law.inv_mass_hat) <= 1e-9 * law.inv_mass_hat


# ----------------------------------------------------------------------------- standalone MJCF


RPM_PER_RAD_S = 30.0 / math.pi  # the standalone model's drive control is a speed in rpm (gear of its servo)
CTRL_RANGE_FACTOR = 2.0  # the controls' range: +- this times the scenario's value (the viewer's sliders)


STL_FACES_MAX = 200_000  # MuJoCo's STL decoder: "number of faces should be between 1 and 200000"


def write_model(scenario: Scenario, out_dir: str | Path) -> Path:
    """DIR/model.xml + DIR/meshes/*.stl (*.obj for a mesh of more than STL_FACES_MAX faces): opens with
    `python -m mujoco.viewer --mjcf DIR/model.xml`.

    The standalone file gives every wheel tooth its collision pieces (the viewer does not re-pose a window,
    so the wheel can turn any number of turns), and MuJoCo recomputes body_invweight0 on load, so its
    contact stiffness differs from a wormsim run's. It always carries the collision pieces (contact.geometry
    pieces): the flank contacts are found by wormsim's own step (wormsim.contact3d.flank_step), which a plain
    MuJoCo viewer does not run.

    Actuators (docs/mjcf.md), both on their controls, without bias terms:
    - `drive` on `{drive.on}_hinge`: a speed drive is a velocity servo whose control is the shaft speed in rpm
      (gear RPM_PER_RAD_S, kv / gear^2: the joint sees the run's servo gain kv in N m s/rad); a torque drive is a
      motor whose control is the torque in N m;
    - `load` on `{load.on}_hinge`: a motor whose control is the load torque in N m (signed in the hinge's sense:
      the scenario's resisting load is opposite to the motion).
    The keyframe `scenario` holds the scenario's final commands (without the STEP ramps); MuJoCo starts with both
    controls at 0 (the shafts at rest), so load that key (the viewer's "Load key", or mj_resetDataKeyframe) or
    set the controls. Each control is limited to +- CTRL_RANGE_FACTOR times the scenario's value.
    """
    if scenario.contact.geometry != "pieces":
        scenario = scenario.model_copy(update={"contact": scenario.contact.model_copy(update={"geometry": "pieces"})})
    out = Path(out_dir)
    (out / "meshes").mkdir(parents=True, exist_ok=True)
    geo = derive(scenario.gear) if scenario.gear is not None else None
    bm = build_model(scenario, window_teeth=geo.z2 if geo is not None else None)
    spec = bm.spec
    cmds = bm.plan.commands
    ctrl = {"drive": float(cmds.drive_target), "load": float(cmds.load_target_nm)}
    for act in spec.actuators:
        if act.name == "drive" and bm.plan.speed_driven:
            kv = float(act.gainprm[0])
            act.set_to_velocity(kv=kv / RPM_PER_RAD_S**2)
            act.gear = [RPM_PER_RAD_S, 0, 0, 0, 0, 0]
            ctrl["drive"] *= RPM_PER_RAD_S  # rad/s -> rpm
        lim = CTRL_RANGE_FACTOR * abs(ctrl[act.name]) or 1.0
        act.ctrllimited = True
        act.ctrlrange = [-lim, lim]
    key = spec.add_key()
    key.name = "scenario"
    key.ctrl = [ctrl[act.name] for act in spec.actuators]
    import trimesh

    for me in spec.meshes:
        v = np.asarray(me.uservert, dtype=float).reshape(-1, 3)
        f = np.asarray(me.userface, dtype=int).reshape(-1, 3)
        # MuJoCo reads at most STL_FACES_MAX faces from an STL file (a large wheel's visual mesh has more): OBJ then
        name = f"{me.name}.stl" if len(f) <= STL_FACES_MAX else f"{me.name}.obj"
        trimesh.Trimesh(v, f, process=False).export(out / "meshes" / name)
        me.uservert = []
        me.userface = []
        me.file = name
    spec.meshdir = "meshes"
    spec.modelfiledir = str(out.resolve())
    path = out / "model.xml"
    path.write_text(spec.to_xml())
    mujoco.MjModel.from_xml_path(str(path))  # fail here, not in the user's viewer
    return path
