"""The path contact3d's exact flanks use to reach MuJoCo's solver (wormsim.contact3d.native.split_step): a 1 kg
box on two slide joints (x, z) above a plane, MuJoCo's collision off for both, one contact added by hand each step
between mj_collision and mj_makeConstraint with the contact law's direct solref (wormsim.contact3d.law (1))."""

from __future__ import annotations

import math

import mujoco
import numpy as np
import pytest

from wormsim.contact3d.native import split_step

XML = """<mujoco><option timestep="1e-3" integrator="implicitfast" cone="elliptic" gravity="0 0 -9.81"/>
<worldbody><geom name="floor" type="plane" size="1 1 .1" contype="0" conaffinity="0"/>
<body name="box" pos="0 0 0.1"><joint name="x" type="slide" axis="1 0 0"/><joint name="z" type="slide" axis="0 0 1"/>
<geom name="b" type="box" size=".1 .1 .1" mass="1" contype="0" conaffinity="0"/></body></worldbody></mujoco>"""
K = 1.0e5  # N/m
D = 0.01  # impedance (wormsim.contact3d.law.IMPEDANCE)
MU = 0.3
G = 9.81


def _box(impratio: float = 1.0):
    m = mujoco.MjModel.from_xml_string(XML)
    m.opt.impratio = impratio
    m.body_invweight0[1, 0] = 1.0  # A_hat = 1 / (1 kg), as wormsim.contact3d.mjcf sets it
    d = mujoco.MjData(m)
    c_c = 0.1 * 2 * math.sqrt(K * 1.0)
    t = mujoco.MjContact()
    t.dim = 3
    t.geom = [0, 1]
    t.geom1, t.geom2 = 0, 1
    t.flex = t.elem = t.vert = [-1, -1]
    t.solref = [-K * (1 - D), -c_c * (1 - D)]  # law (1): S = k (1 - d) A_hat, B = c (1 - d) A_hat
    t.solreffriction = [0.0, 0.0]
    t.solimp = [D, D, 0.001, 0.5, 2.0]
    t.friction = [MU, MU, 0, 0, 0]
    t.frame = [0, 0, 1, 1, 0, 0, 0, 1, 0]

    def add(m, d):
        gap = d.xpos[1, 2] - 0.1
        t.dist = gap
        t.pos = [d.xpos[1, 0], 0.0, gap / 2]
        assert mujoco.mj_addContact(m, d, t) == 0

    return m, d, add


def test_static_normal_force_is_the_weight_and_penetration_the_solref_mapping():
    m, d, add = _box()
    for _ in range(3000):
        split_step(m, d, add)
    f = np.zeros(6)
    mujoco.mj_contactForce(m, d, 0, f)
    assert abs(d.qvel).max() < 1e-9
    assert f[0] == pytest.approx(G, rel=1e-4)
    assert -d.contact.dist[0] == pytest.approx(G / K, rel=1e-4)


def test_sliding_deceleration_is_mu_g():
    m, d, add = _box(impratio=100.0)  # friction saturates above v_reg = mu f_n / (impratio c_c) ~ 5e-4 m/s
    for _ in range(2000):
        split_step(m, d, add)
    d.qvel[0] = 1.0
    t, v = [], []
    for _ in range(400):
        split_step(m, d, add)
        t.append(d.time)
        v.append(d.qvel[0])
    t, v = np.array(t), np.array(v)
    sel = (v > 0.2) & (v < 0.9)
    a = -np.polyfit(t[sel], v[sel], 1)[0]
    assert a == pytest.approx(MU * G, rel=2e-3)


def test_split_step_without_contacts_equals_mj_step():
    m, d, _ = _box()
    d2 = mujoco.MjData(m)
    d.qvel[0] = d2.qvel[0] = 0.5
    for _ in range(50):
        split_step(m, d, lambda m, d: None)
        mujoco.mj_step(m, d2)
    assert np.array_equal(d.qpos, d2.qpos) and np.array_equal(d.qvel, d2.qvel)
