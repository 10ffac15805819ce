"""`WormPair`: a worm gear pair with exact-flank tooth contact as a component of any MuJoCo model.

    import mujoco, wormsim
    pair = wormsim.WormPair.from_scenario("scenarios/screw_jack.yaml")   # gear, materials, contact law, errors, shafts
    spec = mujoco.MjSpec.from_file("my_machine.xml")
    pair.attach(spec, parent="housing")        # worm + wheel bodies, hinges, inertias under that body
    worm_joint, wheel_joint = pair.joint_names  # the user's actuators, tendons, equalities go on these
    model = spec.compile(); data = mujoco.MjData(model)
    for _ in range(n):
        pair.step(model, data)                  # one MuJoCo step with the exact-flank contacts
    ft, fr, fa = pair.mesh_forces(data)         # forces on the wheel [N]

What `attach` adds under the parent body, placed in the parent's frame as the geometry contract (docs/geometry.md)
places them in the assembly frame (wheel axis z through the origin, worm axis parallel to x at
y = -a; `pos`/`quat` move that frame within the parent): a wheel body and a worm body, one hinge each about their
own z axis (named `<prefix>wheel_hinge`, `<prefix>worm_hinge`), their masses and axial moments from the solid meshes
and the materials' densities (wormsim.contact3d.mjcf's inertias), and one visual mesh geom each
(`<prefix>worm_visual`, `<prefix>wheel_visual`, contype/conaffinity 0: MuJoCo never collides them itself). The
scenario's errors: block places and tilts the bodies as contact3d does (meshgen.displaced), and its shafts: block
puts them on compliant bearings with the worm shaft bending, as contact3d does (wormsim.contact3d.shafts: carrier
and bend bodies, `shaft_loads`). The scenario's drive: and load: blocks add nothing: the drive and the load are the
user's model. They only set the working point the contact law's friction rows are sized for (wormsim.contact3d.law
(3), (4)).

What a step does: MuJoCo's own step, split so that the flank contacts are added between mj_collision and
mj_makeConstraint (wormsim.contact3d.native.split_step), so the user's contacts, actuators, tendons, equalities
and the model's timestep and integrator all stay MuJoCo's. The exact-flank kernel (wormsim.tooth.kernel) takes the
bodies' poses from the data (d.xpos, d.xmat after the kinematics, wormsim.tooth.pose), so a moving or compliant
housing meshes; the friction coefficient follows the sliding speed mu(Vs), Vs = |omega1| r1 / cos(gamma), omega1
the worm hinge's speed relative to its parent, at every step.

Several pairs in one model: one WormPair per pair (each with its own prefix), stepped together by
`step(model, data, pairs)` (`wormsim.step`): all their contacts enter one constraint solve. Calling `pair.step` of
each pair in turn would step the model once per pair.

What the pair changes in the user's model (it needs them): `attach` sets the elliptic friction cone and raises
opt.impratio to the contact law's (the friction rows' hardness, wormsim.contact3d.law (3); it applies to the model's
other contacts too), and the first step sets body_invweight0 of the worm and the wheel body to the law's shares of
A_hat (wormsim.contact3d.law (1): the flank contacts' stiffness is the law's whatever the rest of the model weighs).
Refused, with a clear error: a timestep above the contact's stable limit (`stable_timestep_s`, named in the
message), the RK4 integrator (its stages cannot take the added contacts), a worm turning more than
MAX_WORM_TURN_PER_STEP_RAD per step.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from types import SimpleNamespace

import mujoco
import numpy as np

from meshgen import assembly
from meshgen import wheel as mwheel
from meshgen.displaced import Deviations, wheel_mount, worm_mount
from wormsim.contact3d import shafts
from wormsim.contact3d.flank_step import FlankContacts
from wormsim.contact3d.mjcf import Prepared, prepare
from wormsim.contact3d.native import split_step
from wormsim.contact3d.timestep import MAX_WORM_TURN_PER_STEP_RAD, OVERSPEED_GUARD, default_timestep
from wormsim.physics.friction import friction_coefficient_scalar
from wormsim.physics.geometry import displaced_pair
from wormsim.scenario import Scenario, load_scenario
from wormsim.tooth.window import window_size

__all__ = ["PairStepError", "WormPair", "step"]


class PairStepError(ValueError):
    """A model the pair cannot step: timestep above the contact's stable limit, RK4, the worm overspeeding."""


def _frame(pos: Sequence[float], quat: Sequence[float]) -> np.ndarray:
    """4x4 transform of (pos, quat w x y z)."""
    T = np.eye(4)
    R = np.zeros(9)
    q = np.asarray(quat, dtype=float)
    mujoco.mju_quat2Mat(R, q / np.linalg.norm(q))
    T[:3, :3] = R.reshape(3, 3)
    T[:3, 3] = pos
    return T


