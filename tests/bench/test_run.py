"""Benchmark bookkeeping: relative errors, Pareto front, the chart (the speed numbers themselves are
never asserted)."""

import numpy as np

from wormsim.bench.cases import ERROR_KEYS, relative_errors
from wormsim.bench.run import pareto_front, plot_bench


def test_relative_errors_only_where_defined():
    e = relative_errors(
        {"ratio": 53.053, "efficiency": 0.6, "mesh_frequency_hz": None},
        {"ratio": 53.0, "efficiency": 0.0, "mesh_frequency_hz": 0.6},
    )
    # (53.053 - 53.0) / 53.0 = 0.001 (the definition, by hand)
    assert abs(e["ratio"] - 0.001) < 1e-12
    assert e["efficiency"] is None and e["mesh_frequency_hz"] is None
    assert set(e) == set(ERROR_KEYS)


def test_pareto_front_keeps_only_undominated_points():
    cost = np.array([1.0, 2.0, 3.0, 2.5, 0.5])
    err = np.array([0.1, 0.05, 0.01, 0.2, 0.5])
    assert pareto_front(cost, err).tolist() == [True, True, True, False, True]


def test_chart_is_written(tmp_path):
    recs = [
        {
            "scenario": "s",
            "model": m,
            "resolution": res,
            "status": "ok",
            "wall_s_per_sim_s": w,
            "reference": False,
            "finer": False,
            "error": {k: e for k in ERROR_KEYS},
        }
        for m, res, w, e in [
            ("contact3d", {"geometry": "pieces"}, 1.0, 0.01),
            ("contact3d", {"geometry": "flanks"}, 0.3, 0.05),
            ("torsional", {}, 1e-3, 0.02),
        ]
    ]
    plot_bench(recs, tmp_path / "bench.png")
    assert (tmp_path / "bench.png").read_bytes()[:4] == b"\x89PNG"


def test_quick_bench_torsional_level_writes_files_and_records(tmp_path):
    """run_bench(quick=True) restricted to the torsional level (contact3d's quick grid is minutes, not CI-sized):
    the files and each record's keys (speed is measured, never asserted)."""
    import json

    from wormsim.bench.run import run_bench

    recs = run_bench(quick=True, out_dir=tmp_path, models=("torsional",))
    assert recs and all(r["model"] == "torsional" for r in recs)
    on_disk = json.loads((tmp_path / "bench.json").read_text())
    assert len(on_disk) == len(recs)
    for r in on_disk:
        for k in ("scenario", "model", "resolution", "timestep_s", "wall_s", "sim_s", "realtime_factor", "error"):
            assert k in r, k
        assert r["status"] == "ok" and r["sim_s"] > 0 and r["realtime_factor"] > 0 and r["timestep_s"] > 0
        assert r["resolution"]["mesh_stiffness_samples"] in (16, 64)
    assert (tmp_path / "bench.png").read_bytes()[:4] == b"\x89PNG"
    assert "machine" in json.loads((tmp_path / "bench_meta.json").read_text())


def test_bench_cases_restricted_to_named_seeds():
    from wormsim.bench.cases import bench_cases

    cases = bench_cases(quick=False, models=("torsional",), scenarios=("screw_jack",))
    assert cases and {c.scenario for c in cases} == {"screw_jack"}


def test_bench_cli_rejects_unknown_seed_and_bad_repeats(tmp_path, capsys):
    from wormsim.cli import main

    assert main(["bench", "--scenario", "gearbox", "--out", str(tmp_path)]) == 2
    assert "bench --scenario" in capsys.readouterr().err
    assert main(["bench", "--repeats", "0", "--out", str(tmp_path)]) == 2
    assert "allowed: an integer >= 1" in capsys.readouterr().err
    assert not (tmp_path / "bench.json").exists()


def test_full_grid_runs_each_contact3d_case_once_and_marks_the_finer_check():
    from wormsim.bench.cases import bench_cases

    cases = [c for c in bench_cases(quick=False, scenarios=("screw_jack",)) if c.model == "contact3d"]
    keys = [(c.resolution["geometry"], c.resolution["level"], c.timestep_s) for c in cases]
    assert len(keys) == len(set(keys)) == 18
    assert {c.resolution["geometry"] for c in cases} == {"flanks", "pieces"}
    assert sum(c.reference for c in cases) == 1 and sum(c.finer for c in cases) == 1
    ref = next(c for c in cases if c.reference)
    fin = next(c for c in cases if c.finer)
    assert fin.resolution == ref.resolution and abs(fin.timestep_s - ref.timestep_s / 2) < 1e-12
    # the reference is the finest level of the scenario's default contact.geometry
    from wormsim.bench.cases import SCENARIOS
    from wormsim.scenario import load_scenario

    assert ref.resolution == {
        "level": "fine",
        "geometry": load_scenario(SCENARIOS / "screw_jack.yaml").contact.geometry,
    }
    only = bench_cases(quick=True, models=("contact3d",), geometries=("flanks",))
    assert only and {c.resolution["geometry"] for c in only} == {"flanks"} and sum(c.reference for c in only) == 1


