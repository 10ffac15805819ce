"""The contact3d MuJoCo model: worm + wheel on one hinge each, coupled only through tooth contact.

Built with mujoco.MjSpec from the template `models/worm_pair.xml` (see models/README.md):

- bodies in the assembly frame of INTERFACE.md (wheel axis z through the origin, worm axis parallel
  to x at y = -a), placed by meshgen.assembly; one hinge each, no gear or equality constraint;
- collision geoms: meshgen's convex pieces (meshgen.pieces). All worm pieces; for the wheel only an
  ACTIVE WINDOW of `window_teeth` tooth slots around the line of centres, which wormsim.contact3d.runner
  re-poses by whole pitches as the wheel turns (tooth k lives in slot k mod W), so the cost does not
  grow with z2. Contype/conaffinity let worm pieces meet wheel pieces only;
- visual-only geoms: the smooth watertight meshes (whole worm, whole wheel);
- inertias: axial moments of the visual meshes times the materials' densities (trimesh mass
  properties; a solid cylinder r_f..r_a as a fallback if a mesh is not watertight);
- drive: speed -> `velocity` actuator (kv chosen for a 0.1 % speed droop at the expected torque, integrated
  implicitly by implicitfast), torque -> `motor`; the command follows ADAMS STEP over drive.ramp_s;
- load: `motor` on the other shaft, resisting (sign opposite to the expected motion), STEP from
  load.start_s over load.ramp_s; a driven-machine inertia load.inertia_kg_m2 is the loaded hinge's armature
  (rigid on the shaft) and counts in that shaft's effective mass of the contact law;
- contact law: wormsim.contact3d.law (solref/solimp per collision geom; body_invweight0 set to A_hat);
- a contact sensor (worm against the wheel's subtree, reduce="netforce") gives the resultant tooth force
  every step, which wormsim.contact3d.runner averages over each record interval.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from importlib.resources import files
from pathlib import Path

import mujoco
import numpy as np

from meshgen.geometry import GearGeometry, derive
from wormsim.contact3d.backlash import check_backlash, check_conjugate_interference
from wormsim.contact3d.law import ContactLaw, contact_law, efficiency_theory, friction_coefficient, friction_impratio
from wormsim.scenario import Scenario, ScenarioError
from wormsim.units import rpm_to_rad_s

TEMPLATE = files("wormsim.models") / "worm_pair.xml"   # models/, shipped as package data
MESH_SENSOR_DATA = 1 | 2 | 4 | 16    # contact sensor fields found, force, torque, pos (mjtConDataField bits)
SPEED_DROOP = 1e-3          # velocity servo: kv = T_expected / (SPEED_DROOP * omega_cmd)


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
    worm_geoms: np.ndarray              # collision geom ids
    wheel_slot_geoms: np.ndarray        # (W, n_pieces) collision geom ids
    slot_bodies: np.ndarray             # (W,) body ids of the window slots (children of the wheel)
    window_teeth: int
    tooth0_angle_rad: float             # angle of tooth 0's centre in the wheel frame at theta2 = 0
    direction: int                      # +1/-1: expected sign of (load shaft speed) / (drive command)
    drive_sign: int                     # sign of the drive command
    pieces: object = None               # meshgen GearSet
    meta: dict = field(default_factory=dict)


# ----------------------------------------------------------------------------- geometry helpers

def gear_set(scenario: Scenario):
    from meshgen.pieces import build_gear_set

    geo = derive(scenario.gear)
    return geo, build_gear_set(geo, resolution=scenario.simulation.resolution)


def _assembly(geo: GearGeometry, part: str, theta: float) -> np.ndarray:
    import inspect

    from meshgen import assembly

    fn = getattr(assembly, f"{part}_to_assembly")
    n = len(inspect.signature(fn).parameters)
    return np.asarray(fn(theta) if n == 1 else fn(theta, geo), dtype=float)


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
        return float(mp["mass"]), float(mp["inertia"][2, 2] + mp["mass"] * 0.0)
    mass = density * math.pi * (r_out ** 2 - r_in ** 2) * length
    return mass, 0.5 * mass * (r_out ** 2 + r_in ** 2)


def mesh_arms(geo: GearGeometry) -> tuple[float, float]:
    """Moment arms of a unit normal force at the pitch point about the worm and wheel axes:
    worm r1 cos(alpha_n) sin(gamma), wheel r2 cos(alpha_n) cos(gamma) (normal direction of the
    flank at the pitch point, DIN 3975 force components)."""
    ca = math.cos(geo.alpha_n)
    return geo.r1 * ca * math.sin(geo.gamma), geo.r2 * ca * math.cos(geo.gamma)


def nominal_normal_force_n(scenario: Scenario, geo: GearGeometry) -> float:
    """Whole-mesh normal force at the working load, F_n = T2 / (r2 cos(alpha_n) cos(gamma)) (DIN 3975; wheel
    torque T2 = the load, or the worm load times the ratio when the load is on the worm; a torque driving the WHEEL
    counts too, the larger of the two: it passes through the mesh whatever the worm does, and against a free worm it
    is the only load. A torque driving the worm is not counted: what it does not pass to the wheel load accelerates
    the worm). Sets the friction rows' hardness (wormsim.contact3d.law (3)); with T2 = 0 impratio fell to 1 and a
    self-locking pair crept back at ~110 rpm instead of 0.2 rpm (docs/stability_backlash_locking.md)."""
    load, drv = scenario.load, scenario.drive
    t2 = abs(load.torque_nm) * (1.0 if load.on == "wheel" else geo.ratio)
    if drv.torque_nm is not None and drv.on == "wheel":
        t2 = max(t2, abs(drv.torque_nm))
    return t2 / (geo.r2 * math.cos(geo.alpha_n) * math.cos(geo.gamma))


def expected_direction(scenario: Scenario, geo: GearGeometry) -> int:
    """+1/-1: sign of the driven shaft's speed per sign of the drive command. INTERFACE.md: a positive
    worm rotation drives the wheel positive for a right-hand worm (and back-driving the same way)."""
    return geo.hand


def window_size(geo: GearGeometry) -> int:
    """Wheel teeth with collision: those the threaded length can reach, plus one each side."""
    reach = min(geo.worm_length / 2, geo.r_e2)
    half = math.asin(min(reach / geo.r_e2, 1.0)) * geo.z2 / (2 * math.pi)
    return int(min(geo.z2, 2 * math.ceil(half) + 2))


def window_teeth_at(theta2: float, z2: int, window: int, tooth0_angle: float) -> np.ndarray:
    """Unwrapped tooth indices k of the window at wheel angle theta2: the W teeth nearest the line of
    centres (angle -pi/2 in the assembly frame), tooth k at angle tooth0 + 2 pi k / z2 + theta2."""
    pitch = 2 * math.pi / z2
    c = math.floor((-math.pi / 2 - tooth0_angle - theta2) / pitch)
    h = window // 2
    return np.arange(c - h + 1, c - h + 1 + window)


# ----------------------------------------------------------------------------- build

def build_model(scenario: Scenario, gs=None, check_backlash_vs_pieces: bool = True,
                window_teeth: int | None = None) -> BuiltModel:
    """The compiled contact3d model. check_backlash_vs_pieces=False skips wormsim.contact3d.backlash's check (only to measure
    what happens below its limit). window_teeth: wheel tooth slots with collision (default window_size; geo.z2 =
    every tooth, for a standalone file that the viewer can turn without re-posing)."""
    if scenario.gear is None or scenario.drive is None:
        raise ScenarioError("model: contact3d needs gear: and drive: blocks")
    geo, gs = (derive(scenario.gear), gs) if gs is not None else gear_set(scenario)
    # backlash against the pieces' residual bulge (wormsim.contact3d.backlash (2)): exit 2 before the teeth start jammed
    backlash_meta = check_backlash(geo, gs.piece_error_um, scenario.simulation.resolution) \
        if check_backlash_vs_pieces and getattr(gs, "piece_error_um", None) else {}
    mats = scenario.materials
    spec = mujoco.MjSpec.from_file(str(TEMPLATE))
    spec.modelname = scenario.name

    # inertias from densities
    m1, I1 = _axial_inertia(gs.worm_visual, mats.worm.density_kg_m3, 0.0, geo.r1, geo.worm_length)
    m2, I2 = _axial_inertia(gs.wheel_visual, mats.wheel.density_kg_m3, 0.0, geo.r2, geo.face_width)
    arm1, arm2 = mesh_arms(geo)
    # driven-machine inertia J on the loaded shaft (joint armature) belongs to that shaft's effective mass
    j_load = scenario.load.inertia_kg_m2
    J1, J2 = (j_load, 0.0) if scenario.load.on == "worm" else (0.0, j_load)
    inv_mass_hat = arm1 ** 2 / (I1 + J1) + arm2 ** 2 / (I2 + J2)
    slabs = max(1, _slabs_per_flank(gs))
    law = contact_law(scenario.contact, mats, geo.face_width, slabs, inv_mass_hat)
    mu0 = float(friction_coefficient(scenario.contact, 0.0))
    mu_max = max(mu0, float(friction_coefficient(scenario.contact, 1.0)))
    law = replace(law, impratio=friction_impratio(law, mu_max, nominal_normal_force_n(scenario, geo),
                                                  scenario.contact.transition_velocity_m_s))

    worm_b, wheel_b = spec.body("worm"), spec.body("wheel")
    Tw = _assembly(geo, "worm", 0.0)
    Tg = _assembly(geo, "wheel", 0.0)
    if not np.allclose(Tg, np.eye(4), atol=1e-12):
        raise RuntimeError("meshgen.assembly: the wheel frame must coincide with the assembly frame at theta2 = 0")
    worm_b.pos = Tw[:3, 3]
    worm_b.quat = _mat2quat(Tw[:3, :3])
    # transverse moments of a solid cylinder of the part's length, Izz / 2 + m L^2 / 12: irrelevant on a hinge,
    # but they must satisfy the triangle inequality with a margin that survives the 6 digits of a written MJCF
    for body, mass, izz, length in ((worm_b, m1, I1, geo.worm_length), (wheel_b, m2, I2, geo.face_width)):
        body.explicitinertial = True
        body.mass = mass
        body.ipos = [0, 0, 0]
        ixx = izz / 2 + mass * length ** 2 / 12
        body.inertia = [ixx, ixx, izz]

    def add_mesh(name, mesh):
        me = spec.add_mesh()
        me.name = name
        me.uservert = np.asarray(mesh.vertices, dtype=np.float32).ravel()
        me.userface = np.asarray(mesh.faces, dtype=np.int32).ravel()
        me.inertia = mujoco.mjtMeshInertia.mjMESH_INERTIA_CONVEX
        return me

    def set_contact(g):
        g.solref = law.solref
        g.solimp = law.solimp
        g.friction = [mu0, 0.0, 0.0]
        g.margin = 0.0

    add_mesh("worm_visual", gs.worm_visual)
    add_mesh("wheel_visual", gs.wheel_visual)
    for b, name, rgba in ((worm_b, "worm_visual", (0.55, 0.6, 0.7, 1)), (wheel_b, "wheel_visual", (0.85, 0.65, 0.3, 1))):
        g = b.add_geom(default=spec.find_default("visual"))
        g.name, g.meshname, g.rgba = name, name, rgba
    worm_names = []
    for i, piece in enumerate(gs.worm_pieces):
        add_mesh(f"worm_piece_{i}", piece)
        g = worm_b.add_geom(default=spec.find_default("worm_collision"))
        g.name = g.meshname = f"worm_piece_{i}"
        set_contact(g)
        worm_names.append(g.name)
    for j, piece in enumerate(gs.wheel_tooth_pieces):
        add_mesh(f"tooth_piece_{j}", piece)
    W = window_size(geo) if window_teeth is None else int(min(max(window_teeth, 1), geo.z2))
    tooth0 = _tooth0_angle(gs)
    ks = window_teeth_at(0.0, geo.z2, W, tooth0)
    slot_names = [[None] * len(gs.wheel_tooth_pieces) for _ in range(W)]
    for k in ks:
        s = int(k % W)
        ang = 2 * math.pi * k / geo.z2
        # one rigid child body per slot (no joint): re-posing a slot moves its body, so MuJoCo's per-body
        # bounding-volume hierarchy (built at compile time in the body frame) stays valid
        sb = wheel_b.add_body()
        sb.name = f"slot{s}"
        sb.quat = [math.cos(ang / 2), 0, 0, math.sin(ang / 2)]
        sb.explicitinertial = True
        sb.mass = 1e-9
        sb.inertia = [1e-15, 1e-15, 1e-15]
        for j in range(len(gs.wheel_tooth_pieces)):
            g = sb.add_geom(default=spec.find_default("wheel_collision"))
            g.name = f"slot{s}_piece{j}"
            g.meshname = f"tooth_piece_{j}"
            set_contact(g)
            slot_names[s][j] = g.name

    # drive and load
    drv, load = scenario.drive, scenario.load
    direction = expected_direction(scenario, geo)
    drive_joint = f"{drv.on}_hinge"
    load_joint = f"{load.on}_hinge"
    a = spec.add_actuator()
    a.name, a.target, a.trntype = "drive", drive_joint, mujoco.mjtTrn.mjTRN_JOINT
    meta = {"worm_mass_kg": m1, "wheel_mass_kg": m2, "worm_inertia_kg_m2": I1, "wheel_inertia_kg_m2": I2,
            "window_teeth": W, "worm_pieces": len(gs.worm_pieces), "tooth_pieces": len(gs.wheel_tooth_pieces),
            **backlash_meta}
    if drv.speed_rpm is not None:
        w_cmd = abs(rpm_to_rad_s(drv.speed_rpm))
        eta = efficiency_theory(geo.gamma, geo.alpha_n, float(friction_coefficient(scenario.contact, 1.0)),
                                backdriving=drv.on == "wheel")
        if drv.on == "worm":
            t_exp = abs(load.torque_nm) / geo.ratio / max(eta, 0.05)
        else:
            t_exp = abs(load.torque_nm) * geo.ratio / max(eta, 0.05)
        t_exp = max(t_exp, 1e-3)
        kv = t_exp / (SPEED_DROOP * max(w_cmd, 1e-3))
        a.set_to_velocity(kv=kv)
        meta["drive_kv_nm_s"] = kv
        drive_sign = int(np.sign(drv.speed_rpm)) or 1
    else:
        a.set_to_motor()
        drive_sign = int(np.sign(drv.torque_nm)) or 1
    a.ctrllimited = False
    lo = spec.add_actuator()
    lo.name, lo.target, lo.trntype = "load", load_joint, mujoco.mjtTrn.mjTRN_JOINT
    lo.set_to_motor()
    lo.ctrllimited = False
    spec.joint(load_joint).armature = j_load
    meta["load_inertia_kg_m2"] = j_load

    o = spec.option
    o.timestep = default_timestep(law) if scenario.simulation.timestep_s is None else scenario.simulation.timestep_s
    o.impratio = law.impratio      # friction rows' hardness, wormsim.contact3d.law (3)
    if scenario.simulation.speculative:
        o.enableflags |= int(mujoco.mjtEnableBit.mjENBL_SPECULATIVE)
    o.integrator = {"implicitfast": mujoco.mjtIntegrator.mjINT_IMPLICITFAST, "rk4": mujoco.mjtIntegrator.mjINT_RK4,
                    "euler": mujoco.mjtIntegrator.mjINT_EULER, "implicit": mujoco.mjtIntegrator.mjINT_IMPLICIT,
                    "discrete": mujoco.mjtIntegrator.mjINT_DISCRETE}[scenario.simulation.integrator]

    sen = spec.add_sensor()
    sen.name, sen.type = "mesh_force", mujoco.mjtSensor.mjSENS_CONTACT
    sen.objtype, sen.objname = mujoco.mjtObj.mjOBJ_BODY, "worm"
    sen.reftype, sen.refname = mujoco.mjtObj.mjOBJ_XBODY, "wheel"   # XBODY: the wheel's subtree (its slots)
    sen.intprm[0] = MESH_SENSOR_DATA
    sen.intprm[1] = 3       # reduce = netforce
    sen.intprm[2] = 1       # num

    model = spec.compile()
    geom_id = lambda n: mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_GEOM, n)  # noqa: E731
    slot_geoms = np.array([[geom_id(n) for n in row] for row in slot_names], dtype=int)
    slot_bodies = np.array([mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, f"slot{i}") for i in range(W)])
    _set_inv_mass_hat(model, law, arm1 ** 2 / (I1 + J1), arm2 ** 2 / (I2 + J2), slot_bodies)
    jid = lambda n: mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, n)  # noqa: E731
    bm = BuiltModel(
        model=model, spec=spec, geometry=geo, law=law,
        worm_body=mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "worm"),
        wheel_body=mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "wheel"),
        worm_dof=int(model.jnt_dofadr[jid("worm_hinge")]), wheel_dof=int(model.jnt_dofadr[jid("wheel_hinge")]),
        drive_actuator=mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, "drive"),
        load_actuator=mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, "load"),
        worm_geoms=np.array([geom_id(n) for n in worm_names], dtype=int),
        wheel_slot_geoms=slot_geoms, slot_bodies=slot_bodies,
        window_teeth=W, tooth0_angle_rad=tooth0, direction=direction, drive_sign=drive_sign, pieces=gs, meta=meta)
    if check_backlash_vs_pieces:
        # the model itself at the rigid-conjugate pose (wormsim.contact3d.backlash.check_conjugate_interference): exit 2
        meta["conjugate_interference_m"] = check_conjugate_interference(
            bm, scenario.simulation.resolution, nominal_normal_force_n(scenario, geo))
    return bm


def _slabs_per_flank(gs) -> int:
    """n_ref: wheel-tooth pieces across the face width on one flank (meshgen may split a tooth
    into flank pieces; a piece spanning both flanks counts once per flank)."""
    res = getattr(gs, "resolution", None)
    if getattr(res, "wheel_slabs", None):
        return int(res.wheel_slabs)
    zs = [round(float(np.mean(p.vertices[:, 2])), 9) for p in gs.wheel_tooth_pieces]
    return len(set(zs))


def _tooth0_angle(gs) -> float:
    """Angle of tooth 0's centre (mean of its pieces' centroids) in the wheel frame."""
    c = np.mean([p.centroid for p in gs.wheel_tooth_pieces], axis=0)
    return math.atan2(c[1], c[0])


def _rotz(a: float) -> np.ndarray:
    c, s = math.cos(a), math.sin(a)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1.0]])


def _set_inv_mass_hat(model: mujoco.MjModel, law: ContactLaw, a_worm: float, a_wheel: float,
                      slot_bodies: np.ndarray) -> None:
    """Make MuJoCo's diagonal approximation of a worm-wheel contact row equal A_hat (wormsim.contact3d.law (1)):
    body_invweight0[worm] + body_invweight0[slot body] = A_hat."""
    wb = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "worm")
    gb = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, "wheel")
    model.body_invweight0[wb, 0] = a_worm
    model.body_invweight0[gb, 0] = a_wheel
    model.body_invweight0[slot_bodies, 0] = a_wheel
    assert abs(a_worm + a_wheel - law.inv_mass_hat) <= 1e-9 * law.inv_mass_hat


def repose_window(bm: BuiltModel, theta2: float, current: np.ndarray | None = None) -> np.ndarray:
    """Place the window slots on the W teeth nearest the line of centres; returns the tooth indices."""
    ks = window_teeth_at(theta2, bm.geometry.z2, bm.window_teeth, bm.tooth0_angle_rad)
    if current is not None and np.array_equal(ks, current):
        return current
    m = bm.model
    for k in ks:
        if current is not None and k in current:
            continue
        ang = 2 * math.pi * k / bm.geometry.z2
        m.body_quat[bm.slot_bodies[int(k % bm.window_teeth)]] = [math.cos(ang / 2), 0, 0, math.sin(ang / 2)]
    return ks


def round_down_125(h: float) -> float:
    """Largest 1, 2 or 5 x 10^e not above h, as the decimal value (5e-06, not 5 * 10.0 ** -6 = 4.9999999999999996e-06)."""
    e = math.floor(math.log10(h))
    for mant in (5, 2, 1):
        if float(f"{mant}e{e}") <= h * (1 + 1e-12):
            return float(f"{mant}e{e}")
    return float(f"1e{e}")


def default_timestep(law: ContactLaw, contacts: int | None = None) -> float:
    """0.4 x the explicit stability limit with `contacts` (default 3 pairs' worth) in parallel,
    rounded down to 1-2-5 steps."""
    n = contacts if contacts is not None else 3 * law.contacts_per_pair
    return round_down_125(0.4 * law.stable_timestep_s(n))


# ----------------------------------------------------------------------------- standalone MJCF

def write_model(scenario: Scenario, out_dir: str | Path) -> Path:
    """DIR/model.xml + DIR/meshes/*.stl: opens with `python -m mujoco.viewer --mjcf DIR/model.xml`.

    The standalone file gives every wheel tooth its collision pieces (the viewer does not re-pose a window,
    so the wheel can turn any number of turns), and MuJoCo recomputes body_invweight0 on load, so its
    contact stiffness differs from a wormsim run's.
    """
    out = Path(out_dir)
    (out / "meshes").mkdir(parents=True, exist_ok=True)
    geo = derive(scenario.gear) if scenario.gear is not None else None
    bm = build_model(scenario, window_teeth=geo.z2 if geo is not None else None)
    spec = bm.spec
    import trimesh

    for me in spec.meshes:
        v = np.asarray(me.uservert, dtype=float).reshape(-1, 3)
        f = np.asarray(me.userface, dtype=int).reshape(-1, 3)
        trimesh.Trimesh(v, f, process=False).export(out / "meshes" / f"{me.name}.stl")
        me.uservert = []
        me.userface = []
        me.file = f"{me.name}.stl"
    spec.meshdir = "meshes"
    spec.modelfiledir = str(out.resolve())
    path = out / "model.xml"
    path.write_text(spec.to_xml())
    mujoco.MjModel.from_xml_path(str(path))      # fail here, not in the user's viewer
    return path
