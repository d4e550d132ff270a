"""The shipped presets (params/presets/*.toml): each loads and validates over the shipped files, the fem
preset is the converged discretisation of docs/studies/model_convergence.md (K = 8 bonds per face, 4 rings
graded in the ratio 2), and the coarse fem preset keeps the discretisation every earlier fem run used, set
in the file itself rather than taken from the shipped defaults.  Loading only: nothing is run."""
import dataclasses
import tomllib

import pytest

from conftest import ROOT
from grainfrac_yade.params import load_parameters

PRESETS = ROOT / "params" / "presets"
FEM, FEM_COARSE = PRESETS / "fem.toml", PRESETS / "fem_coarse.toml"


@pytest.mark.parametrize("preset", sorted(PRESETS.glob("*.toml")), ids=lambda p: p.name)
def test_every_preset_loads_and_validates(preset):
    load_parameters(extra_files=[str(preset)])


def test_fem_preset_is_the_converged_discretisation():
    res = load_parameters(extra_files=[str(FEM)]).resolution
    assert (res.grain_model, res.nodes_per_face, res.cell_rings, res.cell_ring_growth) == ("fem", 8, 4, 2.0)


def test_coarse_fem_preset_sets_its_discretisation_itself():
    """K = 2 and one ungraded fan per cell, written in the file: a change of the shipped defaults must not
    move the coarse preset (the tests' frozen numbers and the earlier results were measured with it)."""
    written = tomllib.loads(FEM_COARSE.read_text())["resolution"]
    assert {k: written.get(k) for k in ("grain_model", "nodes_per_face", "cell_rings", "cell_ring_growth")} == \
        {"grain_model": "fem", "nodes_per_face": 2, "cell_rings": 1, "cell_ring_growth": 1.0}


def test_fem_presets_differ_only_in_discretisation_and_reference_ucs():
    """The converged preset takes the coarse one's contact inset, Verlet distance, mass scaling and Tables 1
    and 2 as printed; only the mesh and the reference UCS (its own strength) differ."""
    fine, coarse = (load_parameters(extra_files=[str(f)]) for f in (FEM, FEM_COARSE))
    mesh = {"nodes_per_face", "cell_rings", "cell_ring_growth"}
    differ = {f"{section.name}.{key}"
              for section in dataclasses.fields(fine) if dataclasses.is_dataclass(getattr(fine, section.name))
              for key, value in dataclasses.asdict(getattr(fine, section.name)).items()
              if value != dataclasses.asdict(getattr(coarse, section.name))[key]}
    assert differ == {f"resolution.{k}" for k in mesh} | {"calibration.reference_ucs"}


@pytest.mark.parametrize("name", ["fem_calibrated.toml", "ldb_lab.toml"])
def test_calibrated_fem_presets_are_on_the_coarse_discretisation(name):
    """Their factors were fitted with 2 bonds per face and one fan per cell: they keep that mesh."""
    res, coarse = (load_parameters(extra_files=[str(f)]).resolution for f in (PRESETS / name, FEM_COARSE))
    assert res == coarse
