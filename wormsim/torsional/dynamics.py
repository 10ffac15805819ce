"""The `torsional` fidelity level: worm and wheel rotations as 2 DOF coupled by a mesh force element
(seed 002's class of model, I theta'' + C theta' + K(t) theta = T(t)), with the wedge friction law.

Coordinates theta1 (worm), theta2 (wheel) about their own axes (meshgen.assembly: positive worm rotation drives
the wheel positive for a right-hand worm, theta2 = hand theta1 z1 / z2 for the rigid conjugate pair).

Mesh deflection. The wheel lag angle (transmission error with the opposite sign of contact3d's)

    e = hand (z1 / z2) theta1 - theta2,    e' = hand (z1 / z2) omega1 - omega2

measures how far the worm leads the wheel. Conjugate flanks with circumferential backlash j (taken from the
wheel tooth, j / 2 per side, meshgen.wheel) leave an angular gap g = j / (2 r2) each side, so the flank the
worm pushes in forward drive (side +1) touches for e > g and the opposite flank (side -1) for e < -g;
in between, no force. (With assembly errors, `errors:`, the gaps are the kinematic TCA's g_side(theta1) and the
elastic torque is the loaded TCA's table of the displaced flanks, wormsim.torsional.loaded_tca; docs/errors.md 5a.)
The penetration along the line of action is delta = arm0 (|e| - g), arm0 = r2 cos(alpha_n)
cos(gamma) (wormsim.tooth.stiffness.mesh_stiffness_table: k(theta1) from the generated flanks, once; with the teeth's
compliance, the stiffness's default, the loaded tooth contact analysis's).

Mesh torque on the wheel (ADAMS IMPACT form with e = 1, damping blended in over the penetration depth d_max
like IMPACT's STEP, never pulling):

    T2m = side max(0, K_theta,side(theta1) (|e| - g) + C_theta(theta1) STEP(delta, 0, 0, d_max, 1) side e')

C_theta = c arm0^2 K_theta / K_theta,mean: the line-of-action damping c (contact.damping_n_s_per_m, capped at
wormsim.contact3d.law.MAX_DAMPING_RATIO (0.1) of the critical damping of the mesh mode, default DEFAULT_DAMPING_RATIO
(0.1) of it: the constants contact3d uses) scaled with the number of pairs engaged. Seed 001's C = 5e4 N s/m is
capped to 78 N s/m this way.

Friction: the wedge law (seed 000, DIN 3975 / Niemann-Winter worm gear forces) with the virtual friction angle
rho' = atan(mu / cos alpha_n), mu = mu(Vs) of wormsim.contact3d.law (constant, static/dynamic STEP blend over the
transition velocity v_t, or seed 000's rho(Vs) groups), Vs = omega1 r1 / cos(gamma) (signed). The torque the
mesh takes from the worm is

    T1m = hand (T2m / r2) r1 tan(gamma + s rho'),   s = sign(T2m) hand tanh(Vs / v_s),   v_s = v_t / 10

s = +1 is tractive (the worm drives: T2m omega2 > 0, eta = tan g / tan(g + rho')), s = -1 back-driving
(tan(g - rho') / tan g), and tanh the smooth transition through Vs = 0 (v_t = contact.transition_velocity_m_s).
Without friction T1m omega1 = T2m omega2 (power balance, p = r1 tan g = r2 z1 / z2). Self-locking comes out:
for rho' > gamma a wheel torque makes tan(gamma - s rho') = 0 at Vs = v_s atanh(gamma / rho'), a creep of the
order of v_s. v_s is a tenth of v_t (SIGN_VELOCITY_FRACTION) so that this creep stays below the static -> dynamic
transition and a pair whose STATIC rho' exceeds gamma holds from rest even where its dynamic rho' is below gamma
(with v_s = v_t the creep, 1.75 v_t at rho' = gamma + 0.3 deg, reached mu_dynamic and the worm ran back:
tests/contact3d/test_backlash.py, docs/stability_backlash_locking.md).

Equations of motion:

    I1 omega1' = T_drive,1 + T_load,1 - T1m,     I2 omega2' = T2m + T_drive,2 + T_load,2

Drive: speed-controlled -> a stiff servo on speed T = kv (omega_cmd(t) - omega), kv for a 0.1 % droop at the
expected torque (as contact3d's MuJoCo velocity actuator, wormsim.contact3d.mjcf); torque -> T(t). Both follow ADAMS
STEP over drive.ramp_s; the load resists the expected motion, STEP from load.start_s over load.ramp_s
(as wormsim.contact3d.runner.commands).

Inertias: analytic solid cylinders (not the meshes): worm radius r1 over the threaded length b1, wheel radius
r2 over the face width b2, from the materials' densities: I = m r^2 / 2, m = density pi r^2 L.

Forces reported on the wheel (DIN 3975 / DIN 3996 force components, Niemann-Winter Maschinenelemente III):
with the normal force F_n and friction mu F_n, F_t2 = F_n (cos a_n cos g - mu sin g), F_r = F_n sin a_n,
F_a2 = F_t1 = F_n (cos a_n sin g + mu cos g); with mu = tan(rho') cos(a_n) this is

    F_t2 = T2m / r2,   F_a2 = F_t2 tan(g + s rho'),   F_r = |F_t2| tan(a_n) cos(rho') / cos(g + s rho').

Integration: fixed-step backward Euler with Newton iterations (integrate_backward_euler): the mesh mode, the
servo and the friction regularisation are many decades faster than the motion (stiff); the implicit step
follows the motion and the quasi-static mesh force at steps of one k(theta) sample's worth of worm rotation
(default_timestep) and damps the kHz modes. scipy solve_ivp (LSODA, BDF, Radau; `simulate(..., method=)`)
resolves them and serves as the accuracy reference; it is 20-500x slower (docs/torsional.md).
Summary keys and their computation: those of contact3d (wormsim.results.metrics: steady window, FFT peak), except
that mesh_frequency_hz is the meshing line of the transmission error, not of the tangential force (see
torsional_summary; the force's peak is reported as force_peak_full_band_hz).
"""

