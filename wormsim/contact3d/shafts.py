"""Worm and wheel shafts on compliant bearings, and the worm shaft's bending, as MuJoCo bodies and joints (the
scenario's `shafts:` block; absent: the rigid hinges of wormsim.contact3d.mjcf).

Each shaft with a `shafts.<part>` block sits on a carrier body placed where the rigid model puts the part (its frame:
z the shaft axis, origin at the mesh point on the axis, which is where the line of centres meets it). The carrier
moves on joints relative to the parent (the world, or the housing of wormsim.pair):

- radial (radial_stiffness_n_per_um given): slides along x and y and hinges about x and y through the mesh point. A
  point of the axis at s (along z, from the mesh point) moves by (u_x + s phi_y, u_y - s phi_x); bearing i at s_i
  (bearings_mm) is a fixed tendon of that length in each direction with the bearing's radial stiffness k_r, so the
  tendons' spring forces -k_r L are the bearing forces, and the shaft rests on two springs as on its bearings;
- axial (axial_stiffness_n_per_um given): a slide along z with the locating bearing's axial stiffness k_a.
Omitted stiffnesses are rigid (no joint). The bearings' damping is DAMPING_RATIO of critical against the shaft's mass.

Bending of the worm shaft (bending: true): a lumped beam. Between the carrier and the worm body a bend body moves on
two slides across the axis with the stiffness of a simply supported beam under a point load at the mesh point, a
distance l1 from one bearing and l2 from the other (L = l1 + l2):

    k_b = 3 E I L / (l1^2 l2^2),   I = pi d_f1^4 / 64                                                      (1)

(the deflection under the load F a^2 b^2 / (3 E I L), Roark's Formulas for Stress and Strain, table 8.1 case 1e;
l1 = l2 = L / 2 gives 48 E I / L^3), E the worm material's Young's modulus and d_f1 the worm's root diameter (the
section the thread stands on). The shaft's slope at the mesh point (zero for a load midway) is not modelled: the
worm body translates. Masses: the shaft between the bearings, rho pi d_f1^2 / 4 L, is split half onto the carrier
(the bearings' share) and half onto the bend body (a simply supported beam's first mode has half its mass as modal
mass); without bending all of it rides on the carrier. The worm body keeps its own mass and inertia.

The exact-flank kernel takes the bodies' poses from MuJoCo each step (wormsim.tooth.pose), so the contact follows
the shafts; its candidate window is widened for the expected mesh displacement (margin_rad).

Outputs (ShaftLog): the mesh point's displacement across each axis (worm_deflection_mesh_um,
wheel_deflection_mesh_um: the magnitude of the mean displacement vector over the steady window), the bearings'
radial forces (one per bearing, the magnitude of the mean force vector) and the locating bearing's axial force,
their maxima over the steady window, and their time series. A rigid bearing's force is the constraint's reaction
on the shaft (ShaftLog); a rigid shaft's deflection is 0.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import mujoco
import numba
import numpy as np

from meshgen.geometry import GearGeometry
from wormsim.contact3d.native import f64_at
from wormsim.scenario import Materials, ScenarioError, Shafts, ShaftSupport

DAMPING_RATIO = 0.05  # bearings' and bending's damping, share of critical against the shaft's mass (an assumption:
# rolling-bearing supports are lightly damped; it only settles the shaft modes, the static results do not use it)
TINY_MASS_KG = 1e-9  # a carrier without a shaft mass of its own (the wheel's)
STABLE_SHARE = 0.8  # the timestep may use at most this share of the stiffest shaft mode's explicit limit 2 / omega
MARGIN_FACTOR = 3.0  # the candidate window covers this many times the static mesh displacement at the working load
SOLVER = mujoco.mjtSolver.mjSOL_CG  # the constraint solver of a model whose shafts move (set_solver)


def beam_stiffness_n_per_m(youngs_modulus_pa: float, second_moment_m4: float, l1_m: float, l2_m: float) -> float:
    """(1): a simply supported beam's stiffness under a point load l1 from one support and l2 from the other,
    3 E I L / (l1^2 l2^2) (Roark, table 8.1 case 1e); 48 E I / L^3 midway."""
    L = l1_m + l2_m
    return 3.0 * youngs_modulus_pa * second_moment_m4 * L / (l1_m**2 * l2_m**2)


def root_second_moment_m4(root_diameter_m: float) -> float:
    """I = pi d^4 / 64 of a solid round section."""
    return math.pi * root_diameter_m**4 / 64.0


@dataclass(frozen=True)
class Support:
    """One shaft's supports in SI (from ShaftSupport)."""

    bearings_m: tuple[float, float]
    locating: int
    radial_n_per_m: float | None
    axial_n_per_m: float | None
    bend_n_per_m: float | None
    shaft_mass_kg: float  # between the bearings (0: not known, the wheel's)
    shaft_length_m: float

    @property
    def moves(self) -> bool:
        return self.radial_n_per_m is not None or self.axial_n_per_m is not None or self.bend_n_per_m is not None