class _Binding:
    """A pair's ids and contacts in one compiled model."""

    def __init__(self, pair: WormPair, model: mujoco.MjModel):
        names = pair._names()
        if names is None:
            raise RuntimeError("WormPair.attach(spec, ...) first, then compile the spec and step")

        def oid(kind: mujoco.mjtObj, name: str) -> int:
            i = mujoco.mj_name2id(model, kind, name)
            if i < 0:
                raise ValueError(
                    f"the model has no {kind.name[6:].lower()} {name!r}: compile the spec the pair was attached to"
                )
            return i

        J, B = mujoco.mjtObj.mjOBJ_JOINT, mujoco.mjtObj.mjOBJ_BODY
        p = pair.plan
        self.model = model
        self.worm_body = oid(B, names["worm_body"])
        self.wheel_body = oid(B, names["wheel_body"])
        self.parent_body = oid(B, names["parent"]) if names["parent"] != "world" else 0
        jw, jg = oid(J, names["worm_hinge"]), oid(J, names["wheel_hinge"])
        self.worm_dof, self.wheel_dof = int(model.jnt_dofadr[jw]), int(model.jnt_dofadr[jg])
        geo = p.geometry
        bm = SimpleNamespace(
            model=model,
            geometry=geo,
            law=p.law,
            plan=p,
            meta={
                "flank_contacts": "slice",
                "flank_geoms": (names["worm_geom"], names["wheel_geom"]),
                "poses_from_data": True,  # a moving housing, the shafts (wormsim.contact3d.flank_step)
                "margin_rad": shafts.mesh_margin_rad(pair.supports, p.normal_force_n, geo),
            },
            window_teeth=window_size(geo),
            worm_dof=self.worm_dof,
            wheel_dof=self.wheel_dof,
            worm_body=self.worm_body,
            wheel_body=self.wheel_body,
            tooth0_angle_rad=mwheel.tooth_angle(geo, 0),
            deviations=pair.deviations,
            tooth_shift_rad=pair.tooth_shift_rad,
        )
        # the law's A_hat (wormsim.contact3d.law (1)) on the two bodies the flank contacts act between
        model.body_invweight0[self.worm_body, 0] = p.inv_mass_worm
        model.body_invweight0[self.wheel_body, 0] = p.inv_mass_wheel
        self.contacts = FlankContacts(bm, p.law.contacts_per_pair, merge=False)
        self.mu_of = friction_coefficient_scalar(pair.scenario.contact)
        self.vs_per_w1 = geo.r_m1 / math.cos(geo.gamma_m)
        self.R0 = pair._placement[:3, :3]
        self.shaft_log: shafts.ShaftLog | None = None  # WormPair.shaft_loads
        self.k0 = 0  # the pair's contacts in d.contact at the last step: [k0, k0 + n)
        self.n = 0


