"""Parameter loading: the shipped files, the averaging rule, and every kind of bad input."""
import math

import numpy as np
import subprocess
import sys

import pytest

from grainfrac_yade.errors import ParameterError
from grainfrac_yade.params import default_files, load_parameters, pair_key
from conftest import ROOT

# Table 2 of the paper as printed, mixed rows included: (k_n [Pa/m], J^T [MPa], J^C [MPa], phi [deg]).
PAPER_TABLE_2 = {
    ("biotite", "biotite"): (4.20e14, 19, 37, 48),
    ("k_feldspar", "k_feldspar"): (7.75e14, 23, 52, 55),
    ("quartz", "quartz"): (1.01e15, 26, 62, 62),
    ("plagioclase", "plagioclase"): (8.00e14, 24, 57, 59),
    ("biotite", "k_feldspar"): (5.97e14, 21, 44.5, 51.5),
    ("biotite", "quartz"): (7.16e14, 22.5, 49.5, 55),
    ("biotite", "plagioclase"): (6.10e14, 21.5, 47, 53.5),
    ("k_feldspar", "quartz"): (8.93e14, 24.5, 57, 58.5),
    ("k_feldspar", "plagioclase"): (7.87e14, 23.5, 54.5, 57),
    ("quartz", "plagioclase"): (9.06e14, 25, 59.5, 60.5),
}


def half_ulp_3sig(x):
    """Half a unit in the third significant digit: the rounding error of a value printed as 1.23E+14."""
    return 0.5 * 10 ** (math.floor(math.log10(abs(x))) - 2)


def test_shipped_files_load(params):
    assert params.minerals == ("biotite", "k_feldspar", "quartz", "plagioclase")
    assert sum(params.composition.values()) == pytest.approx(1.0)
    assert len(params.contacts) == 10
    assert params.grains["quartz"].young == 91e9
    assert params.stress_corrosion.beta1 == 1e-3 and params.stress_corrosion.beta2 == 1e-7
    assert params.stress_corrosion.dt_min == 1e-5 and params.stress_corrosion.dt_max == 1e4
    assert params.stress_corrosion.unbalanced_force_threshold == 100.0
    c = params.contact("quartz", "quartz")
    assert c.residual_friction_angle == pytest.approx(math.radians(62) * 0.5)


@pytest.mark.parametrize("pair", [p for p in PAPER_TABLE_2 if p[0] != p[1]])
def test_mixed_rows_of_table_2_are_the_averages(params, pair):
    """Strengths and angles: exactly the average. k_n: within the printing precision of Table 2."""
    a, b = pair
    printed = PAPER_TABLE_2[pair]
    pa, pb = PAPER_TABLE_2[(a, a)], PAPER_TABLE_2[(b, b)]
    for col in (1, 2, 3):
        assert printed[col] == (pa[col] + pb[col]) / 2
    avg_kn = (pa[0] + pb[0]) / 2
    bound = half_ulp_3sig(printed[0]) + (half_ulp_3sig(pa[0]) + half_ulp_3sig(pb[0])) / 2
    assert abs(printed[0] - avg_kn) <= bound
    derived = params.contact(a, b)
    assert derived.normal_stiffness == avg_kn
    assert derived.tensile_strength == (pa[1] + pb[1]) / 2 * 1e6
    assert derived.cohesion == (pa[2] + pb[2]) / 2 * 1e6
    assert derived.friction_angle_deg == (pa[3] + pb[3]) / 2


def test_explicit_mixed_row_overrides_average(tmp_path):
    f = tmp_path / "mix.toml"
    f.write_text('[contacts."quartz/biotite"]\nnormal_stiffness = 7.16e14\nshear_stiffness_ratio = 1.0\n'
                 "tensile_strength = 22.5e6\nresidual_tensile_strength = 0.0\ncohesion = 49.5e6\n"
                 "residual_cohesion = 0.0\nfriction_angle_deg = 55.0\nresidual_friction_ratio = 0.5\n")
    p = load_parameters(extra_files=[f])
    assert p.contacts[pair_key("biotite", "quartz")].normal_stiffness == 7.16e14


def test_override_applies_and_is_validated():
    p = load_parameters(overrides=["stress_corrosion.beta1=0.002", 'stress_corrosion.clock="paper"'])
    assert p.stress_corrosion.beta1 == 0.002 and p.stress_corrosion.clock == "paper"
    p = load_parameters(overrides=["stress_corrosion.clock=paper"])  # bare word read as a string
    assert p.stress_corrosion.clock == "paper"