def support(sh: Shafts | None, materials: Materials, geo: GearGeometry, part: str) -> Support | None:
    """The part's Support from the scenario's shafts: block sh (None without one); materials: the worm's."""
    s: ShaftSupport | None = getattr(sh, part) if sh is not None else None
    if s is None:
        return None
    b = (s.bearings_mm[0] * 1e-3, s.bearings_mm[1] * 1e-3)
    L = b[1] - b[0]
    bend = mass = None
    if part == "worm":
        d_f1 = 2 * geo.r_f1
        mass = materials.worm.density_kg_m3 * math.pi * d_f1**2 / 4 * L
        if s.bending:
            E = materials.worm.youngs_modulus_gpa * 1e9
            bend = beam_stiffness_n_per_m(E, root_second_moment_m4(d_f1), -b[0], b[1])
    return Support(
        bearings_m=b,
        locating=s.locating_bearing,
        radial_n_per_m=None if s.radial_stiffness_n_per_um is None else s.radial_stiffness_n_per_um * 1e6,
        axial_n_per_m=None if s.axial_stiffness_n_per_um is None else s.axial_stiffness_n_per_um * 1e6,
        bend_n_per_m=bend,
        shaft_mass_kg=mass or 0.0,
        shaft_length_m=L,
    )


def _quat(R: np.ndarray) -> np.ndarray:
    q = np.zeros(4)
    mujoco.mju_mat2Quat(q, np.ascontiguousarray(R, dtype=float).ravel())
    return q


def _joint(body, name: str, kind, axis, stiffness: float = 0.0, damping: float = 0.0):
    j = body.add_joint()
    j.name, j.type, j.axis = name, kind, list(axis)
    j.stiffness = [stiffness, 0.0, 0.0]  # MuJoCo 4: linear, then higher-order terms
    j.springref = 0.0
    j.damping = [damping, 0.0, 0.0]
    return j


def _cylinder_inertia(mass: float, length: float, radius: float) -> list[float]:
    ixx = mass * (3 * radius**2 + length**2) / 12
    return [ixx, ixx, mass * radius**2 / 2]