class WormPair:
    """A worm gear pair with exact-flank tooth contact, to attach to a MuJoCo model (module docstring).

    Build it with `WormPair.from_scenario`. Attributes: `scenario` (the Scenario), `plan` (geometry, inertias, contact
    law: wormsim.contact3d.mjcf.Prepared), `geometry` (meshgen's GearGeometry, SI), `prefix` (names' prefix, set by
    `attach`)."""

    def __init__(self, scenario: Scenario, plan: Prepared, deviations: Deviations | None, tooth_shift_rad):
        self.scenario = scenario
        self.plan = plan
        self.geometry = plan.geometry
        self.deviations = deviations
        self.tooth_shift_rad = tooth_shift_rad
        self.supports = plan.supports  # part -> Support or None (wormsim.contact3d.shafts.support)
        self.prefix: str | None = None
        self.parent: str | None = None
        self._placement = np.eye(4)
        self._binding: _Binding | None = None

    # ------------------------------------------------------------------ construction

    @classmethod
    def from_scenario(cls, source: str | Path | Scenario) -> WormPair:
        """The pair of a scenario (a YAML path or a Scenario): its gear:, materials:, contact:, errors: and shafts:
        blocks.
        The drive: and load: blocks give only the working point the friction rows are sized for (module docstring);
        a driven-machine inertia (load.inertia_kg_m2) and mass scaling are not used: the user's model holds its
        machine. contact.flank_contacts is taken as slice (one MuJoCo contact per face slice)."""
        sc = source if isinstance(source, Scenario) else load_scenario(source)
        load = sc.load.model_copy(update={"inertia_kg_m2": 0.0})
        sim = sc.simulation.model_copy(update={"mass_scaling": 1})
        sc = sc.model_copy(update={"load": load, "simulation": sim})
        if sc.contact.geometry != "flanks":
            sc = sc.model_copy(update={"contact": sc.contact.model_copy(update={"geometry": "flanks"})})
        plan = prepare(sc)
        geo = plan.geometry
        disp = displaced_pair(sc.errors, geo)
        dev = disp[0] if disp is not None else None
        shift = dev.tooth_angle_shift(geo, np.arange(geo.z2)) if dev is not None and any(dev.tooth_shift) else None
        return cls(sc, plan, dev, shift)

    # ------------------------------------------------------------------ properties

    @property
    def ratio(self) -> float:
        """Gear ratio z2 / z1 (worm speed / wheel speed)."""
        return float(self.geometry.ratio)

    @property
    def wheel_pitch_radius_m(self) -> float:
        """r2, the wheel's reference radius [m]: a wheel torque T gives a tangential force T / r2."""
        return float(self.geometry.r2)

    @property
    def center_distance_m(self) -> float:
        """a, the centre distance [m]."""
        return float(self.geometry.a)

    @property
    def stable_timestep_s(self) -> float:
        """The contact's explicit stable limit [s] (wormsim.contact3d.law.ContactLaw.stable_limit_s): the largest
        model timestep `step` accepts."""
        return float(self.plan.law.stable_limit_s)

    @property
    def default_timestep_s(self) -> float:
        """The timestep contact3d would use for this pair [s]: 0.4 x the stable limit, rounded down to two digits
        (wormsim.contact3d.timestep.default_timestep)."""
        return float(default_timestep(self.plan.law))

    @property
    def joint_names(self) -> tuple[str, str]:
        """(worm hinge, wheel hinge) names in the model (after `attach`)."""
        if self.prefix is None:
            raise RuntimeError("WormPair.attach(spec, ...) names the joints")
        return f"{self.prefix}worm_hinge", f"{self.prefix}wheel_hinge"

    @property
    def body_names(self) -> tuple[str, str]:
        """(worm body, wheel body) names in the model (after `attach`)."""
        if self.prefix is None:
            raise RuntimeError("WormPair.attach(spec, ...) names the bodies")
        return f"{self.prefix}worm", f"{self.prefix}wheel"

    def _names(self) -> dict | None:
        if self.prefix is None:
            return None
        p = self.prefix
        return {
            "worm_body": f"{p}worm",
            "wheel_body": f"{p}wheel",
            "worm_hinge": f"{p}worm_hinge",
            "wheel_hinge": f"{p}wheel_hinge",
            "worm_geom": f"{p}worm_visual",
            "wheel_geom": f"{p}wheel_visual",
            "parent": self.parent,
        }

    # ------------------------------------------------------------------ attach

    def attach(
        self,
        spec: mujoco.MjSpec,
        parent: str = "world",
        prefix: str | None = None,
        pos: Sequence[float] = (0.0, 0.0, 0.0),
        quat: Sequence[float] = (1.0, 0.0, 0.0, 0.0),
    ) -> tuple[str, str]:
        """Add the worm and the wheel (bodies, hinges, inertias, visual meshes) under body `parent` of `spec`
        ("world": the world body), placed in the parent's frame as the geometry contract places them in the
        assembly frame; `pos` [m] and `quat` (w, x, y, z) put that assembly frame in the parent's frame. `prefix`
        (default: the scenario's name and "_") starts every added name, so several pairs coexist. Sets the elliptic
        friction cone and raises opt.impratio to the law's (module docstring). Returns `joint_names`."""
        if self.prefix is not None:
            raise RuntimeError(f"this pair is attached already (prefix {self.prefix!r}): one WormPair per pair")
        prefix = f"{self.scenario.name}_" if prefix is None else prefix
        if parent in ("world", None):
            pb, parent = spec.worldbody, "world"
        else:
            pb = spec.body(parent)
            if pb is None:
                have = [b.name for b in spec.bodies if b.name]
                raise ValueError(f"attach: no body {parent!r} in the spec (bodies: {', '.join(have) or 'none'})")
        for name in (f"{prefix}worm", f"{prefix}wheel"):
            if spec.body(name) is not None:
                raise ValueError(f"attach: the spec has a body {name!r} already: give each pair its own prefix=")
        p, geo, dev = self.plan, self.geometry, self.deviations
        T0 = _frame(pos, quat)
        self._placement = T0
        ine = p.inertias
        if dev is not None:
            mounts = {"worm": worm_mount(geo, dev), "wheel": wheel_mount(geo, dev)}
        else:
            Tw = np.asarray(assembly.worm_to_assembly(0.0, geo), dtype=float)
            mounts = {"worm": (Tw, np.eye(4)), "wheel": (np.eye(4), np.eye(4))}
        mu0 = p.gear.mu_static
        meshes = {"worm": p.pieces.worm_visual, "wheel": p.pieces.wheel_visual}
        props = {
            "worm": (ine.worm_mass_kg, ine.worm_inertia_kg_m2, geo.worm_length, (0.55, 0.6, 0.7, 1)),
            "wheel": (ine.wheel_mass_kg, ine.wheel_inertia_kg_m2, geo.face_width, (0.85, 0.65, 0.3, 1)),
        }
        for part in ("wheel", "worm"):
            M, E = mounts[part]
            X = T0 @ M @ E  # body -> parent at hinge angle 0 (meshgen.displaced (1), (2))
            mass, izz, length, rgba = props[part]
            ixx = izz / 2 + mass * length**2 / 12  # a solid cylinder's transverse moment (as contact3d's model)
            # the hinge on the axis of rotation, off the part's axis by the runout; on its bearings (shafts:)
            b = shafts.add_part(
                spec, pb, f"{prefix}{part}", X, -E[:3, 3], mass, [ixx, ixx, izz], self.supports[part], geo.r_f1
            )
            me = spec.add_mesh()
            me.name = f"{prefix}{part}_visual"
            me.uservert = np.asarray(meshes[part].vertices, dtype=np.float32).ravel()
            me.userface = np.asarray(meshes[part].faces, dtype=np.int32).ravel()
            me.inertia = mujoco.mjtMeshInertia.mjMESH_INERTIA_CONVEX
            g = b.add_geom()
            g.name = me.name
            g.type = mujoco.mjtGeom.mjGEOM_MESH
            g.meshname = me.name
            g.contype = g.conaffinity = 0
            g.group = 1
            g.density = 0
            g.rgba = rgba
            g.friction = [mu0, 0.0, 0.0]
            g.solref = p.law.solref
            g.solimp = p.law.solimp
            g.margin = 0.0
        o = spec.option
        o.cone = mujoco.mjtCone.mjCONE_ELLIPTIC
        o.impratio = max(float(o.impratio), float(p.law.impratio))
        self.prefix, self.parent = prefix, parent
        return self.joint_names

    # ------------------------------------------------------------------ stepping

    def bind(self, model: mujoco.MjModel) -> _Binding:
        """The pair's ids and contacts in `model` (made at the first step with that model; checks its options)."""
        b = self._binding
        if b is None or b.model is not model:
            _check_options(self, model)
            b = self._binding = _Binding(self, model)
        return b

    def step(self, model: mujoco.MjModel, data: mujoco.MjData) -> None:
        """One MuJoCo step of the model with this pair's exact-flank contacts (module docstring). With several pairs
        in the model use `step(model, data, pairs)`."""
        step(model, data, [self])

    def contact_count(self) -> int:
        """The pair's flank contacts handed to MuJoCo at the last step."""
        return 0 if self._binding is None else self._binding.n

    def worm_speed_rad_s(self, data: mujoco.MjData) -> float:
        """The worm hinge's speed relative to its parent [rad/s]."""
        return float(data.qvel[self._bound().worm_dof])

    def wheel_speed_rad_s(self, data: mujoco.MjData) -> float:
        """The wheel hinge's speed relative to its parent [rad/s]."""
        return float(data.qvel[self._bound().wheel_dof])

    def shaft_loads(self, data: mujoco.MjData) -> dict[str, float]:
        """The shafts' state at the last step, for parts with a shafts: block (wormsim.contact3d.shafts, ShaftLog):
        `<part>_deflection_mesh_{x,y}_m` (the axis's displacement at the mesh point across the axis, shaft frame),
        `<part>_bearing{0,1}_radial_{x,y}_n` and `<part>_bearing_axial_n` (the bearings' forces on the shaft [N]: a
        compliant bearing's spring, a rigid one's share of the constraint reaction)."""
        b = self._bound()
        if b.shaft_log is None:
            b.shaft_log = shafts.ShaftLog(b.model, self.supports, 1, self.prefix or "")
        b.shaft_log.record(0, data)
        return {k: float(v[0]) for k, v in b.shaft_log.series().items()}

    def _bound(self) -> _Binding:
        if self._binding is None:
            raise RuntimeError("step the model with the pair first (pair.step or wormsim.step)")
        return self._binding

    def mesh_forces(self, data: mujoco.MjData) -> tuple[float, float, float]:
        """(ft, fr, fa) [N]: the resultant of the pair's tooth forces on the wheel at the last step (the contact
        forces of the constraint solve: normal and two friction rows of each flank contact), resolved in the pair's
        assembly frame as it sits in the parent body now, in the sign convention of docs/outputs.md
        (wormsim.results.summary_keys.FORCE_SIGNS, as contact3d's series tangential_force_n, radial_force_n,
        axial_force_n):
        tangential along +x (the wheel's positive sense at the pitch point on the line of centres), radial positive
        towards the wheel axis (+y, the separating force), axial along -hand z (F_a2 = F_t2 tan(gamma + rho') with
        its sign); contact3d's tangential_force_mean_n, radial_force_resultant_mean_n and axial_force_resultant_mean_n
        are the magnitudes of their means (the headline radial_force_mean_n and axial_force_mean_n are DIN 3975's,
        docs/outputs.md "Force keys")."""
        b = self._bound()
        F = np.zeros(3)
        con = data.contact
        k0, n = b.k0, b.n
        if n:
            adr = np.asarray(con.efc_address[k0 : k0 + n])
            ok = adr >= 0
            fr = np.asarray(con.frame[k0 : k0 + n])[ok].reshape(-1, 3, 3)
            f = data.efc_force[adr[ok][:, None] + np.arange(3)]
            F = np.einsum("ni,nij->j", f, fr)  # on geom 2, the wheel
        R = data.xmat[b.parent_body].reshape(3, 3) @ b.R0  # the assembly frame in the world
        x, y, z = R.T @ F
        return float(x), float(y), float(-self.geometry.hand * z)


