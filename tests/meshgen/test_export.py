"""The geometry files' content (meshgen.export.assembly_data) and the mid-plane section figure (meshgen.section) of a
generated gear set: the frames as assembly.json states them, and a section that cuts both parts."""

from __future__ import annotations

import matplotlib.image as mpimg
import numpy as np
import pytest

from meshgen.export import assembly_data
from meshgen.section import plot_section
from tests.conftest import SCENARIOS
from wormsim.physics.geometry import gear_set
from wormsim.scenario import load_scenario


@pytest.fixture(scope="module")
def screw_jack():
    return gear_set(load_scenario(SCENARIOS / "screw_jack.yaml", ["simulation.resolution=coarse"]))


def test_assembly_data_places_the_worm_axis_at_the_centre_distance(screw_jack):
    g, gs = screw_jack
    d = assembly_data(g, gs)
    assert d["center_distance_m"] == g.a
    tw, tg = np.array(d["worm"]["transform"]), np.array(d["wheel"]["transform"])
    # worm frame: origin on its axis at mid-length -> (0, -a, 0); its axis +z -> assembly -x
    assert np.allclose(tw[:3, 3], [0.0, -g.a, 0.0]) and np.allclose(tw[:3, :3] @ [0, 0, 1], [-1, 0, 0])
    assert np.allclose(tg, np.eye(4))  # the wheel frame is the assembly frame at theta2 = 0
    assert d["worm"]["volume_m3"] == pytest.approx(gs.worm_visual.volume) and d["worm"]["volume_m3"] > 0
    assert d["wheel"]["pieces_per_tooth"] == len(gs.wheel_tooth_pieces) > 0
    assert d["derived"] == g.as_dict_mm_deg()


def test_section_figure_is_drawn(screw_jack, tmp_path):
    g, gs = screw_jack
    out = tmp_path / "section.png"
    plot_section(g, gs, out, "screw_jack")
    img = mpimg.imread(out)
    assert img.shape[0] > 300 and img.shape[1] > 500
    # both parts' section lines are drawn in their colours (wheel #c88a1e, worm #55606e), not only the axes
    rgb = (img[..., :3] * 255).round().astype(int)
    for colour in ((0xC8, 0x8A, 0x1E), (0x55, 0x60, 0x6E)):
        assert np.any(np.all(np.abs(rgb - colour) <= 12, axis=-1)), colour
