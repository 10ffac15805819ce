"""The report panels of the tooth pair's stiffness (wormsim.tooth.stiffness_plot): k(theta1) of both flank sides and
the LTCA's, and the load share per wheel tooth, or the note why there is none."""

from __future__ import annotations

from types import SimpleNamespace

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from wormsim.tooth.stiffness_plot import draw_load_shares, draw_mesh_stiffness  # noqa: E402

TH = np.linspace(0.0, 2 * np.pi / 3, 8, endpoint=False)
MS = SimpleNamespace(
    theta1_rad=TH,
    k_mesh_fwd_n_per_m=2e8 + 1e7 * np.cos(3 * TH),
    k_mesh_rev_n_per_m=1.9e8 + 0 * TH,
    stiffness_source="teeth",
)
SHARE = np.stack([0.6 + 0.1 * np.cos(3 * TH), 0.4 - 0.1 * np.cos(3 * TH), 0 * TH], axis=1)
LT = SimpleNamespace(
    theta1_rad=TH, mesh_stiffness_n_per_m=1.5e8 + 0 * TH, torque_nm=24.0, load_share=SHARE, teeth_in_contact=2 + 0 * TH
)


def test_mesh_stiffness_panel_draws_both_flank_sides_and_the_ltca():
    fig, (a, b) = plt.subplots(1, 2)
    draw_mesh_stiffness(a, MS)
    draw_mesh_stiffness(b, MS, LT)
    assert len(a.lines) == 2 and len(b.lines) == 3
    assert np.allclose(b.lines[2].get_ydata(), LT.mesh_stiffness_n_per_m)
    assert np.allclose(a.lines[0].get_xdata(), np.degrees(TH))
    assert f"{np.mean(MS.k_mesh_fwd_n_per_m):.3g}" in a.get_title()
    plt.close(fig)


def test_load_share_panel_draws_the_loaded_teeth_or_says_why_not():
    fig, (a, b) = plt.subplots(1, 2)
    draw_load_shares(a, LT, "teeth")
    assert len(a.lines) == 2  # the third tooth carries nothing: no line
    assert "max 0.70" in a.get_title() and "teeth in contact 2.00" in a.get_title()
    draw_load_shares(b, None, "scenario")
    assert not b.axison and "scenario" in b.texts[0].get_text()
    plt.close(fig)