def _check_options(pair: WormPair, model: mujoco.MjModel) -> None:
    """The model's timestep against the contact's stable limit, and its integrator (module docstring)."""
    h, lim = float(model.opt.timestep), pair.stable_timestep_s
    if h > lim:
        raise PairStepError(
            f"{pair.prefix}: the model's timestep {h:.3g} s is above the exact-flank contact's stable limit "
            f"{lim:.3g} s (contact stiffness {pair.plan.law.pair_stiffness_n_per_m:.3g} N/m per tooth pair against "
            f"the pair's effective mass {pair.plan.law.effective_mass_kg:.3g} kg; wormsim.contact3d.law): set "
            f"model.opt.timestep <= {lim:.3g} s (contact3d uses {pair.default_timestep_s:.3g} s for this pair)"
        )
    try:  # the shafts' bearing and bending springs (wormsim.contact3d.shafts)
        shafts.check_timestep(model, h, pair.prefix or "")
    except ValueError as e:
        raise PairStepError(f"{pair.prefix}: {e}") from None
    if model.opt.integrator == mujoco.mjtIntegrator.mjINT_RK4:
        raise PairStepError(
            f"{pair.prefix}: the RK4 integrator cannot take the added flank contacts (its stages run MuJoCo's "
            f"collision alone): use implicitfast (contact3d's), implicit or Euler"
        )
    if model.opt.cone != mujoco.mjtCone.mjCONE_ELLIPTIC:
        raise PairStepError(f"{pair.prefix}: the flank contacts need the elliptic cone (attach sets it)")