def add_part(
    spec: mujoco.MjSpec,
    parent,
    name: str,
    X: np.ndarray,
    hinge_pos: np.ndarray,
    mass_kg: float,
    inertia_kg_m2: list[float],
    sup: Support | None,
    radius_m: float,
):
    """The part's body (`name`, hinge `name`_hinge about its z at hinge_pos) under `parent` (an MjsBody) at the 4x4
    placement X, on its carrier (`name`_carrier) and bend body (`name`_bend) where `sup` asks for them (module
    docstring). radius_m: the shaft section's radius (the carrier's inertia). Returns the part's MjsBody."""
    holder, pos, quat = parent, X[:3, 3], _quat(X[:3, :3])
    SLIDE, HINGE = mujoco.mjtJoint.mjJNT_SLIDE, mujoco.mjtJoint.mjJNT_HINGE
    if sup is not None and sup.moves:
        m_shaft = sup.shaft_mass_kg
        m_c = (0.5 if sup.bend_n_per_m is not None else 1.0) * m_shaft
        m_c = max(m_c, TINY_MASS_KG)
        # the damping's mass: the shaft and the part riding on it
        m_d = m_shaft + mass_kg
        c = holder.add_body()
        c.name = f"{name}_carrier"
        c.pos, c.quat = pos, quat
        c.explicitinertial = True
        c.mass = m_c
        c.inertia = _cylinder_inertia(m_c, sup.shaft_length_m, radius_m)
        c.ipos = [0, 0, 0.5 * (sup.bearings_m[0] + sup.bearings_m[1])]
        kr = sup.radial_n_per_m
        if kr is not None:
            cr = 2 * DAMPING_RATIO * math.sqrt(kr * m_d)
            jx = _joint(c, f"{name}_radial_x", SLIDE, (1, 0, 0))
            jy = _joint(c, f"{name}_radial_y", SLIDE, (0, 1, 0))
            tx = _joint(c, f"{name}_tilt_x", HINGE, (1, 0, 0))
            ty = _joint(c, f"{name}_tilt_y", HINGE, (0, 1, 0))
            for i, s in enumerate(sup.bearings_m):
                for axis, pairs in (("x", ((jx, 1.0), (ty, s))), ("y", ((jy, 1.0), (tx, -s)))):
                    t = spec.add_tendon()
                    t.name = f"{name}_bearing{i}_{axis}"
                    t.stiffness = [kr, 0.0, 0.0]
                    t.damping = [cr, 0.0, 0.0]
                    t.springlength = [0.0, 0.0]
                    for j, coef in pairs:
                        t.wrap_joint(j.name, coef)
        ka = sup.axial_n_per_m
        if ka is not None:
            _joint(c, f"{name}_axial", SLIDE, (0, 0, 1), ka, 2 * DAMPING_RATIO * math.sqrt(ka * m_d))
        holder, pos, quat = c, np.zeros(3), np.array([1.0, 0, 0, 0])
        kb = sup.bend_n_per_m
        if kb is not None:
            b = holder.add_body()
            b.name = f"{name}_bend"
            m_b = 0.5 * m_shaft
            b.explicitinertial = True
            b.mass = max(m_b, TINY_MASS_KG)
            b.ipos = [0, 0, 0]
            b.inertia = [max(m_b * radius_m**2 / 4, 1e-15)] * 2 + [max(m_b * radius_m**2 / 2, 1e-15)]
            cb = 2 * DAMPING_RATIO * math.sqrt(kb * (m_b + mass_kg))
            _joint(b, f"{name}_bend_x", SLIDE, (1, 0, 0), kb, cb)
            _joint(b, f"{name}_bend_y", SLIDE, (0, 1, 0), kb, cb)
            holder = b
    body = holder.add_body()
    body.name = name
    body.pos, body.quat = pos, quat
    body.explicitinertial = True
    body.mass = mass_kg
    body.ipos = [0, 0, 0]
    body.inertia = inertia_kg_m2
    j = body.add_joint()
    j.name, j.type, j.axis = f"{name}_hinge", HINGE, [0, 0, 1]
    j.pos = hinge_pos
    return body


def set_solver(spec: mujoco.MjSpec, sups: dict[str, Support | None]) -> None:
    """MuJoCo's conjugate-gradient solver (SOLVER) for a model with shaft joints: Newton's Hessian of the elliptic
    friction cones grows with nv^2 per contact, and the shafts take nv from 2 to up to 14; CG needs no Hessian and
    converges within MuJoCo's tolerance in a few iterations here (decision 0035, measured there). The rigid model
    (no shafts: block, or only rigid supports) keeps MuJoCo's default, Newton."""
    if any(s is not None and s.moves for s in sups.values()):
        spec.option.solver = SOLVER


def mesh_margin_rad(supports: dict[str, Support | None], normal_force_n: float, geo: GearGeometry) -> float:
    """The kernel's candidate window widened for the mesh displacement: MARGIN_FACTOR x the static displacement of
    the mesh point under the nominal normal force through every spring in series (both shafts), as a wheel angle
    (over r2)."""
    compliance = 0.0
    for sup in supports.values():
        if sup is None:
            continue
        for k in (sup.radial_n_per_m, sup.axial_n_per_m, sup.bend_n_per_m):
            if k is not None:
                compliance += 1.0 / k
    return MARGIN_FACTOR * normal_force_n * compliance / geo.r2


def check_timestep(model: mujoco.MjModel, timestep_s: float, prefix: str = "") -> float:
    """The shaft modes' explicit limit (stable_limit_s); raises ScenarioError naming the keys when the timestep
    exceeds STABLE_SHARE of it. Returns the limit (inf without shaft joints)."""
    lim = stable_limit_s(model, prefix)
    if timestep_s > STABLE_SHARE * lim:
        raise ScenarioError(
            f"simulation.timestep_s = {timestep_s:.3g} s is too large for the shafts' stiffness: the stiffest shaft "
            f"mode's explicit limit is {lim:.3g} s; allowed range: simulation.timestep_s <= "
            f"{STABLE_SHARE * lim:.3g} s, or lower shafts.*.radial_stiffness_n_per_um / axial_stiffness_n_per_um"
        )
    return lim