from __future__ import annotations

import math
import time

import numpy as np
from scipy.integrate import solve_ivp

from meshgen.geometry import GearGeometry
from wormsim.exceptions import DivergedError, LockedError, PenetrationError, SimulationError
from wormsim.physics import gear_theory as gt
from wormsim.physics.friction import friction_coefficient_scalar
from wormsim.physics.locking import Held, held_keys, run_keys
from wormsim.physics.plan import GearPlan, gear_plan
from wormsim.physics.units import rad_s_to_rpm, step
from wormsim.results.metrics import dominant_frequency, drive_summary, mean_speeds_rpm, mesh_line_keys, window_of
from wormsim.results.result import Result
from wormsim.results.summary_keys import level_summary
from wormsim.scenario import Contact, Load, Materials, Scenario
from wormsim.tooth.mesh_stiffness import MeshStiffness
from wormsim.tooth.stiffness import mesh_stiffness_table, stiffness_outputs

CHORD_ITER = 4  # backward Euler: Newton iterations that reuse the first Jacobian of a step
LINE_SEARCH_HALVINGS = 30  # backward Euler's globalised Newton: the most halvings of a step's update
MAX_SAMPLES = 20000
SAMPLES_PER_MESH_PERIOD = 64
RTOL, ATOL_ANGLE = 1e-7, 1e-10
SIGN_VELOCITY_FRACTION = 0.1  # v_s / v_t: friction-direction regularisation (module docstring)


def inertias(materials: Materials, load: Load, g: GearGeometry) -> tuple[float, float]:
    """(I1, I2) in kg m^2: solid cylinders (module docstring), plus the driven-machine inertia
    load.inertia_kg_m2 on the loaded shaft (rigid on it, as contact3d's joint armature)."""
    return gt.shaft_inertias_kg_m2(materials, load, g.r1, g.worm_length, g.r2, g.face_width)


class _TorqueTable:
    """T_side(theta1, x) of a loaded TCA (wormsim.torsional.loaded_tca): bilinear, periodic in theta1, uniform in x;
    0 below the grid, extended beyond its end with the last interval's slope. at() returns (T, dT/dx)."""

    def __init__(self, ltca):
        self.N, self.P = len(ltca.theta1_rad), ltca.period_rad
        self.x0 = float(ltca.x_rad[0])
        self.dx = float(ltca.x_rad[1] - ltca.x_rad[0])
        self.M = len(ltca.x_rad)
        self.T = {1: ltca.torque_fwd_nm.tolist(), -1: ltca.torque_rev_nm.tolist()}

    def at(self, th1: float, x: float, side: int) -> tuple[float, float]:
        u = (x - self.x0) / self.dx
        if u <= 0.0:
            return 0.0, 0.0
        j = min(int(u), self.M - 2)
        f = u - j
        y = (th1 % self.P) / self.P * self.N
        i = int(y)
        a = y - i
        tab = self.T[side]
        r0, r1 = tab[i % self.N], tab[(i + 1) % self.N]
        t0 = r0[j] * (1.0 - a) + r1[j] * a
        t1 = r0[j + 1] * (1.0 - a) + r1[j + 1] * a
        return t0 + (t1 - t0) * f, (t1 - t0) / self.dx


