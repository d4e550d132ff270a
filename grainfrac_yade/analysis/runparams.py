"""A run's parameters and specimen rebuilt from its params.json (pure core, no YADE).

params.json is :meth:`~grainfrac_yade.params.Parameters.to_dict`: the file layout (friction
angles as ``*_deg``, contacts keyed "a/b", SI units) plus ``sources``; it round-trips through
:func:`~grainfrac_yade.params.build_parameters` once ``sources`` is taken out. Files written
before a key was added to the schema (e.g. ``stress_corrosion.rate_form``) lack it:
:func:`load_run_parameters` can fill such keys from the shipped defaults and says which.

:func:`rebuild_specimen` tessellates the run's specimen again from params.json and the seed
(the tessellation is seeded, so it is the same specimen) and checks it against the run's own
records: the bond count of summary.json and the bond positions of cracks.csv.
"""
from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import GrainfracError
from ..geometry.specimen import build_specimen
from ..grains import layout_for
from ..params import build_parameters, load_parameters, migrate_tree

#: Sections of the file layout that are tables of one schema class (missing keys can be filled).
#: composition, grains and contacts are never filled: they define the material.
FILLABLE_EXCLUDE = ("composition", "grains", "contacts", "sources")
#: Sections whose keys make the tessellation: a filled key here means the specimen is not the run's.
GEOMETRY_SECTIONS = ("specimen",)
#: Largest distance [m] between a crack's recorded position and the rebuilt bond point.
POSITION_TOLERANCE = 1e-9


@dataclass(frozen=True)
class RunParameters:
    """Parameters of a run; ``filled``: dotted keys missing from params.json, taken from the defaults."""
    params: object           # grainfrac_yade.params.Parameters
    filled: tuple = ()
    path: Path | None = None


def _read(path: Path) -> dict:
    try:
        data = json.loads(path.read_text())
    except FileNotFoundError:
        raise GrainfracError(f"{path}: params.json not found; fix: the run folder must hold the params.json "
                             "written by the run") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise GrainfracError(f"{path}: not readable JSON ({type(exc).__name__}: {exc}); fix: restore the "
                             "run's params.json") from None
    if not isinstance(data, dict):
        raise GrainfracError(f"{path}: not a JSON object; fix: restore the run's params.json")
    return data


_DEFAULTS = None


def default_tree() -> dict:
    """The shipped parameter set as a params.json tree (cached)."""
    global _DEFAULTS
    if _DEFAULTS is None:
        _DEFAULTS = load_parameters().to_dict()
    return _DEFAULTS


def load_run_parameters(path, fill_missing: bool = False) -> RunParameters:
    """Validated :class:`Parameters` from a params.json (file or run folder).

    ``fill_missing``: keys of the schema sections (not composition/grains/contacts) that the file
    lacks are taken from the shipped defaults and listed in ``filled``. Any other problem (unknown
    key, bad value, missing material table) raises GrainfracError naming the file.
    """
    path = Path(path)
    if path.is_dir():
        path = path / "params.json"
    tree = _read(path)
    sources = tree.pop("sources", ())
    migrate_tree(tree)   # renamed keys (stress_corrosion.mode -> stress_corrosion.law) read as today's
    filled = []
    if fill_missing:
        for section, table in default_tree().items():
            if section in FILLABLE_EXCLUDE or not isinstance(table, dict):
                continue
            mine = tree.setdefault(section, {})
            if not isinstance(mine, dict):
                continue   # reported by build_parameters
            for key, value in table.items():
                if key not in mine:
                    mine[key] = value
                    filled.append(f"{section}.{key}")
    origins = {}
    try:
        params = build_parameters(tree, origins, tuple(sources) if isinstance(sources, list) else ())
    except GrainfracError as exc:
        raise GrainfracError(f"{path}: {exc}") from None
    return RunParameters(params, tuple(filled), path)