def stable_limit_s(model: mujoco.MjModel, prefix: str = "") -> float:
    """The shaft modes' explicit limit min 2 / omega_i (omega_i^2 = K_ii / M_ii over the shaft joints: the joint's
    own stiffness plus its tendons' k coef^2 against the mass matrix's diagonal at qpos0); inf without shaft joints."""
    names = ("_radial_", "_tilt_", "_axial", "_bend_")
    dofs = [
        j
        for j in range(model.njnt)
        if any(n in (mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j) or "") for n in names)
        and (mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j) or "").startswith(prefix)
    ]
    if not dofs:
        return math.inf
    d = mujoco.MjData(model)
    mujoco.mj_forward(model, d)
    M = np.zeros((model.nv, model.nv))
    mujoco.mj_fullM(model, d, M)
    K = np.zeros(model.nv)
    for j in dofs:
        K[model.jnt_dofadr[j]] += model.jnt_stiffness[j]
    for t in range(model.ntendon):
        adr, num = model.tendon_adr[t], model.tendon_num[t]
        for w in range(adr, adr + num):
            if model.wrap_type[w] == mujoco.mjtWrap.mjWRAP_JOINT:
                K[model.jnt_dofadr[model.wrap_objid[w]]] += model.tendon_stiffness[t] * model.wrap_prm[w] ** 2
    lim = math.inf
    for j in dofs:
        v = model.jnt_dofadr[j]
        if K[v] > 0:
            lim = min(lim, 2.0 / math.sqrt(K[v] / M[v, v]))
    return lim