class _Mesh:
    """The force element (module docstring); scalar call for the ODE, array call for the outputs."""

    def __init__(self, c: Contact, g: GearGeometry, ms: MeshStiffness, I1: float, I2: float, kin=None, ltca=None):
        self.g, self.ms = g, ms
        self.hz = g.hand * g.z1 / g.z2
        self.gap = g.backlash / (2 * g.r2)
        # assembly errors: the gaps of the displaced flanks from the kinematic TCA, per side, as tables
        # over its period of worm angle (meshgen.kinematic_tca); None: the perfect pair's constant gap
        self.kin = kin
        if kin is not None:
            self.kP, self.kN = kin.period_rad, len(kin.theta1_rad)
            self.gf, self.gr = kin.gap_fwd_rad.tolist(), kin.gap_rev_rad.tolist()
        # ... and the mesh torque of the displaced flanks from the loaded TCA (wormsim.torsional.loaded_tca)
        self.ltca = ltca
        if ltca is not None:
            self.table = _TorqueTable(ltca)
        self.arm0 = ms.arm0_m
        self.N = ms.samples
        self.period = ms.period_rad
        self.kf = ms.k_theta_fwd_nm_per_rad.tolist()
        self.kr = ms.k_theta_rev_nm_per_rad.tolist()
        self.k_mean = float(np.mean(ms.k_theta_fwd_nm_per_rad))
        # damping along the line of action: requested, capped at MAX_DAMPING_RATIO of critical of the mesh mode
        k_lin = self.k_mean / self.arm0**2
        m_eff = 1.0 / (self.arm0**2 / I2 + (self.hz * self.arm0) ** 2 / I1)  # mesh mode mass on the line of action
        self.c_crit = 2.0 * math.sqrt(k_lin * m_eff)
        c_req = c.damping_n_s_per_m if c.damping_n_s_per_m is not None else gt.DEFAULT_DAMPING_RATIO * self.c_crit
        self.c_req = c_req
        self.c_lin = min(c_req, gt.MAX_DAMPING_RATIO * self.c_crit)
        self.c_theta_per_k = self.c_lin * self.arm0**2 / self.k_mean
        self.d_max = c.penetration_depth_m
        self.vt = c.transition_velocity_m_s
        self.v_sign = SIGN_VELOCITY_FRACTION * self.vt
        self.mu = friction_coefficient_scalar(c)
        self.omega_mesh = math.sqrt(self.k_mean * (1.0 / I2 + self.hz**2 / I1))

    def k_at(self, th1: float, table: list) -> float:
        x = (th1 % self.period) / self.period * self.N
        i = int(x)
        f = x - i
        return table[i % self.N] * (1.0 - f) + table[(i + 1) % self.N] * f

    def gap_at(self, th1: float, table: list) -> tuple[float, float]:
        """(gap, d gap / d theta1) of a displaced-flank table (periodic, linear between samples)."""
        x = (th1 % self.kP) / self.kP * self.kN
        i = int(x)
        f = x - i
        a, b = table[i % self.kN], table[(i + 1) % self.kN]
        return a * (1.0 - f) + b * f, (b - a) * self.kN / self.kP

    def torques(self, th1: float, w1: float, th2: float, w2: float) -> tuple[float, float]:
        """(T2m on the wheel, T1m taken from the worm), N m."""
        e = self.hz * th1 - th2
        de = self.hz * w1 - w2
        if self.kin is not None:
            return self._torques_displaced(th1, w1, e, de)
        if e > self.gap:
            side, dlt, ddlt, K = 1.0, e - self.gap, de, self.k_at(th1, self.kf)
        elif e < -self.gap:
            side, dlt, ddlt, K = -1.0, -e - self.gap, -de, self.k_at(th1, self.kr)
        else:
            return 0.0, 0.0
        return self._torque(th1, w1, side, dlt, ddlt, K)

    def _torques_displaced(self, th1: float, w1: float, e: float, de: float) -> tuple[float, float]:
        """torques() with the displaced flanks' gaps g_side(theta1): side +1 touches for e > g_+1, side -1 for
        e < -g_-1; the penetration rate includes the gap's change with the worm angle."""
        gf, dgf = self.gap_at(th1, self.gf)
        gr, dgr = self.gap_at(th1, self.gr)
        if self.ltca is not None:
            return self._torque_table(th1, w1, e, de, gf, dgf, gr, dgr)
        if e > gf:
            return self._torque(th1, w1, 1.0, e - gf, de - dgf * w1, self.k_at(th1, self.kf))
        if e < -gr:
            return self._torque(th1, w1, -1.0, -e - gr, -de - dgr * w1, self.k_at(th1, self.kr))
        return 0.0, 0.0

    def _torque_table(self, th1, w1, e, de, gf, dgf, gr, dgr) -> tuple[float, float]:
        """The loaded TCA's elastic torque T_side(theta1, x), x = side e - g_side (the lag past the first touch),
        plus the damping of _torque with the table's tangent stiffness dT/dx in place of K_theta."""
        if e >= 0.0:
            side, x, dx, g = 1.0, e - gf, de - dgf * w1, 1
        else:
            side, x, dx, g = -1.0, -e - gr, -de - dgr * w1, -1
        Tel, K = self.table.at(th1, x, g)
        if Tel <= 0.0:
            return 0.0, 0.0
        blend = step(self.arm0 * x, 0.0, 0.0, self.d_max, 1.0)
        T = Tel + self.c_theta_per_k * K * blend * dx
        if T <= 0.0:
            return 0.0, 0.0
        return self._with_friction(side * T, w1)

    def _torque(self, th1, w1, side, dlt, ddlt, K) -> tuple[float, float]:
        blend = step(self.arm0 * dlt, 0.0, 0.0, self.d_max, 1.0)  # IMPACT's damping ramp over d_max
        T = K * dlt + self.c_theta_per_k * K * blend * ddlt
        if T <= 0.0:
            return 0.0, 0.0
        return self._with_friction(side * T, w1)

    def _with_friction(self, T2m: float, w1: float) -> tuple[float, float]:
        """(T2m, T1m): the worm's torque through the wedge law (module docstring)."""
        side = 1.0 if T2m > 0.0 else -1.0
        g = self.g
        vs = w1 * g.r_m1 / math.cos(g.gamma_m)  # at the worm's operating radius (r1 unshifted)
        rho = gt.virtual_friction_angle_rad(self.mu(vs), g.alpha_n)
        s = side * g.hand * math.tanh(vs / self.v_sign)
        return T2m, gt.worm_torque_nm(T2m, g.hand, g.r_m1, g.r2, g.gamma_m, s * rho)

    def outputs(self, th1, w1, th2, w2) -> dict:
        """Vectorised over samples: forces on the wheel and the mesh state."""
        g = self.g
        n = len(th1)
        T2m, T1m = np.zeros(n), np.zeros(n)
        for i in range(n):
            T2m[i], T1m[i] = self.torques(th1[i], w1[i], th2[i], w2[i])
        e = self.hz * th1 - th2
        vs = w1 * g.r_m1 / math.cos(g.gamma_m)
        mu = np.array([self.mu(float(v)) for v in vs])
        rho = gt.virtual_friction_angle_rad(mu, g.alpha_n)
        s = np.sign(T2m) * g.hand * np.tanh(vs / self.v_sign)
        ft = gt.tangential_force_n(T2m, g.r2)
        phase = np.mod(th1, self.period) / self.period * self.N
        kf = np.interp(phase, np.arange(self.N + 1), self.kf + self.kf[:1])
        kr = np.interp(phase, np.arange(self.N + 1), self.kr + self.kr[:1])
        k = np.where(e >= 0, kf, kr) / self.arm0**2
        if self.ltca is not None:  # the loaded TCA's tangent stiffness at the run's lag past the first touch
            x = np.mod(th1, self.kP) / self.kP * self.kN
            gf = np.interp(x, np.arange(self.kN + 1), self.gf + self.gf[:1])
            gr = np.interp(x, np.arange(self.kN + 1), self.gr + self.gr[:1])
            lag = np.where(e >= 0, e - gf, -e - gr)
            k = np.array([self.table.at(a, b, 1 if c >= 0 else -1)[1] for a, b, c in zip(th1, lag, e)]) / self.arm0**2
        if self.kin is None:
            deflection = self.arm0 * np.maximum(np.abs(e) - self.gap, 0.0)
        else:
            x = np.mod(th1, self.kP) / self.kP * self.kN
            gf = np.interp(x, np.arange(self.kN + 1), self.gf + self.gf[:1])
            gr = np.interp(x, np.arange(self.kN + 1), self.gr + self.gr[:1])
            deflection = self.arm0 * np.maximum(np.maximum(e - gf, -e - gr), 0.0)
        return {
            "tangential_force_n": ft,
            "axial_force_n": gt.axial_force_n(ft, g.gamma_m, s * rho),
            "radial_force_n": gt.radial_force_n(np.abs(ft), g.alpha_n, g.gamma_m, s * rho),
            "mesh_torque_worm_nm": T1m,
            "friction_coefficient": mu,
            "transmission_error_rad": -e,
            "mesh_deflection_m": deflection,
            "mesh_stiffness_n_per_m": k,
        }


