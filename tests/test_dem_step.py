"""Critical DEM step without YADE (grainfrac_yade/dem_step.py) against the YADE scene's ``dt_critical``.

The scene sets its masses and step with the same functions, so the two are equal to the last bit for
bodies whose positions the core knows exactly (one sphere per cell, fem spheres: YADE
stores the given centres).  Clumps: YADE sums its members' masses and positions itself; the core's
weighted mean agrees to rounding (1e-12 relative: a few additions of float64).
"""
from __future__ import annotations

import json

import pytest

from conftest import needs_yade
from grainfrac_yade.grains import critical_dem_step
from grainfrac_yade.params import load_parameters
from grainfrac_yade.geometry.specimen import build_specimen

TINY = ["specimen.width=4e-3", "specimen.height=8e-3"]
CLUMP_REL = 1e-12   # see module doc

MODELS = {
    "rigid": [],
    "rigid_clumps": ["resolution.spheres_per_cell=8"],
    "fem": ["resolution.grain_model=fem"],
    "fem_regularised_floor": ["resolution.grain_model=fem", "specimen.min_edge_fraction=0.05",
                              "numerics.step_floor_quantile=0.3"],
    "rigid_regularised_floor": ["specimen.min_edge_fraction=0.05", "numerics.step_floor_quantile=0.3"],
}


@needs_yade
@pytest.mark.yade
@pytest.mark.parametrize("model", sorted(MODELS))
def test_core_step_is_the_scene_step(model):
    from grainfrac_yade.engines.yade.scene import build_scene
    p = load_parameters(overrides=TINY + MODELS[model])
    s = build_specimen(p, 2)
    core = critical_dem_step(s, p)
    scene = build_scene(s, p)
    if model == "rigid_clumps":
        assert core == pytest.approx(scene.dt_critical, rel=CLUMP_REL)
    else:
        assert core == scene.dt_critical
    assert scene.O.dt == p.numerics.timestep_safety * scene.dt_critical


def test_specimen_json_reports_step_and_short_faces(tmp_path):
    from grainfrac_yade.commands.specimen import run_specimen
    p = load_parameters(overrides=TINY + ["resolution.grain_model=fem", "specimen.min_edge_fraction=0.05"])
    run_specimen(p, 2, tmp_path / "run")
    rec = json.loads((tmp_path / "run" / "specimen.json").read_text())
    s = build_specimen(p, 2)
    assert rec["critical_dem_step_s"] == critical_dem_step(s, p) > 0
    assert rec["dem_step_s"] == p.numerics.timestep_safety * rec["critical_dem_step_s"]
    assert rec["grain_model"] == "fem" and rec["min_edge_fraction"] == 0.05
    assert rec["edges_collapsed"] == s.edges_collapsed > 0 and rec["edges_kept_short"] == 0
    assert rec["shortest_face_m"] == s.tessellation.face_measure.min() >= 0.05 * p.specimen.grain_size