class ShaftLog:
    """The shafts' outputs (module docstring), one value per sample: displacements from the joints, a compliant
    bearing's force from its spring (tendon or slide), a rigid bearing's force from the reaction MuJoCo's constraint
    solve puts on the shaft (mj_rnePostConstraint's cfrc_int of the outermost shaft body: the force and moment its
    parent exerts), split over the two bearings by the shaft's statics (bearing_split).

    Per sample the log keeps only the raw mjData values these need (`cols`: (field, flat index) of qpos, ten_length,
    cfrc_int, subtree_com, xpos, xmat), copied by `gather` from their addresses (the compiled samples of
    wormsim.contact3d.flank_samples call the same gather and, where `reactions`, mj_rnePostConstraint first); `series`
    computes the outputs from them for all samples at once."""

    def __init__(self, model: mujoco.MjModel, supports: dict[str, Support | None], n: int, prefix: str = ""):
        self.model = model
        self.supports = supports
        self.n = n

        def jq(name: str) -> int:
            j = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, prefix + name)
            return int(model.jnt_qposadr[j]) if j >= 0 else -1

        def tid(name: str) -> int:
            return mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_TENDON, prefix + name)

        def bid(name: str) -> int:
            return mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, prefix + name)

        self.cols: list[tuple[str, int]] = []
        self.parts: dict[str, dict] = {}
        self.reactions = False
        for part, sup in supports.items():
            if sup is None:
                continue
            carrier = bid(f"{part}_carrier")
            tendons = [(tid(f"{part}_bearing{i}_x"), tid(f"{part}_bearing{i}_y")) for i in range(2)]
            axial = jq(f"{part}_axial")
            ids = {
                "defl": [self._col("qpos", jq(f"{part}_{j}")) for j in ("radial_x", "radial_y", "bend_x", "bend_y")],
                "axial": self._col("qpos", axial),
                "tendons": [(self._col("ten_length", tx), self._col("ten_length", ty)) for tx, ty in tendons],
                "rigid": tendons[0][0] < 0 or axial < 0,
            }
            if ids["rigid"]:
                b = carrier if carrier >= 0 else bid(part)  # the outermost shaft body
                root = int(model.body_rootid[b])
                ids["cfrc"] = [self._col("cfrc_int", 6 * b + k) for k in range(6)]
                ids["com"] = [self._col("subtree_com", 3 * root + k) for k in range(3)]
                ids["xpos"] = [self._col("xpos", 3 * b + k) for k in range(3)]
                ids["xmat"] = [self._col("xmat", 9 * b + k) for k in range(9)]
                ids["hinge"] = -1 if carrier >= 0 else self._col("qpos", jq(f"{part}_hinge"))  # its rotation
            self.reactions |= ids["rigid"]
            self.parts[part] = ids
        self.raw = np.zeros((n, len(self.cols)))
        self._d: mujoco.MjData | None = None
        self._adr = np.zeros(0, dtype=np.int64)

    def _col(self, field: str, index: int) -> int:
        """The raw column of mjData's field at the flat index (-1 for -1: the joint or tendon is absent)."""
        if index < 0:
            return -1
        self.cols.append((field, index))
        return len(self.cols) - 1

    def addresses(self, d: mujoco.MjData) -> np.ndarray:
        """The raw columns' addresses in d (int64; d's arrays stay where mj_makeData put them)."""
        if d is not self._d:
            arrays = {f: getattr(d, f) for f in {f for f, _ in self.cols}}
            adr = [arrays[f].ctypes.data + arrays[f].itemsize * k for f, k in self.cols]
            self._d, self._adr = d, np.array(adr, dtype=np.int64)
        return self._adr

    def record(self, i: int, d: mujoco.MjData) -> None:
        """Sample i: the raw values at this instant (after mj_rnePostConstraint where a bearing is rigid)."""
        if self.reactions:
            mujoco.mj_rnePostConstraint(self.model, d)
        gather(self.addresses(d), self.raw, i)

    def truncate(self, n: int) -> None:
        """Keep the first n samples (a run that ended early: wormsim.physics.locking)."""
        self.raw = self.raw[:n]
        self.n = n

    def series(self) -> dict[str, np.ndarray]:
        """The outputs per sample (shaft frame: z the axis, x and y across it as the rigid model's part frame at hinge
        angle 0): the displacements and the bearings' forces on the shaft."""
        raw = self.raw
        S: dict[str, np.ndarray] = {}

        def col(c: int) -> np.ndarray:
            return raw[:, c]

        for part, ids in self.parts.items():
            sup = self.supports[part]
            a = ids["defl"]
            for ax, (c1, c2) in (("x", (a[0], a[2])), ("y", (a[1], a[3]))):
                v = np.zeros(len(raw))
                for c in (c1, c2):
                    if c >= 0:
                        v = v + col(c)
                S[f"{part}_deflection_mesh_{ax}_m"] = v
            if ids["rigid"]:
                f_loc, m_loc = self._reaction(ids)
                split = bearing_split(f_loc, m_loc, sup.bearings_m)
            if ids["tendons"][0][0] >= 0:
                k = sup.radial_n_per_m
                for b, (tx, ty) in enumerate(ids["tendons"]):
                    S[f"{part}_bearing{b}_radial_x_n"] = -k * col(tx)
                    S[f"{part}_bearing{b}_radial_y_n"] = -k * col(ty)
            else:
                for b in range(2):
                    S[f"{part}_bearing{b}_radial_x_n"] = split[b][0]
                    S[f"{part}_bearing{b}_radial_y_n"] = split[b][1]
            if ids["axial"] >= 0:
                S[f"{part}_bearing_axial_n"] = -sup.axial_n_per_m * col(ids["axial"])
            else:
                S[f"{part}_bearing_axial_n"] = f_loc[:, 2].copy()
        return S

    def _reaction(self, ids: dict) -> tuple[np.ndarray, np.ndarray]:
        """Per sample (force, moment about the mesh point) the parent exerts on the shaft, in the shaft frame."""
        raw = self.raw
        cf = raw[:, ids["cfrc"]]
        torque, force = cf[:, :3], cf[:, 3:]
        c, p = raw[:, ids["com"]], raw[:, ids["xpos"]]
        moment = torque + np.cross(c - p, force)  # about p
        R = raw[:, ids["xmat"]].reshape(-1, 3, 3)
        if ids["hinge"] >= 0:  # the part body turns with its hinge: back to the shaft's own frame
            th = raw[:, ids["hinge"]]
            ct = np.array([math.cos(v) for v in th])
            st = np.array([math.sin(v) for v in th])
            Rz = np.zeros((len(th), 3, 3))
            Rz[:, 0, 0], Rz[:, 0, 1], Rz[:, 1, 0], Rz[:, 1, 1], Rz[:, 2, 2] = ct, st, -st, ct, 1.0
            R = R @ Rz
        Rt = R.transpose(0, 2, 1)
        return (Rt @ force[:, :, None])[:, :, 0], (Rt @ moment[:, :, None])[:, :, 0]

    def summary(self, t: np.ndarray, window: tuple[float, float] | list[float]) -> dict:
        """The shafts' summary keys over the steady window (module docstring; INTERFACE.md, third wave)."""
        sl = (t >= window[0]) & (t <= window[1])
        if not sl.any():
            sl = np.ones_like(t, dtype=bool)
        S = self.series()
        out: dict[str, float | list[float]] = {}
        for part in ("worm", "wheel"):
            if part not in self.parts:
                continue
            ux, uy = S[f"{part}_deflection_mesh_x_m"][sl], S[f"{part}_deflection_mesh_y_m"][sl]
            out[f"{part}_deflection_mesh_um"] = 1e6 * float(np.hypot(ux.mean(), uy.mean()))
            out[f"{part}_deflection_mesh_max_um"] = 1e6 * float(np.hypot(ux, uy).max())
            mean, mx = [], []
            for b in range(2):
                fx, fy = S[f"{part}_bearing{b}_radial_x_n"][sl], S[f"{part}_bearing{b}_radial_y_n"][sl]
                mean.append(float(np.hypot(fx.mean(), fy.mean())))
                mx.append(float(np.hypot(fx, fy).max()))
            out[f"{part}_bearing_radial_mean_n"] = mean
            out[f"{part}_bearing_radial_max_n"] = mx
            fa = S[f"{part}_bearing_axial_n"][sl]
            out[f"{part}_bearing_axial_mean_n"] = abs(float(fa.mean()))
            out[f"{part}_bearing_axial_max_n"] = float(np.abs(fa).max())
        return out