def step(model: mujoco.MjModel, data: mujoco.MjData, pairs: Sequence[WormPair]) -> None:
    """One MuJoCo step of `model` with the exact-flank contacts of every pair in `pairs` in one constraint solve
    (wormsim.contact3d.native.split_step: MuJoCo's step with the contacts added after its collision). The
    model's timestep and integrator are used as they are (module docstring for what is refused)."""
    bound = [p.bind(model) for p in pairs]
    h = float(model.opt.timestep)
    for p, b in zip(pairs, bound, strict=True):
        w1 = float(data.qvel[b.worm_dof])
        if abs(w1) * h > OVERSPEED_GUARD * MAX_WORM_TURN_PER_STEP_RAD:
            raise PairStepError(
                f"{p.prefix}: the worm turns {abs(w1) * h:.3g} rad per step (at {abs(w1):.4g} rad/s); the exact-flank "
                f"contact resolves at most {MAX_WORM_TURN_PER_STEP_RAD} rad: timestep <= "
                f"{MAX_WORM_TURN_PER_STEP_RAD / max(abs(w1), 1e-12):.3g} s at this speed"
            )
        b.contacts.set_friction(b.mu_of(abs(w1) * b.vs_per_w1))

    def add(m: mujoco.MjModel, d: mujoco.MjData) -> None:
        for b in bound:
            b.k0 = d.ncon
            b.contacts.add(m, d)
            b.n = d.ncon - b.k0

    split_step(model, data, add)