def _write_variant(tmp_path, old, new, name="ldb_granite.toml"):
    src = (ROOT / "params" / name).read_text()
    assert old in src
    f = tmp_path / name
    f.write_text(src.replace(old, new, 1))
    files = [f if p.name == name else p for p in default_files()]
    return f, files


@pytest.mark.parametrize("old,new,key,words", [
    ("normal_stiffness = 4.20e14", "normal_stiffness = -4.20e14", 'contacts."biotite/biotite".normal_stiffness',
     "must be > 0"),
    ("biotite = 0.071", "biotite = 0.081", "composition", "sum to 1.01"),
    ("young = 91e9", "youngs = 91e9", "grains.quartz.youngs", "unknown key"),
    ("poisson = 0.20", "", "grains.quartz.poisson", "missing key"),
    ("tensile_strength = 26e6", "tensile_strength = nan", 'contacts."quartz/quartz".tensile_strength',
     "not finite"),
    ("grain_size = 1.0e-3", 'grain_size = "1 mm"', "specimen.grain_size", "not a number"),
    ("dimension = 2", "dimension = 4", "specimen.dimension", "not one of"),
])
def test_bad_file_gives_one_clear_line(tmp_path, old, new, key, words):
    f, files = _write_variant(tmp_path, old, new)
    with pytest.raises(ParameterError) as err:
        load_parameters(files)
    msg = str(err.value)
    assert "\n" not in msg
    assert str(f) in msg, msg
    assert key in msg and words in msg and "fix:" in msg


@pytest.mark.parametrize("old,new,key,words", [
    ('grain_model = "rigid"', 'grain_model = "soft"', "resolution.grain_model", "not one of ['rigid', 'fem']"),
    ('grain_model = "rigid"', 'grain_model = "deformable"', "resolution.grain_model",
     "(the spring lattice) was retired: fem cells superseded it"),
    ("nodes_per_face = 2", "nodes_per_face = 0", "resolution.nodes_per_face", "must be >= 1"),
])
def test_bad_grain_model_gives_one_clear_line(tmp_path, old, new, key, words):
    f, files = _write_variant(tmp_path, old, new, name="numerics.toml")
    with pytest.raises(ParameterError) as err:
        load_parameters(files)
    msg = str(err.value)
    assert "\n" not in msg
    assert str(f) in msg and key in msg and words in msg and "fix:" in msg


def test_grain_model_defaults_to_rigid_cells(params):
    assert params.resolution.grain_model == "rigid" and params.resolution.nodes_per_face == 2
    p = load_parameters(overrides=["resolution.grain_model=fem", "resolution.nodes_per_face=3"])
    assert p.resolution.grain_model == "fem" and p.resolution.nodes_per_face == 3


def test_the_retired_lattice_gives_one_line_from_set_and_from_a_batch_table(tmp_path):
    with pytest.raises(ParameterError) as err:
        load_parameters(overrides=["resolution.grain_model=deformable"])
    msg = str(err.value)
    assert "\n" not in msg and msg.startswith("--set: resolution.grain_model:") and "retired" in msg
    assert 'use resolution.grain_model = "fem"' in msg
    from grainfrac_yade.commands.batch import check_table
    from grainfrac_yade.errors import GrainfracError
    table = tmp_path / "lattice.table"
    table.write_text("resolution.grain_model seed ratio\n'deformable' 1 0.8\n")
    with pytest.raises(GrainfracError) as err:
        check_table(table, "creep")
    msg = str(err.value)   # one bad row: one line
    assert "\n" not in msg and f"{table}:2" in msg and "retired" in msg and '"fem"' in msg


def test_missing_file_and_bad_syntax(tmp_path):
    with pytest.raises(ParameterError, match="nope.toml: \\(file\\): file not found"):
        load_parameters(extra_files=[tmp_path / "nope.toml"])
    bad = tmp_path / "bad.toml"
    bad.write_text("[specimen\nwidth = 1\n")
    with pytest.raises(ParameterError, match="bad.toml: \\(syntax\\): not valid TOML"):
        load_parameters(extra_files=[bad])


def test_dt_min_above_dt_max():
    with pytest.raises(ParameterError, match="stress_corrosion.dt_min.*exceeds dt_max"):
        load_parameters(overrides=["stress_corrosion.dt_min=1e5"])


