"""The contact kernel's worm gap for the ZN, ZK and ZC flanks (meshgen.worm_forms' table compiled,
meshgen.worm_forms_jit): the same checks as ZA / ZI (tests/tooth/test_kernel.py), and the compiled table equal to
meshgen's inside and outside its range."""

from __future__ import annotations

import numpy as np
import pytest

from meshgen import worm, worm_forms
from meshgen.geometry import derive
from meshgen.worm_forms_jit import half_thickness
from tests.conftest import SCENARIOS
from tests.tooth.test_kernel import test_kernel_distance_is_meshgen_thread_gap as kernel_distance_check
from wormsim.scenario import load_scenario


@pytest.mark.parametrize(
    "name,profile", [("seat_motor", "ZN"), ("screw_jack", "ZK"), ("screw_jack", "ZC"), ("involute_41", "ZK")]
)
def test_kernel_distance_new_forms(name, profile):
    kernel_distance_check(name, profile)


@pytest.mark.parametrize("profile", ["ZN", "ZK", "ZC"])
def test_compiled_table_is_meshgen(profile):
    g = derive(load_scenario(SCENARIOS / "screw_jack.yaml", [f"gear.profile={profile}"]).gear)
    P = worm.worm_params(g)
    lo, hi = worm_forms.table_range(g)
    r = np.linspace(lo - 0.5 * g.m_x, hi + 0.5 * g.m_x, 301)
    got = np.array([half_thickness(x, P, 13) for x in r])
    np.testing.assert_allclose(got[:, 0], worm.half_thickness(g, r), rtol=0, atol=1e-15)
    np.testing.assert_allclose(got[:, 1], worm.half_thickness_dr(g, r), rtol=0, atol=1e-12)