def default_timestep(g: GearGeometry, ms: MeshStiffness, w1_full_rad_s: float, duration_s: float) -> float:
    """One k(theta) sample's worth of worm rotation at full speed, period / (N omega1), rounded down to 1-2-5,
    and at least duration / MAX_SAMPLES."""
    h = ms.period_rad / ms.samples / max(w1_full_rad_s, 1e-9)
    return max(gt.round_down_125(min(h, duration_s / 50)), duration_s / MAX_SAMPLES)


FD_TH, FD_W = 1e-10, 1e-7  # integrate_backward_euler's forward-difference steps (angle, speed)
TOL_TH, TOL_W = 1e-13, 1e-10  # and its absolute update tolerances (angle, speed)


def _converged(x, dx) -> bool:
    """Every Newton update below TOL + 1e-10 |x + dx| (integrate_backward_euler)."""
    x1, u1, x2, u2 = x
    dp1, dw1, dp2, dw2 = dx
    return (
        abs(dp1) <= TOL_TH + 1e-10 * abs(x1 + dp1)
        and abs(dp2) <= TOL_TH + 1e-10 * abs(x2 + dp2)
        and abs(dw1) <= TOL_W + 1e-10 * abs(u1 + dw1)
        and abs(dw2) <= TOL_W + 1e-10 * abs(u2 + dw2)
    )


def _jacobian(acc, t1, x1, u1, x2, u2, a1, a2):
    """Forward differences of (a1, a2) in (theta1, omega1, theta2, omega2) (integrate_backward_euler; 4 evaluations
    of acc)."""
    d = FD_TH + 1e-9 * abs(x1)
    b1, b2 = acc(t1, x1 + d, u1, x2, u2)
    j10, j30 = (b1 - a1) / d, (b2 - a2) / d
    d = FD_W + 1e-9 * abs(u1)
    b1, b2 = acc(t1, x1, u1 + d, x2, u2)
    j11, j31 = (b1 - a1) / d, (b2 - a2) / d
    d = FD_TH + 1e-9 * abs(x2)
    b1, b2 = acc(t1, x1, u1, x2 + d, u2)
    j12, j32 = (b1 - a1) / d, (b2 - a2) / d
    d = FD_W + 1e-9 * abs(u2)
    b1, b2 = acc(t1, x1, u1, x2, u2 + d)
    j13, j33 = (b1 - a1) / d, (b2 - a2) / d
    return j10, j11, j12, j13, j30, j31, j32, j33


def _backtrack(acc, y0, t1, hh, x, dx, r_now):
    """integrate_backward_euler's line search (Armijo): the update dx from x halved until the step's residual in
    speed units, |(r_theta1 / h, r_omega1, r_theta2 / h, r_omega2)|, falls below (1 - 1e-4 lam) r_now, at most
    LINE_SEARCH_HALVINGS times; returns (lam, the accelerations at x + lam dx, the evaluations of acc)."""
    p1, v1, p2, v2 = y0
    lam = 1.0
    for k in range(LINE_SEARCH_HALVINGS + 1):
        x1, u1, x2, u2 = (xi + lam * di for xi, di in zip(x, dx))
        a1, a2 = acc(t1, x1, u1, x2, u2)
        r_new = math.hypot((p1 - x1) / hh + u1, v1 + hh * a1 - u1, (p2 - x2) / hh + u2, v2 + hh * a2 - u2)
        if r_new <= (1.0 - 1e-4 * lam) * r_now or k == LINE_SEARCH_HALVINGS:
            break
        lam *= 0.5
    return lam, a1, a2, k + 1