def parameters_from_json(path):
    """:class:`~grainfrac_yade.params.Parameters` of a params.json (exactly as written; no filling)."""
    return load_run_parameters(path).params


@dataclass(frozen=True)
class RebuiltSpecimen:
    specimen: object         # grainfrac_yade.geometry.specimen.Specimen
    run_params: RunParameters
    checks: tuple            # what was verified against the run's records (text)

    @property
    def note(self) -> str:
        text = f"{self.specimen.n_cells} cells rebuilt from params.json and seed {self.specimen.seed}"
        if self.checks:
            text += "; verified: " + ", ".join(self.checks)
        if self.run_params.filled:
            text += "; keys missing in params.json taken from the shipped defaults (they do not shape the " \
                    "specimen): " + ", ".join(self.run_params.filled)
        return text


def rebuild_specimen(folder, seed, n_bonds=None, cracks=None) -> RebuiltSpecimen:
    """The run's specimen from its params.json and ``seed``, checked against the run's records.

    ``n_bonds``: summary.json's bond count (compared with the rebuilt layout); ``cracks``:
    cracks.csv with ``bond``, ``x_m``, ``y_m`` (each crack must sit on the rebuilt bond point).
    Raises GrainfracError with the reason when the specimen cannot be rebuilt or does not match.
    """
    folder = Path(folder)
    try:
        seed = int(seed)
    except (TypeError, ValueError):
        raise GrainfracError(f"{folder}: run.json has no integer seed ({seed!r}); fix: cannot rebuild the "
                             "specimen without its seed") from None
    rp = load_run_parameters(folder, fill_missing=True)
    shaping = [k for k in rp.filled if k.split(".")[0] in GEOMETRY_SECTIONS]
    if shaping:
        raise GrainfracError(f"{folder / 'params.json'}: lacks {', '.join(shaping)} (older format); fix: the "
                             "specimen cannot be rebuilt exactly, the outline is drawn instead")
    params = rp.params
    if params.specimen.dimension != 2:
        raise GrainfracError(f"{folder}: 3D specimen (specimen.dimension = {params.specimen.dimension}); "
                             "fix: grain maps are drawn for 2D specimens only")
    specimen = build_specimen(params, seed)
    checks = []
    need_layout = n_bonds is not None or (cracks is not None and len(cracks) and
                                          all(c in cracks for c in ("bond", "x_m", "y_m")))
    if need_layout:
        layout = layout_for(specimen, params)
        if n_bonds is not None and np.isfinite(float(n_bonds)):
            if layout.n_bonds != int(n_bonds):
                raise GrainfracError(f"{folder}: rebuilt specimen has {layout.n_bonds} bonds, summary.json "
                                     f"{int(n_bonds)}; fix: params.json or the code changed since the run, the "
                                     "outline is drawn instead")
            checks.append(f"{layout.n_bonds} bonds as in summary.json")
        if cracks is not None and len(cracks) and all(c in cracks for c in ("bond", "x_m", "y_m")):
            bond = cracks["bond"].to_numpy()
            if bond.min() < 0 or bond.max() >= layout.n_bonds:
                raise GrainfracError(f"{folder}: cracks.csv names bond {int(bond.max())} but the rebuilt "
                                     f"specimen has {layout.n_bonds} bonds; fix: the outline is drawn instead")
            err = float(np.max(np.abs(layout.bond_point[bond, :2] - cracks[["x_m", "y_m"]].to_numpy(float))))
            if not err <= POSITION_TOLERANCE:
                raise GrainfracError(f"{folder}: cracks.csv positions lie up to {err:.3g} m from the rebuilt bond "
                                     "points; fix: params.json or the code changed since the run, the outline is "
                                     "drawn instead")
            checks.append(f"all {len(bond)} crack positions on the rebuilt bonds (max deviation {err:.1g} m)")
    return RebuiltSpecimen(specimen, rp, tuple(checks))