def test_speedup_of_flanks_over_pieces_pairs_equal_level_and_step_factor():
    from wormsim.bench.run import speedups

    def rec(geo, lvl, f, w):
        return {
            "scenario": "s",
            "model": "contact3d",
            "status": "ok",
            "resolution": {"level": lvl, "geometry": geo},
            "timestep_factor": f,
            "wall_s_per_sim_s": w,
        }

    recs = [
        rec("pieces", "medium", 1.0, 120.0),
        rec("flanks", "medium", 1.0, 10.0),
        rec("pieces", "medium", 2.0, 60.0),
        rec("flanks", "medium", 2.0, 6.0),
        rec("flanks", "fine", 1.0, 20.0),
    ]
    assert speedups(recs) == {"s": {"medium": 12.0}}
    # 120 / 10 and 60 / 6: pieces' over flanks' wall_s_per_sim_s of the records above (by hand)
    assert recs[1]["speedup_vs_pieces"] == 12.0 and recs[3]["speedup_vs_pieces"] == 10.0
    assert "speedup_vs_pieces" not in recs[4]  # no pieces run of that level: no speed-up claimed


def test_loop_speedup_uses_the_stepping_loop_wall_time_of_the_same_records():
    from wormsim.bench.run import speedups

    def rec(geo, whole, loop):
        return {
            "scenario": "s",
            "model": "contact3d",
            "status": "ok",
            "resolution": {"level": "medium", "geometry": geo},
            "timestep_factor": 1.0,
            "wall_s_per_sim_s": whole,
            "loop_wall_s_per_sim_s": loop,
        }

    recs = [rec("pieces", 120.0, 110.0), rec("flanks", 15.0, 5.0)]
    # 120 / 15 and 110 / 5 of the records above (by hand)
    assert speedups(recs) == {"s": {"medium": 8.0}}
    assert speedups(recs, "loop_wall_s_per_sim_s", "loop_speedup_vs_pieces") == {"s": {"medium": 22.0}}
    assert recs[1]["speedup_vs_pieces"] == 8.0 and recs[1]["loop_speedup_vs_pieces"] == 22.0
    recs[0]["loop_wall_s_per_sim_s"] = None  # a level without a loop time (torsional): no loop speed-up claimed
    del recs[1]["loop_speedup_vs_pieces"]
    assert speedups(recs, "loop_wall_s_per_sim_s", "loop_speedup_vs_pieces") == {}
    assert "loop_speedup_vs_pieces" not in recs[1]


def _acc_rec(geo, f, w, p2p, eff=1e-3, **over):
    err = {"ratio": 1e-6, "tangential_force_mean_n": 1e-4, "tangential_force_p2p_n": p2p, "mesh_frequency_hz": 1e-5}
    err["efficiency"] = eff
    r = {
        "scenario": "s",
        "model": "contact3d",
        "status": "ok",
        "resolution": {"level": "medium", "geometry": geo},
        "timestep_factor": f,
        "wall_s_per_sim_s": w,
        "error": err,
    }
    r.update(over)
    return r


def test_speedup_at_equal_or_better_accuracy_takes_the_cheapest_flanks_run_at_least_as_accurate():
    """Both readings (wormsim.bench.run.speedups_equal_accuracy): against the pieces at their default step, and
    against the cheapest pieces run; a flanks run worse in one error key does not count."""
    from wormsim.bench.run import speedups_equal_accuracy

    recs = [
        _acc_rec("pieces", 2.0, 50.0, 150.0),
        _acc_rec("pieces", 1.0, 100.0, 160.0),
        _acc_rec("pieces", 0.5, 200.0, 140.0),
        _acc_rec("flanks", 4.0, 2.0, 0.5, eff=2e-3),  # cheapest, but its efficiency error is the pieces' x2
        _acc_rec("flanks", 2.0, 5.0, 0.1),
        _acc_rec("flanks", 1.0, 10.0, 0.0),
    ]
    got = speedups_equal_accuracy(recs)["s"]["medium"]
    d, c = got["vs_default_pieces"], got["vs_cheapest_pieces"]
    # 100 / 5 and 50 / 5 of the records above: the cheapest flanks run no worse in any error key (by hand)
    assert d["speedup"] == 20.0 and d["pieces_timestep_factor"] == 1.0 and d["flanks_timestep_factor"] == 2.0
    assert c["speedup"] == 10.0 and c["pieces_timestep_factor"] == 2.0 and c["flanks_timestep_factor"] == 2.0
    recs[3]["error"]["efficiency"] = 1e-3  # now as accurate: it is taken
    # 100 / 2: the cheapest flanks run is now taken (by hand)
    assert speedups_equal_accuracy(recs)["s"]["medium"]["vs_default_pieces"]["speedup"] == 50.0