def integrate_backward_euler(acc, duration: float, h: float, max_iter: int = 30, limit=None):
    """Fixed-step backward (implicit) Euler, L-stable (Hairer & Wanner, Solving ODEs II, IV.3), for
    theta_i' = omega_i, omega_i' = a_i(t, theta1, omega1, theta2, omega2):

        y_{n+1} = y_n + h f(t_{n+1}, y_{n+1}),

    solved by Newton's method from the predictor 2 y_n - y_{n-1}, with a forward-difference Jacobian of (a1, a2)
    taken at the predictor and reused for CHORD_ITER iterations (chord method), then recomputed each iteration
    (the mesh force is piecewise smooth: backlash, contact onset); the 4x4 Newton
    system is reduced to 2x2 in the speed updates (d theta_i = r_theta_i + h d omega_i) and solved by Cramer's
    rule, all in floats. Converged when every update is below TOL + 1e-10 |y|. A step whose iteration does not
    converge is split in two (recursively, down to h / 1024). Where that fails too, the step is solved again with
    the globalised Newton method (Nocedal & Wright, Numerical Optimization, ch. 11): the Jacobian each
    iteration and a backtracking line search on the residual (Armijo, halving the update up to
    LINE_SEARCH_HALVINGS times, _backtrack), the same splitting and convergence test: the plain iteration cycles
    across the friction direction's tanh band where the solution lies inside it (a held back-drive; decision
    0055). Every step the plain iteration solves keeps its bits. It steps over the mesh and servo modes (kHz) and
    damps them: it follows the motion and the quasi-static mesh force. limit (the speed servo's peak torque,
    _Setup): each step is solved with the limit as it was in the step before (limit.on) and solved again with it
    switched when the solution says otherwise (limit.binds(t, y)) or the solve fails, so that a run whose servo
    never reaches its knee takes the unlimited law's iterations, bit for bit.
    Returns (t, Y (4, n + 1), evaluations of acc)."""
    n = int(math.floor(duration / h + 1e-9))
    t = np.arange(n + 1) * h
    Y = np.zeros((4, n + 1))
    nfev = 0

    def solve_step(y0, yp, t1, hh, depth, damped=False):
        nonlocal nfev
        p1, v1, p2, v2 = y0
        x1, u1, x2, u2 = yp
        a1 = a2 = None
        for it in range(max_iter * (2 if damped else 1)):
            if a1 is None or not damped:
                a1, a2 = acc(t1, x1, u1, x2, u2)
                nfev += 1
            if damped or it == 0 or it >= CHORD_ITER:  # chord (simplified) Newton first, full Newton if it stalls
                j10, j11, j12, j13, j30, j31, j32, j33 = _jacobian(acc, t1, x1, u1, x2, u2, a1, a2)
                nfev += 4
            r0, r1 = p1 + hh * u1 - x1, v1 + hh * a1 - u1
            r2, r3 = p2 + hh * u2 - x2, v2 + hh * a2 - u2
            # (I - hJ) d = r with d_theta_i = r_theta_i + h d_omega_i  ->  2x2 in (d_omega1, d_omega2)
            m00 = 1.0 - hh * j11 - hh * hh * j10
            m01 = -hh * j13 - hh * hh * j12
            m10 = -hh * j31 - hh * hh * j30
            m11 = 1.0 - hh * j33 - hh * hh * j32
            q0 = r1 + hh * (j10 * r0 + j12 * r2)
            q1 = r3 + hh * (j30 * r0 + j32 * r2)
            det = m00 * m11 - m01 * m10
            dw1 = (q0 * m11 - m01 * q1) / det
            dw2 = (m00 * q1 - m10 * q0) / det
            dp1, dp2 = r0 + hh * dw1, r2 + hh * dw2
            converged = _converged((x1, u1, x2, u2), (dp1, dw1, dp2, dw2))
            if damped and not converged:  # backtracking on the residual (Armijo), the globalised Newton
                r_now = math.hypot(r0 / hh, r1, r2 / hh, r3)
                lam, a1, a2, k = _backtrack(acc, y0, t1, hh, (x1, u1, x2, u2), (dp1, dw1, dp2, dw2), r_now)
                nfev += k
                dp1, dw1, dp2, dw2 = lam * dp1, lam * dw1, lam * dp2, lam * dw2
            x1, u1, x2, u2 = x1 + dp1, u1 + dw1, x2 + dp2, u2 + dw2
            if not math.isfinite(x1 + u1 + x2 + u2):
                break
            if converged:
                return (x1, u1, x2, u2)
        if depth >= 10:
            raise SimulationError(
                f"torsional: implicit step did not converge at t = {t1:.4g} s even at timestep {hh:.3g} s"
            )
        ym = solve_step(y0, y0, t1 - hh / 2, hh / 2, depth + 1, damped)
        return solve_step(ym, ym, t1, hh / 2, depth + 1, damped)

    def limited_step(y0, yp, t1, damped):
        """solve_step with the servo's limit switched where the solution (or a failed solve) asks for it."""
        try:
            y1 = solve_step(y0, yp, t1, h, 0, damped)
            if limit.binds(t1, y1) == limit.on:
                return y1
        except SimulationError:
            pass
        limit.on = not limit.on
        return solve_step(y0, yp, t1, h, 0, damped)

    def step_of(y0, yp, t1, damped):
        return solve_step(y0, yp, t1, h, 0, damped) if limit is None else limited_step(y0, yp, t1, damped)

    y_prev = y = (0.0, 0.0, 0.0, 0.0)
    for i in range(n):
        pred = tuple(2 * a - b for a, b in zip(y, y_prev))
        on = limit.on if limit is not None else None
        try:
            y_new = step_of(y, pred, t[i + 1], False)
        except SimulationError:  # the plain iteration cycles: the globalised one (docstring)
            if limit is not None:
                limit.on = on
            y_new = step_of(y, pred, t[i + 1], True)
        y_prev, y = y, y_new
        Y[:, i + 1] = y
    return t, Y, nfev


