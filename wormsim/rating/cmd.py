"""`wormsim rate SCENARIO --out DIR [--set ...] [--fe]`: the rating of one scenario into DIR/rating.json, rating.md."""

from __future__ import annotations

from wormsim.rating.output import write_rating
from wormsim.rating.rate import rate
from wormsim.runfolder.writer import check_writable_dir
from wormsim.scenario import load_scenario


def rate_command(scenario_path: str, out_dir: str, overrides: list[str], fe: bool = False) -> int:
    sc = load_scenario(scenario_path, overrides)
    check_writable_dir(out_dir)  # refused before any work (exit 2)
    fe = fe or (sc.rating is not None and sc.rating.root_stress == "fe")
    if sc.gear is not None:
        # teeth that cannot be made (a pointed or undercut thread, no tooth at the face edges) are refused naming the
        # field (exit 2), as `wormsim check` and `run` refuse them: no rating of a gear that does not exist, and no
        # FE solid that gmsh refuses
        from wormsim.physics.validate import validate_geometry

        validate_geometry(sc.model_copy(update={"model": "torsional"}))
    result = rate(sc)
    if fe:
        from wormsim.rating.fe_root import add_fe_root_stress

        add_fe_root_stress(sc, result)
    json_path, md_path = write_rating(out_dir, result, sc.name)
    keys = ["safety_pitting", "safety_wear", "safety_root", "safety_deflection", "safety_temperature"]
    for key in keys + (["root_stress_max_mpa", "safety_root_sim"] if "fe_root" in result else []):
        v = result.get(key)
        print(f"  {key:<20}  {v:.3g}" if isinstance(v, float) else f"  {key:<20}  -")
    for w in result["warnings"]:
        print(f"  warning: {w}")
    print(f"wrote {json_path}, {md_path}")
    return 0