def test_speedup_at_equal_accuracy_needs_every_error_key_on_both_sides():
    from wormsim.bench.run import speedups_equal_accuracy

    recs = [_acc_rec("pieces", 1.0, 100.0, 160.0), _acc_rec("flanks", 1.0, 10.0, 0.0)]
    del recs[1]["error"]["ratio"]
    assert speedups_equal_accuracy(recs)["s"]["medium"] == {"vs_default_pieces": None, "vs_cheapest_pieces": None}
    recs[1]["error"]["ratio"] = 0.0
    recs[0]["error"]["mesh_frequency_hz"] = None
    assert speedups_equal_accuracy(recs)["s"]["medium"]["vs_default_pieces"] is None
    recs[0]["error"]["mesh_frequency_hz"] = 1e-5
    # 100 / 10 of the two records (by hand)
    assert speedups_equal_accuracy(recs)["s"]["medium"]["vs_default_pieces"]["speedup"] == 10.0


def test_json_results_are_readable_by_others(tmp_path):
    import os
    import stat

    from wormsim.runfolder.writer import write_json_atomic

    write_json_atomic(tmp_path / "x.json", {"a": 1})
    mode = stat.S_IMODE(os.stat(tmp_path / "x.json").st_mode)
    umask = os.umask(0)
    os.umask(umask)
    assert mode == 0o666 & ~umask


def test_shafts_twins_follow_their_rigid_case_and_their_ratio_pairs_them():
    """bench --shafts: each flanks case at the default step is followed by its shafted twin (cases.SHAFTS_BLOCK in
    its scenario, not the reference), and shaft_ratios divides each twin by its rigid run; the twins stay out of the
    flanks-against-pieces speed-ups."""
    from wormsim.bench.cases import SHAFTS_BLOCK, bench_cases
    from wormsim.bench.run import shaft_ratios, speedups

    cases = bench_cases(quick=True, models=("contact3d",), geometries=("flanks",), shafts=True)
    twins = [i for i, c in enumerate(cases) if c.shafts]
    assert len(twins) == 2  # coarse and medium at the default step
    for i in twins:
        rigid, twin = cases[i - 1], cases[i]
        assert not rigid.shafts and rigid.timestep_factor == 1.0 and not twin.reference and not twin.finer
        assert (rigid.resolution, rigid.timestep_s, rigid.overrides) == (
            twin.resolution,
            twin.timestep_s,
            twin.overrides,
        )
        assert twin.build().shafts.worm.bending and rigid.build().shafts is None
    assert SHAFTS_BLOCK["worm"]["radial_stiffness_n_per_um"] > 0

    def rec(shafts: bool, geo: str, loop: float, best: float, wall: float) -> dict:
        return {
            "scenario": "screw_jack",
            "model": "contact3d",
            "resolution": {"level": "medium", "geometry": geo},
            "timestep_s": 1e-5,
            "timestep_factor": 1.0,
            "status": "ok",
            "shafts": shafts,
            "loop_wall_s": loop,
            "loop_wall_s_best": best,
            "wall_s": wall,
            "steps": 1000,
            "wall_s_per_sim_s": wall,
            "loop_wall_s_per_sim_s": loop,
        }

    records = [
        rec(False, "flanks", 2.0, 1.5, 3.0),
        rec(True, "flanks", 3.0, 1.8, 4.5),
        rec(False, "pieces", 20.0, 20, 30),
    ]
    r = shaft_ratios(records)["screw_jack"]["medium"]
    assert r["loop"] == 1.5 and r["loop_best"] == 1.2 and r["whole"] == 1.5
    assert r["rigid_step_wall_us"] == 2000.0 and r["shafts_step_wall_us"] == 3000.0
    assert speedups(records) == {"screw_jack": {"medium": 10.0}}  # the rigid flanks run's, not the twin's
    assert "speedup_vs_pieces" not in records[1]