def _integrate_scipy(rhs, duration: float, h: float, ms: MeshStiffness, w1_full: float, method: str):
    """scipy solve_ivp LSODA, BDF or Radau (error-controlled, resolves the mesh vibration): the accuracy reference."""
    n = int(math.floor(duration / h + 1e-9))
    t_eval = np.arange(n + 1) * h
    max_step = min(ms.period_rad / ms.samples / max(w1_full, 1e-9), duration / 20)
    atol = np.array([ATOL_ANGLE, ATOL_ANGLE * 1e3, ATOL_ANGLE, ATOL_ANGLE * 1e3])
    sol = solve_ivp(
        rhs,
        (0.0, duration),
        [0.0, 0.0, 0.0, 0.0],
        method=method,
        t_eval=t_eval,
        rtol=RTOL,
        atol=atol,
        max_step=max_step,
    )
    if sol.status != 0:
        raise DivergedError(f"torsional integration ({method}) failed at t = {sol.t[-1]:.4g} s: {sol.message}")
    return sol.t, sol.y, sol.nfev


SCIPY_METHODS = {"lsoda": "LSODA", "bdf": "BDF", "radau": "Radau"}


def simulate(scenario: Scenario, progress=None, method: str = "implicit") -> Result:
    """method: "implicit" (default, fixed-step backward Euler) or one of scipy's error-controlled solvers
    "LSODA", "BDF", "Radau" (any case)."""
    scipy_method = SCIPY_METHODS.get(method.lower())
    if scipy_method is None and method != "implicit":
        raise ValueError(f"torsional method {method!r}: allowed implicit, {', '.join(SCIPY_METHODS.values())}")
    return run_plan(gear_plan(scenario), progress, scipy_method)


class _Setup:
    """What the run integrates, from its plan: mesh stiffness, inertias, the displaced pair's TCAs, the force
    element, the commands and the servo."""

    def __init__(self, plan: GearPlan):
        g = self.g = plan.geometry
        t_ms = time.perf_counter()
        ms = self.ms = mesh_stiffness_table(plan.contact, g, plan.materials, plan.simulation.mesh_stiffness_samples)
        kp = ms.stiffness_per_length_n_per_m2
        self.t_ms = time.perf_counter() - t_ms
        self.I1, self.I2 = inertias(plan.materials, plan.duty.load, g)
        pair = self.pair = plan.displaced
        self.kin = pair[1] if pair is not None else None
        self.ltca, self.t_lt = None, 0.0
        if pair is not None:
            from wormsim.torsional.loaded_tca import loaded_tca  # only with errors

            t_lt = time.perf_counter()
            t2w = plan.working_wheel_torque_nm
            self.ltca = loaded_tca(
                g, pair[0], self.kin, kp * g.face_width, t2w, float(np.mean(ms.k_theta_fwd_nm_per_rad))
            )
            self.t_lt = time.perf_counter() - t_lt
        self.mesh = _Mesh(plan.contact, g, ms, self.I1, self.I2, self.kin, self.ltca)
        drv = plan.duty.drive
        cmds = plan.duty.commands
        self.speed_driven = drv.speed_rpm is not None
        self.kv = plan.servo_gain_nm_s if self.speed_driven else 0.0
        self.worm_drive = drv.on == "worm"
        self.drive_f, self.load_f = cmds.drive, cmds.load
        # a stalling speed drive's peak torque (gear_theory.servo_peak_applies), None elsewhere or for a step command
        j_drive = gt.drive_inertia_kg_m2(drv.on, g.ratio, self.I1, self.I2)
        self.peak = (
            gt.servo_peak_torque_nm(plan.drive_torque_nm, j_drive, cmds.drive_target, drv.ramp_s)
            if gt.servo_peak_applies(self.speed_driven, plan.backdrive_self_locks)
            else None
        )
        self.on = False  # the limit applied (integrate_backward_euler's limit; the series: always, binds)
        w_full = abs(cmds.drive_target) if self.speed_driven else 2 * math.pi
        self.w1_full = w_full * (g.ratio if (self.speed_driven and not self.worm_drive) else 1.0)

    def binds(self, t: float, y) -> bool:
        """The servo's unlimited law beyond the knee of its peak (gear_theory.servo_limited_torque_nm) at state y."""
        w = y[1] if self.worm_drive else y[3]
        return abs(self.kv * (self.drive_f(t) - w)) > gt.SERVO_KNEE * self.peak

    def shaft_torques(self, t, w1, w2):
        cmd = self.drive_f(t)
        td = self.kv * (cmd - (w1 if self.worm_drive else w2)) if self.speed_driven else cmd
        if self.on:  # the servo under its peak torque
            td = gt.servo_limited_torque_nm(td, self.peak)
        tl = self.load_f(t)
        return (td, tl) if self.worm_drive else (tl, td)