@numba.njit(cache=True, nogil=True)
def gather(adr, raw, i):
    """Row i of raw: the float64 values at the addresses adr (ShaftLog.addresses)."""
    for k in range(adr.shape[0]):
        raw[i, k] = f64_at(adr[k])[0]


def bearing_split(force: np.ndarray, moment: np.ndarray, bearings_m: tuple[float, float]) -> list[tuple]:
    """The radial forces (x, y) of two bearings at s0, s1 on the axis that carry a shaft load (force, moment about
    the mesh point, shaft frame; rows of samples): F_0 + F_1 = F and sum s_i e_z x F_i = M across the axis, i.e.
    s0 Fx0 + s1 Fx1 = M_y and s0 Fy0 + s1 Fy1 = -M_x (a statically determinate two-bearing shaft)."""
    s0, s1 = bearings_m
    fx1 = (moment[..., 1] - s0 * force[..., 0]) / (s1 - s0)
    fy1 = (-moment[..., 0] - s0 * force[..., 1]) / (s1 - s0)
    return [(force[..., 0] - fx1, force[..., 1] - fy1), (fx1, fy1)]


def mount(spec: mujoco.MjSpec, sups: dict[str, Support | None], geo: GearGeometry) -> dict[str, Support | None]:
    """contact3d's model (wormsim.contact3d.mjcf, after its bodies are placed): each part with a Support (support, in
    the run's plan) rebuilt on its carrier (add_part) with the placement, hinge, mass and inertia the rigid model gave
    it."""
    radius = {"worm": geo.r_f1, "wheel": geo.r_f1}  # the wheel's carrier holds no shaft mass (TINY_MASS_KG)
    for part, sup in sups.items():
        if sup is None or not sup.moves:
            continue
        old = spec.body(part)
        X = np.eye(4)
        R = np.zeros(9)
        mujoco.mju_quat2Mat(R, np.asarray(old.quat, dtype=float))
        X[:3, :3], X[:3, 3] = R.reshape(3, 3), np.asarray(old.pos, dtype=float)
        hinge_pos = np.asarray(spec.joint(f"{part}_hinge").pos, dtype=float)
        mass, inertia = float(old.mass), [float(v) for v in old.inertia]
        spec.delete(old)
        add_part(spec, spec.worldbody, part, X, hinge_pos, mass, inertia, sup, radius[part])
    return sups


def model_meta(
    model: mujoco.MjModel, sups: dict[str, Support | None], normal_force_n: float, geo: GearGeometry, timestep_s: float
) -> dict:
    """What contact3d's model carries for the shafts (BuiltModel.meta): the supports, the kernel's poses from the
    data and its widened window (wormsim.contact3d.flank_step), the shaft modes' limit (checked, check_timestep)."""
    return {
        "shafts": sups,
        "poses_from_data": True,
        "margin_rad": mesh_margin_rad(sups, normal_force_n, geo),
        "shaft_stable_limit_s": check_timestep(model, timestep_s),
    }
