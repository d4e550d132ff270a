"""The accuracy-cost study's plan: settings that vary one numerical knob at a time, read from
``params/accuracy_cost.toml``, and the yade-batch rows that measure them (no YADE import).

A *setting* is the shipped model plus parameter files and ``section.key`` overrides; it belongs to
one *knob* (resolution, grain deformability, creep clock, relaxation, failure criterion).  Every
setting gets creep runs at each driving-stress ratio and seed of the study; settings whose knob
changes the loading test itself (``ucs_test = true``) also get a UCS test per seed.  Each knob names
its *reference*: the most accurate of its settings that the machine affords; the error of a setting is
measured against the reference of its knob (:mod:`grainfrac_yade.analysis.accuracy`).  The shipped
defaults form the setting ``default``, a point of every knob's series.

Every row of a yade-batch table must give every column, so keys that some settings override get the
shipped value in the rows of the others: the same run as leaving them out (a batch row counts as an
override only what differs from the shipped files, :mod:`grainfrac_yade.engines.yade.batch`).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from ..errors import GrainfracError
from ..params import flat_values, load_parameters, read_toml, shipped_values

#: The shipped defaults' setting: in every knob's series, never itself a knob.
DEFAULT_SETTING = "default"
#: Keys of a [[setting]] table.
SETTING_KEYS = ("name", "knob", "what", "set", "params", "ucs_test", "ucs")
#: Keys of the [study] and [quick] tables.
STUDY_KEYS = ("folder", "width", "height", "seeds", "ratios", "ucs", "creep_time_limit", "settings")


@dataclass(frozen=True)
class Setting:
    """One point of the study: parameter files (relative to the repository) and overrides."""
    name: str
    knob: str
    what: str
    overrides: dict = field(default_factory=dict)      # {"section.key": value}
    files: tuple = ()                                    # parameter files merged over the shipped ones
    ucs_test: bool = False                               # True: the knob changes the loading test: UCS rows too
    ucs: float | None = None                             # Pa, this setting's ratio reference if not the study's


@dataclass(frozen=True)
class Knob:
    name: str
    reference: str      # the setting the knob's errors are measured against
    what: str = ""


@dataclass(frozen=True)
class Study:
    folder: Path
    width: float            # m
    height: float           # m
    seeds: tuple
    ratios: tuple           # driving-stress ratios
    ucs: float              # Pa, what every ratio refers to (unless a setting gives its own)
    creep_time_limit: float # s
    settings: tuple         # Setting, in run order
    knobs: dict             # name -> Knob

    def setting(self, name: str) -> Setting:
        return next(s for s in self.settings if s.name == name)

    def run_folder(self, setting: Setting, test: str, seed: int, ratio: float | None = None) -> Path:
        """``<folder>/<setting>/ucs_seed<S>`` or ``<folder>/<setting>/creep_r<ratio>_seed<S>``."""
        leaf = f"ucs_seed{seed}" if test == "ucs" else f"creep_r{ratio:g}_seed{seed}"
        return self.folder / setting.name / leaf


def _fail(path, key, problem, fix):
    raise GrainfracError(f"{path}: {key}: {problem}; fix: {fix}")


def _unknown_keys(path, where, table, valid):
    for key in table:
        if key not in valid:
            _fail(path, f"{where}.{key}", "unknown key", "use one of " + ", ".join(valid))


def load_study(path, quick: bool = False, repo=None) -> Study:
    """The study of ``path`` (its [study] table; with ``quick`` the [quick] table's values over it and only
    the settings it lists, plus their knobs' references).  Every setting's parameters are loaded and
    validated here, so a typo stops the command before anything runs."""
    path = Path(path)
    repo = Path(repo) if repo else Path(__file__).resolve().parents[2]
    if not path.exists():
        raise GrainfracError(f"{path}: no such file; fix: give the study file, e.g. params/accuracy_cost.toml")
    data = read_toml(path)
    for key in data:
        if key not in ("study", "quick", "knob", "setting"):
            _fail(path, key, "unknown table", "use [study], [quick], [knob.NAME] and [[setting]]")
    base = dict(data.get("study", {}))
    _unknown_keys(path, "study", base, STUDY_KEYS)
    if quick:
        extra = data.get("quick")
        if not extra:
            _fail(path, "quick", "missing", "add a [quick] table (folder, seeds, ratios, settings, ...)")
        _unknown_keys(path, "quick", extra, STUDY_KEYS)
        base.update(extra)
    for key in ("folder", "width", "height", "seeds", "ratios", "ucs", "creep_time_limit"):
        if key not in base:
            _fail(path, f"study.{key}", "missing", "give it in [study]")
    ratios = tuple(float(r) for r in base["ratios"])
    if not ratios or any(not 0 < r < 1 for r in ratios):
        _fail(path, "study.ratios", f"{list(ratios)}", "driving-stress ratios lie between 0 and 1 (of the UCS)")
    seeds = tuple(int(s) for s in base["seeds"])
    if not seeds:
        _fail(path, "study.seeds", "empty", "give at least one seed")
    for key in ("width", "height", "ucs", "creep_time_limit"):
        if not float(base[key]) > 0:
            _fail(path, f"study.{key}", f"{base[key]!r} is not positive", "give a positive value (SI units)")

    knobs = {}
    for name, table in data.get("knob", {}).items():
        _unknown_keys(path, f"knob.{name}", table, ("reference", "what"))
        if "reference" not in table:
            _fail(path, f"knob.{name}.reference", "missing", "name the knob's most accurate setting")
        knobs[name] = Knob(name, table["reference"], table.get("what", ""))
    settings = [_setting(path, i, table, knobs) for i, table in enumerate(data.get("setting", []))]
    names = [s.name for s in settings]
    if len(set(names)) != len(names):
        dup = next(n for n in names if names.count(n) > 1)
        _fail(path, f"setting {dup!r}", "named twice", "give each [[setting]] its own name")
    if DEFAULT_SETTING not in names:
        _fail(path, "setting", f"no setting named {DEFAULT_SETTING!r}", "add the shipped defaults as a setting")
    for knob in knobs.values():
        if knob.reference not in names:
            _fail(path, f"knob.{knob.name}.reference", f"no setting named {knob.reference!r}",
                  "name one of: " + ", ".join(names))
    if quick:
        wanted = list(base.get("settings") or names)
        for name in wanted:
            if name not in names:
                _fail(path, "quick.settings", f"no setting named {name!r}", "name one of: " + ", ".join(names))
        chosen = {DEFAULT_SETTING, *wanted}
        chosen |= {knobs[settings[names.index(n)].knob].reference for n in wanted if n != DEFAULT_SETTING}
        settings = [s for s in settings if s.name in chosen]
    study = Study(folder=Path(base["folder"]), width=float(base["width"]), height=float(base["height"]),
                  seeds=seeds, ratios=ratios, ucs=float(base["ucs"]),
                  creep_time_limit=float(base["creep_time_limit"]), settings=tuple(settings), knobs=knobs)
    for s in study.settings:
        load_parameters(extra_files=[repo / f for f in s.files], overrides=list(s.overrides.items())
                        + list(geometry_overrides(study).items()))
    return study


def _setting(path, index, table, knobs) -> Setting:
    where = f"setting[{index}]"
    _unknown_keys(path, where, table, SETTING_KEYS)
    name = table.get("name")
    if not name:
        _fail(path, f"{where}.name", "missing", "give each [[setting]] a name")
    knob = table.get("knob", "")
    if name != DEFAULT_SETTING and knob not in knobs:
        _fail(path, f"setting {name!r}.knob", f"{knob!r} is not a knob", "use one of " + ", ".join(knobs))
    ucs = table.get("ucs")
    if ucs is not None and not float(ucs) > 0:
        _fail(path, f"setting {name!r}.ucs", f"{ucs!r} is not positive", "give the UCS in Pa")
    return Setting(name=name, knob=knob, what=table.get("what", ""), overrides=dict(table.get("set", {})),
                   files=tuple(table.get("params", ())), ucs_test=bool(table.get("ucs_test", False)),
                   ucs=float(ucs) if ucs is not None else None)


def geometry_overrides(study: Study) -> dict:
    return {"specimen.width": study.width, "specimen.height": study.height,
            "stress_corrosion.creep_time_limit": study.creep_time_limit}


def setting_columns(study: Study, setting: Setting, repo) -> dict:
    """{"section.key": value} of the setting: its files, then its overrides, then the study's geometry."""
    return flat_values([Path(repo) / f for f in setting.files],
                       list(setting.overrides.items()) + list(geometry_overrides(study).items()))


def _fill(rows: list) -> list:
    """Every row with every column: a key a row does not set gets its shipped value."""
    shipped = shipped_values()
    keys = []
    for r in rows:
        keys += [k for k in r if k not in keys]
    missing = [k for k in keys if any(k not in r for r in rows) and k not in shipped]
    if missing:
        raise GrainfracError(f"accuracy-cost: {missing[0]} has no shipped value to fill the other rows with; fix: "
                             "give it in every setting that needs it")
    return [{k: r.get(k, shipped.get(k)) for k in keys} for r in rows]


def ucs_rows(study: Study, repo) -> list:
    """yade-batch rows of the UCS tests (settings with ``ucs_test``), seeds in order."""
    rows = [dict(setting_columns(study, s, repo), seed=seed, out=str(study.run_folder(s, "ucs", seed)),
                 description=f"{s.name}_ucs_seed{seed}")
            for s in study.settings if s.ucs_test for seed in study.seeds]
    return _fill(rows) if rows else []


def creep_rows(study: Study, repo) -> list:
    """yade-batch rows of the creep tests: per setting, per ratio, per seed (the run order)."""
    rows = [dict(setting_columns(study, s, repo), ratio=ratio, ucs=s.ucs or study.ucs, seed=seed,
                 out=str(study.run_folder(s, "creep", seed, ratio)), description=f"{s.name}_r{ratio:g}_seed{seed}")
            for s in study.settings for ratio in study.ratios for seed in study.seeds]
    return _fill(rows)


def run_index(study: Study) -> dict:
    """{run folder: (setting name, test, ratio or None, seed)} of every run the study plans."""
    index = {}
    for s in study.settings:
        for seed in study.seeds:
            index[study.run_folder(s, "ucs", seed)] = (s.name, "ucs", None, seed)
            for ratio in study.ratios:
                index[study.run_folder(s, "creep", seed, ratio)] = (s.name, "creep", ratio, seed)
    return index


def setting_of_folder(study: Study, folder) -> tuple:
    """(setting name, test, ratio or None, seed) of a run folder of the study; None if not one of its runs."""
    return run_index(study).get(Path(folder))