def run_plan(plan: GearPlan, progress=None, scipy_method: str | None = None) -> Result:
    """The torsional run of a plan (wormsim.physics.plan.gear_plan): integrate, guard, summarise."""
    su = _Setup(plan)
    g, ms, mesh = su.g, su.ms, su.mesh
    I1, I2, shaft_torques = su.I1, su.I2, su.shaft_torques

    def acc(t, th1, w1, th2, w2):
        T2m, T1m = mesh.torques(th1, w1, th2, w2)
        t1, t2 = shaft_torques(t, w1, w2)
        return (t1 - T1m) / I1, (T2m + t2) / I2

    def rhs(t, y):
        a1, a2 = acc(t, *y)
        return (y[1], a1, y[3], a2)

    duration = plan.simulation.duration_s
    h = plan.simulation.timestep_s or default_timestep(g, ms, su.w1_full, duration)
    t_wall = time.perf_counter()
    if scipy_method is not None:
        su.on = su.peak is not None  # scipy's solvers: the limited law throughout
        t, Y, nfev = _integrate_scipy(rhs, duration, h, ms, su.w1_full, scipy_method)
        solver = f"scipy {scipy_method} rtol {RTOL}"
    else:
        limit = su if su.peak is not None else None
        t, Y, nfev = integrate_backward_euler(acc, duration, h, limit=limit)
        solver = "backward Euler (fixed step, Newton)"
    wall = time.perf_counter() - t_wall
    if progress is not None:
        progress.update(duration)
    if not np.all(np.isfinite(Y)):
        raise DivergedError(f"torsional integration diverged (timestep {h:.3g} s); lower simulation.timestep_s")
    S, held = _series(plan, su, t, Y)
    solver_keys = {"timestep_s": h, "solver": solver, "solver_rhs_evaluations": int(nfev), "solve_wall_s": wall}
    summary, lt_teeth = _summary(plan, su, S, held, solver_keys)
    return Result(
        model="torsional",
        summary=summary,
        series=S,
        steps=len(S["t_s"]) - 1,
        sim_time_s=float(S["t_s"][-1]),
        extra={"mesh_stiffness": ms, "geometry": g, "ltca": lt_teeth},
    )


def _series(plan: GearPlan, su: _Setup, t: np.ndarray, Y: np.ndarray) -> tuple[dict, Held | None]:
    """The run's series from the integrated states (up to the hold when a self-locking pair held) and the hold."""
    th1, w1, th2, w2 = Y
    ms = su.ms
    out = su.mesh.outputs(th1, w1, th2, w2)
    cmd = np.array([su.drive_f(x) for x in t])
    held = _guards(plan, t, w1, w2, out, cmd)
    if (
        held is not None
    ):  # a self-locking pair held the back-driving wheel: the run ends there (wormsim.physics.locking)
        n = int(np.searchsorted(t, held.t_s, side="right"))
        t, th1, w1, th2, w2, cmd = t[:n], th1[:n], w1[:n], th2[:n], w2[:n], cmd[:n]
        out = {k: v[:n] for k, v in out.items()}
    su.on = su.peak is not None  # the limited law is the unlimited one below its knee (servo_limited_torque_nm)
    tq = np.array([su.shaft_torques(ti, a, b) for ti, a, b in zip(t, w1, w2)])
    S = {
        "t_s": t,
        "worm_angle_rad": th1,
        "wheel_angle_rad": th2,
        "worm_speed_rpm": rad_s_to_rpm(w1),
        "wheel_speed_rpm": rad_s_to_rpm(w2),
        "worm_torque_nm": tq[:, 0],
        "wheel_torque_nm": tq[:, 1],
        "drive_command": cmd,
        "teeth_in_contact": np.where(
            out["mesh_deflection_m"] > 0,
            np.interp(
                np.mod(th1, ms.period_rad) / ms.period_rad * ms.samples,
                np.arange(ms.samples + 1),
                np.append(ms.teeth_fwd, ms.teeth_fwd[0]),
            ),
            0.0,
        ),
        **out,
    }
    return S, held


def _summary(plan: GearPlan, su: _Setup, S: dict, held: Held | None, solver_keys: dict) -> tuple[dict, object]:
    """The torsional keys of the run (solver_keys: the integration's) and the teeth's LTCA for the report."""
    g, ms, mesh, kin = su.g, su.ms, su.mesh, su.kin
    t = S["t_s"]
    drive = torsional_summary(S, plan, ms)
    t2_work = plan.working_wheel_torque_nm
    st_keys, lt_teeth = stiffness_outputs(
        ms, g, plan.materials, t2_work, plan.duty.working_flank, errors=su.pair is not None
    )
    lock = (
        run_keys(plan.duty.drive, plan.rho_static_rad, plan.transition_velocity_m_s, g, t, S["worm_speed_rpm"])
        if held is None
        else held_keys(t, S["worm_speed_rpm"], S["wheel_torque_nm"], held.stuck_since_s or held.t_s)
    )
    used = {
        "scenario": plan.name,
        **solver_keys,
        "mesh_stiffness_wall_s": su.t_ms,
        "worm_inertia_kg_m2": su.I1,
        "wheel_inertia_kg_m2": su.I2,
        "inertia_source": "solid cylinders r1 x b1, r2 x b2 (+ load.inertia_kg_m2 on the loaded shaft)",
        "mesh_natural_frequency_hz": mesh.omega_mesh / (2 * math.pi),
        "contact_damping_requested_n_s_per_m": mesh.c_req,
        "contact_damping_used_n_s_per_m": mesh.c_lin,
        "contact_damping_ratio": mesh.c_lin / mesh.c_crit,
        "drive_kv_nm_s": su.kv if su.speed_driven else None,
        "drive_peak_torque_nm": su.peak,
        "backlash_angle_rad": 2 * mesh.gap,
        "friction": plan.friction_mode,
        **ms.summary(),
        **st_keys,
    }
    errors: dict = {}
    if kin is not None:
        side = plan.duty.working_flank
        errors.update(kin.summary(g, side))
        k_lt = su.ltca.secant_stiffness_nm_per_rad(side, t2_work) / ms.arm0_m**2
        errors["mesh_stiffness_loaded_tca_mean_n_per_m"] = float(np.nanmean(k_lt)) if np.isfinite(k_lt).any() else None
        errors["loaded_tca_wall_s"] = su.t_lt
        te = kin.te_rad(side)
        S["transmission_error_kinematic_rad"] = np.interp(
            np.mod(S["worm_angle_rad"], kin.period_rad), np.append(kin.theta1_rad, kin.period_rad), np.append(te, te[0])
        )
    return level_summary("torsional", drive, lock, used, errors), lt_teeth