@pytest.mark.parametrize("override,words", [
    ("stress_corrosion.beta=3", "no such parameter"),
    ("stress_corrosion.beta1=-1", "must be > 0"),
    ("beta1", "not of the form"),
    ("resolution.spheres_per_cell=1.5", "not an integer"),
    ("numerics.static_softening=linear", "not one of"),
    ("numerics.static_softening_teeth=0", "must be >= 1"),
    ("numerics.static_softening_ductility=0.5", "must be >= 1"),
])
def test_bad_override(override, words):
    with pytest.raises(ParameterError, match=words) as err:
        load_parameters(overrides=[override])
    assert str(err.value).startswith("--set")


def test_cli_prints_one_line_no_traceback(tmp_path):
    res = subprocess.run([sys.executable, "-m", "grainfrac_yade", "specimen", "--set", "composition.quartz=0.5",
                          "--out", str(tmp_path / "x")], capture_output=True, text=True, cwd=ROOT)
    assert res.returncode == 2
    lines = res.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in res.stderr
    assert "composition" in lines[0] and "fix:" in lines[0]
    assert not (tmp_path / "x").exists()


def test_temperature_form_reproduces_beta_at_25C_and_follows_eq6():
    """Paper Eq. 6: beta2 = V/RT scales as 1/T; beta1 = A exp(-E/RT) (Arrhenius)."""
    from grainfrac_yade.arrhenius import GAS_CONSTANT, physical_from_betas
    p = load_parameters()
    energy = 6.0e4   # J/mol: any positive value; the identities below hold for all
    prefactor, volume = physical_from_betas(p.stress_corrosion.beta1, p.stress_corrosion.beta2, energy, 298.15)
    form = [("stress_corrosion.rate_form", "physical"), ("stress_corrosion.rate_prefactor", prefactor),
            ("stress_corrosion.activation_energy", energy), ("stress_corrosion.activation_volume", volume)]
    at25 = load_parameters(overrides=form).stress_corrosion
    assert at25.beta1 == pytest.approx(p.stress_corrosion.beta1, rel=1e-12)
    assert at25.beta2 == pytest.approx(p.stress_corrosion.beta2, rel=1e-12)
    at80 = load_parameters(overrides=form + [("stress_corrosion.temperature", 353.15)]).stress_corrosion
    assert at80.beta2 == pytest.approx(p.stress_corrosion.beta2 * 298.15 / 353.15, rel=1e-12)
    expected = p.stress_corrosion.beta1 * np.exp(-energy / GAS_CONSTANT * (1 / 353.15 - 1 / 298.15))
    assert at80.beta1 == pytest.approx(expected, rel=1e-12) and at80.beta1 > at25.beta1


def test_temperature_form_without_activation_energy_is_one_clear_error():
    with pytest.raises(ParameterError, match="activation_energy.*fix:"):
        load_parameters(overrides=[("stress_corrosion.rate_form", "physical"),
                                   ("stress_corrosion.rate_prefactor", 1.0),
                                   ("stress_corrosion.activation_volume", 1e-4)])


def test_params_json_older_than_grain_model_loads_as_rigid_cells(tmp_path, params):
    """Runs written before resolution.grain_model / nodes_per_face existed were rigid-cell runs."""
    import json
    from grainfrac_yade.analysis.runparams import load_run_parameters
    tree = params.to_dict()
    del tree["resolution"]["grain_model"], tree["resolution"]["nodes_per_face"]
    (tmp_path / "params.json").write_text(json.dumps(tree))
    old = load_run_parameters(tmp_path, fill_missing=True)
    assert set(old.filled) == {"resolution.grain_model", "resolution.nodes_per_face"}
    assert old.params.resolution.grain_model == "rigid" and old.params == params


def test_grain_model_choices_are_the_registered_grain_models():
    import dataclasses
    from grainfrac_yade.grains import GRAIN_MODEL_NAMES, grain_model
    from grainfrac_yade.params import ResolutionParams
    spec = {f.name: f for f in dataclasses.fields(ResolutionParams)}["grain_model"].metadata
    assert tuple(spec["choices"]) == GRAIN_MODEL_NAMES
    assert [grain_model(n).name for n in GRAIN_MODEL_NAMES] == list(GRAIN_MODEL_NAMES)
