"""contact3d/mjcf.py's values of the gear set's meshes cached on disk (_on_gear_set): the same numbers as computed
directly, keyed by what they depend on, and a flank run's model built without importing trimesh."""

from __future__ import annotations

import subprocess
import sys

import numpy as np

from meshgen import wheel
from tests.conftest import ROOT, SCENARIOS
from wormsim.contact3d import mjcf
from wormsim.physics.geometry import gear_set
from wormsim.scenario import load_scenario


def test_cached_inertias_angle_and_normals_equal_the_direct_computation():
    sc = load_scenario(SCENARIOS / "screw_jack.yaml", ["simulation.resolution=coarse"])
    geo, gs = gear_set(sc)
    for _ in range(2):  # the first call may compute and store, the second reads
        ine = mjcf.shaft_inertias(sc, geo, gs)
        assert (ine.worm_mass_kg, ine.worm_inertia_kg_m2) == mjcf._axial_inertia(
            gs.worm_visual, sc.materials.worm.density_kg_m3, 0.0, geo.r1, geo.worm_length
        )
        # tooth 0's pieces sit on the geometry's tooth 0 (meshgen.wheel.tooth_angle), which the run uses
        assert abs(mjcf._pieces_angle(gs.wheel_tooth_pieces) - wheel.tooth_angle(geo, 0)) < 1e-8
        assert np.array_equal(mjcf.visual_vertex_normals(gs, "wheel_visual"), gs.wheel_visual.vertex_normals)
    heavy = load_scenario(
        SCENARIOS / "screw_jack.yaml", ["simulation.resolution=coarse", "materials.wheel.density_kg_m3=9000"]
    )
    assert mjcf.shaft_inertias(heavy, geo, gs).wheel_mass_kg != ine.wheel_mass_kg  # the density is in the key


def test_a_flank_model_is_built_without_trimesh():
    build = (
        "import sys; from wormsim.contact3d.mjcf import build_model; from wormsim.scenario import load_scenario; "
        f"build_model(load_scenario(r'{SCENARIOS / 'screw_jack.yaml'}', ['simulation.resolution=coarse'])); "
        "print('trimesh' in sys.modules)"
    )
    runs = [subprocess.run([sys.executable, "-c", build], cwd=ROOT, capture_output=True, text=True, check=True)]
    runs.append(subprocess.run([sys.executable, "-c", build], cwd=ROOT, capture_output=True, text=True, check=True))
    assert runs[1].stdout.strip().splitlines()[-1] == "False"  # the first run filled the caches (it may need trimesh)
