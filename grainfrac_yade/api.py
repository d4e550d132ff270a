"""The package's API for scripts: what the study scripts (``studies/``) and a user's own scripts may import.

Everything here is named in :data:`EXPORTS` (name -> the module that defines it) and loaded on first use, so that
importing this module loads neither YADE nor the other engines.  A script reaches an engine only through the
registry (:func:`engine`, :func:`engine_for`) and the hooks the engine module offers by name (docs/maintainers.md,
"The scripts' API"); it never imports an engine's sub-module or a name with a leading underscore
(``tests/test_studies_api.py`` reads every module of ``studies/`` and holds it to this).

What is here, by layer:

* parameters and specimens: :func:`load_parameters`, :data:`PARAMS_DIR`, :func:`flatten` (a parameter set as dotted
  keys), :data:`ADDED_KEYS` (keys added since the first release), :func:`build_specimen`, :func:`layout_for`,
  :func:`grain_model`, :func:`critical_dem_step`;
* the laws: :func:`build_law`, :func:`time_to_failure` (Hillig-Charles lifetime under constant stresses, Eq. 7
  integrated);
* the test protocols on any engine: :func:`run_ucs`, :func:`run_creep`, :class:`CreepRun`, :class:`TimedCreepRun`,
  :func:`run_ucs_to_folder`, :func:`run_brazilian_to_folder`, :class:`Levers`, :func:`mean_bond_force`,
  :func:`scene_density`; the engines: :func:`engine`, :func:`engine_for`;
* static solves without a protocol: :func:`elastic_summary`;
* analysis: :func:`ucs_summary`, :func:`crack_initiation_volumetric_stress`, :func:`split_peak_index`, the lab
  fit module :mod:`lab_fit`, the discretisation study's :func:`paired_changes`, :func:`log_changes` and :func:`extrapolate`;
* runs and commands: :func:`prepare_run_dir`, :func:`summary_header`, :func:`write_json`, :func:`code_version`,
  :func:`tensile_scale_overrides` (the Brazilian command's ``--tensile-scale``), :func:`static_hold` (``bench
  --static``'s timed creep test on the static engine);
* errors: :class:`GrainfracError`, :class:`NumericalFailure`.
"""
from __future__ import annotations

from importlib import import_module

#: Each exported name -> the module that defines it (a module itself where the name is the module's last part).
EXPORTS = {
    "load_parameters": "grainfrac_yade.params", "PARAMS_DIR": "grainfrac_yade.params",
    "flatten": "grainfrac_yade.params.loading", "ADDED_KEYS": "grainfrac_yade.params.loading",
    "build_specimen": "grainfrac_yade.geometry.specimen",
    "layout_for": "grainfrac_yade.grains", "grain_model": "grainfrac_yade.grains",
    "critical_dem_step": "grainfrac_yade.grains",
    "build_law": "grainfrac_yade.law", "time_to_failure": "grainfrac_yade.law.hillig_charles",
    "run_ucs": "grainfrac_yade.protocols.ucs", "run_creep": "grainfrac_yade.protocols.creep",
    "CreepRun": "grainfrac_yade.protocols.creep", "TimedCreepRun": "grainfrac_yade.protocols.timed_creep",
    "run_ucs_to_folder": "grainfrac_yade.protocols.ucs_output",
    "run_brazilian_to_folder": "grainfrac_yade.protocols.brazilian_output",
    "Levers": "grainfrac_yade.kernel.levers", "mean_bond_force": "grainfrac_yade.kernel.equilibrium",
    "scene_density": "grainfrac_yade.wave",
    "engine": "grainfrac_yade.engines.registry", "engine_for": "grainfrac_yade.engines.registry",
    "elastic_summary": "grainfrac_yade.elastic",
    "ucs_summary": "grainfrac_yade.analysis.ucs_analysis",
    "crack_initiation_volumetric_stress": "grainfrac_yade.analysis.ucs_analysis",
    "split_peak_index": "grainfrac_yade.analysis.brazilian_analysis",
    "lab_fit": "grainfrac_yade.analysis.lab_fit",
    "paired_changes": "grainfrac_yade.analysis.mesh_convergence",
    "log_changes": "grainfrac_yade.analysis.mesh_convergence",
    "extrapolate": "grainfrac_yade.analysis.mesh_convergence",
    "prepare_run_dir": "grainfrac_yade.runs.runio", "summary_header": "grainfrac_yade.runs.runio",
    "write_json": "grainfrac_yade.runs.runio", "code_version": "grainfrac_yade.runs.runio",
    "tensile_scale_overrides": "grainfrac_yade.commands.brazilian",
    "static_hold": "grainfrac_yade.commands.bench_static",
    "GrainfracError": "grainfrac_yade.errors", "NumericalFailure": "grainfrac_yade.errors",
}

__all__ = sorted(EXPORTS)


def __getattr__(name):
    """An exported name, its module imported on first use (module doc)."""
    if name not in EXPORTS:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r} (the scripts' API: {__all__})")
    where = EXPORTS[name]
    value = import_module(where) if where.rsplit(".", 1)[-1] == name else getattr(import_module(where), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(list(globals()) + __all__)