def _guards(plan: GearPlan, t, w1, w2, out, cmd) -> Held | None:
    """Teeth would skip (deflection past 0.4 m_x, gear_theory.penetration_limit_m, contact3d's penetration limit);
    a speed-driven drive stuck below half its command for 0.05 s after the ramps (locked: a jam, LockedError; or a
    wheel back-driving a self-locking pair: returned as Held, the run's result, wormsim.physics.locking). The
    deflection is
    checked up to the end of the run (the hold when held)."""
    g, drv = plan.geometry, plan.duty.drive
    held = None
    if drv.speed_rpm is not None:
        held = _locked_guard(plan, t, w1, w2, cmd)
    n = len(t) if held is None else int(np.searchsorted(t, held.t_s, side="right"))
    dmax = float(np.max(out["mesh_deflection_m"][:n]))
    lim = gt.penetration_limit_m(g.m_x)
    if dmax > lim:
        i = int(np.argmax(out["mesh_deflection_m"] > lim))
        why = "raise contact.stiffness_n_per_m or lower load.torque_nm"
        vs = abs(float(w1[i])) * g.r_m1 / math.cos(g.gamma_m)
        creeping = drv.on == "wheel" and vs < 10 * plan.transition_velocity_m_s
        if creeping and i > 0 and plan.backdrive_self_locks:
            return Held(float(t[i - 1]), _stuck_since(plan, t, w2, cmd))  # the stalled wheel's servo pushed on
        if creeping:
            rho = gt.virtual_friction_angle_rad(float(out["friction_coefficient"][i]), g.alpha_n)
            why = (
                f"the pair is self-locking (rho' = {math.degrees(rho):.2f} deg > "
                f"gamma = {math.degrees(g.gamma_m):.2f} "
                f"deg): the wheel cannot drive the worm, which creeps at Vs = {vs * 1e3:.2g} mm/s"
            )
        raise PenetrationError(
            f"mesh deflection {dmax * 1e6:.1f} um at t = {t[i]:.4g} s exceeds 0.4 m_x = {lim * 1e6:.1f} um: "
            f"the teeth would skip; {why}"
        )
    return held


def _stuck_since(plan: GearPlan, t, w_drive, cmd) -> float | None:
    """The first time after the lock check's start at which the speed-driven drive is stuck (None: never)."""
    bad = (t > plan.duty.lock_check_start_s) & gt.drive_stuck(w_drive, cmd)
    return float(t[int(np.argmax(bad))]) if bad.any() else None


def _locked_guard(plan: GearPlan, t, w1, w2, cmd) -> Held | None:
    w_drive = w1 if plan.duty.drive.on == "worm" else w2
    bad = (t > plan.duty.lock_check_start_s) & gt.drive_stuck(w_drive, cmd)
    if bad.any():
        i0 = int(np.argmax(bad))
        run = np.nonzero(~bad[i0:])[0]
        i1 = i0 + (int(run[0]) if len(run) else len(bad) - i0) - 1
        if t[i1] - t[i0] >= gt.LOCK_HOLD_S or (not len(run) and t[-1] - t[i0] > 0):
            if plan.backdrive_self_locks:  # the answer, not a failure (wormsim.physics.locking)
                i_end = int(np.searchsorted(t, t[i0] + gt.LOCK_HOLD_S))
                return Held(float(t[min(i_end, i1)]), float(t[i0]))
            raise LockedError(
                f"the drive locked at t = {t[i0]:.4g} s: {rad_s_to_rpm(float(w_drive[i0])):.3g} rpm against a "
                f"command of {rad_s_to_rpm(float(cmd[i0])):.3g} rpm (self-locking: the wheel cannot drive the worm "
                f"when rho' > gamma; or the load {plan.duty.load.torque_nm} N m is too high)"
            )
    return None


def torsional_summary(S: dict, plan: GearPlan, ms: MeshStiffness) -> dict:
    """contact3d's summary keys, computed by the same functions (wormsim.results.metrics), with one difference:
    the meshing line is taken from the transmission error (wormsim.results.metrics.mesh_line). The mesh force element's
    tangential force is quasi-static: its fluctuation is the inertial part, the 2nd time derivative of the
    transmission error, which weights the harmonics of k(theta)'s tooth-entry kinks by n^2 and puts the
    force's peak on a harmonic (reported as force_peak_full_band_hz)."""
    g = plan.geometry
    t = S["t_s"]
    i0, i1, _ = window_of(S, plan.duty, g)
    sl = slice(i0, i1)
    n1, n2 = mean_speeds_rpm(S, i0, i1)
    f_force, _, _, _ = dominant_frequency(t[sl], S["tangential_force_n"][sl])
    return {
        **drive_summary(S, plan, i0, i1, n1, n2),
        **mesh_line_keys(t, S, sl, g.z1 * n1 / 60.0, "transmission_error_rad"),
        "mesh_frequency_source": "transmission error",
        "force_peak_full_band_hz": f_force,
        "mesh_deflection_mean_um": float(np.mean(S["mesh_deflection_m"][sl]) * 1e6),
    }
