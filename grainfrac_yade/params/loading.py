"""Loading parameters: merge files and ``--set`` overrides, validate them into :class:`Parameters`, and
read the parameter trees of older runs (renamed, added and retired keys).

A parameter set is the merge of one or more TOML files (later files win) plus ``--set
section.key=value`` overrides.  The merged set must name every key of the schema and nothing else;
each value is checked (sign, range, type).  Errors are :class:`~grainfrac_yade.errors.ParameterError`
with one line naming the file, the key and the fix.
"""
from __future__ import annotations

import dataclasses
import math
import tomllib
from itertools import combinations_with_replacement
from typing import Mapping

from ..arrhenius import betas_from_physical
from ..contact_strength import MIN_WEIBULL_MODULUS
from ..errors import GrainfracError, ParameterError
from ..failure_criterion import check_combination
from ..law.readings import FACE_READING_LAWS
from .cells import cell_count
from .fem_only import check_fem_only
from .files import read_toml
from .schema import (DEFAULT_FILES, FRACTION_SUM_TOLERANCE, PARAMS_DIR, SECTION_CLASSES, ContactParams, GrainParams,
                     Parameters, SpecimenParams, StressCorrosionParams, _check_value, average_contact, field_spec,
                     nearest_key, pair_key)

#: Keys renamed in the schema: old dotted key -> (new dotted key, {old value: new value}).  Parameter
#: files and --set refuse the old key in one line; params.json of older runs are migrated on reading
#: (:func:`migrate_tree`).
RENAMED_KEYS = {"stress_corrosion.mode": ("stress_corrosion.law", {"strength": "hillig_charles", "area": "area"}),
                # one interval for every test since the UCS and Brazilian tests checkpoint too; same value
                "creep.checkpoint_interval": ("numerics.checkpoint_interval", {})}


def renamed_key_fix(dotted: str) -> str | None:
    """The fix for a key the schema renamed (None if ``dotted`` was not renamed)."""
    if dotted not in RENAMED_KEYS:
        return None
    new, values = RENAMED_KEYS[dotted]
    if not values:
        section, key = new.split(".")
        return f"{dotted} was moved to {new}; write {key} = ... under [{section}] (same value), or --set {new}=..."
    mapping = ", ".join(f'{old!r} -> {v!r}' for old, v in values.items())
    return f"{dotted} was replaced by {new}; write {new.rsplit('.', 1)[-1]} = ... ({mapping})"


#: Keys added to the schema after runs were made, with the value every run before had by construction
#: (no such knob then): params.json of older runs read them so (:func:`migrate_tree`).
ADDED_KEYS = {"numerics.engine": "yade", "specimen.min_edge_fraction": 0.0, "numerics.keep_intact_joints": False,
              "creep.servo_response_crossings": 0.0, "creep.max_relaxation_crossings": 0.0,
              "calibration.shear_stiffness_ratio_scale": 1.0, "calibration.tensile_cohesion_ratio_scale": 1.0,
              "calibration.inter_mineral_strength_ratio": 1.0, "calibration.strength_weibull_modulus": 0.0,
              "resolution.cell_rings": 1, "resolution.cell_ring_growth": 1.0, "numerics.static_condensation": "none",
              "numerics.static_softening": "none", "numerics.static_softening_teeth": 1, "numerics.static_softening_ductility": 1.0, "numerics.static_failure": "bond",
              "stress_corrosion.reading": "node"}


def migrate_tree(tree: dict) -> list:
    """Rewrite renamed keys of a nested parameter tree (a params.json) in place, and give keys added later
    (:data:`ADDED_KEYS`) the value older runs had; return what changed."""
    notes = []
    for dotted, value in ADDED_KEYS.items():
        section, key = dotted.split(".")
        table = tree.get(section)
        if isinstance(table, dict) and key not in table:
            table[key] = value
            notes.append(f"{dotted} absent (older run) read as {value!r}")
    for old, (new, values) in RENAMED_KEYS.items():
        section, key = old.split(".")
        table = tree.get(section)
        if not isinstance(table, dict) or key not in table:
            continue
        value = table.pop(key)
        new_section, new_key = new.split(".")
        target = tree.setdefault(new_section, {}) if new_section != section else table
        if not isinstance(target, dict):
            continue
        if new_key not in target:
            target[new_key] = values.get(value, value)
        notes.append(f"{old} = {value!r} read as {new} = {target[new_key]!r}")
    return notes


def _build(cls, table: Mapping, origins: Mapping, section: str):
    """Build dataclass ``cls`` from a TOML table, rejecting unknown and missing keys."""
    names = [f.name for f in dataclasses.fields(cls)]
    for key in table:
        renamed = renamed_key_fix(f"{section}.{key}")
        if renamed:
            raise ParameterError(origins.get(f"{section}.{key}", "parameters"), f"{section}.{key}", "renamed key",
                                 renamed)
        if key not in names:
            close = nearest_key(key, names)
            hint = f"did you mean {close!r}?" if close else f"known keys: {', '.join(names)}"
            raise ParameterError(origins.get(f"{section}.{key}".replace('"', ""), "parameters"), f"{section}.{key}",
                                 "unknown key", f"remove it or correct the spelling ({hint})")
    values = {}
    for f in dataclasses.fields(cls):
        dotted = f"{section}.{f.name}"
        origin_key = dotted.replace('"', "")
        if f.name not in table:
            raise ParameterError(_section_origin(origins, section), dotted, "missing key",
                                 f"add `{f.name} = ...` [{f.metadata['unit']}] ({f.metadata['doc']})")
        values[f.name] = _check_value(table[f.name], f.metadata, origins.get(origin_key, "parameters"), dotted)
    return cls(**values)


def _section_origin(origins: Mapping, section: str) -> str:
    section = section.replace('"', "")
    files = sorted({v for k, v in origins.items() if k.startswith(section + ".")})
    return " + ".join(files) if files else "parameter files"


def flatten(table: Mapping, prefix: str = "", hashable: bool = False) -> dict:
    """Nested dict -> {"section.key": value}; ``hashable`` turns lists into tuples (to compare, group)."""
    out = {}
    for key, value in table.items():
        dotted = f"{prefix}{key}"
        if isinstance(value, dict):
            out.update(flatten(value, dotted + ".", hashable))
        else:
            out[dotted] = tuple(value) if hashable and isinstance(value, list) else value
    return out


def _merge(base: dict, new: Mapping, origins: dict, source: str, prefix: str = ""):
    for key, value in new.items():
        dotted = f"{prefix}{key}"
        if isinstance(value, dict):
            _merge(base.setdefault(key, {}), value, origins, source, dotted + ".")
        else:
            base[key] = value
            origins[dotted] = source


class FlagOverride(tuple):
    """A ``(key, value)`` override given by a shortcut flag (``--width``, ``--confinement``, ...): unpacks as the
    pair; ``flag`` is what the user typed, named by a refusal in place of ``--set``."""

    def __new__(cls, key: str, value, flag: str = "--set"):
        self = super().__new__(cls, (key, value))
        self.flag = flag
        return self

    def __getnewargs__(self):   # copy and pickle rebuild it from these (a tuple's own would drop the flag)
        return (self[0], self[1], self.flag)


def override_origin(item) -> str:
    """How the user gave override ``item``: its shortcut flag, else ``--set``."""
    return getattr(item, "flag", "--set")


def parse_override(text: str) -> tuple:
    """Split ``section.key=value``; the value is read as TOML, else as a plain string."""
    if "=" not in text or "." not in text.split("=", 1)[0]:
        raise ParameterError("--set", text, "not of the form section.key=value",
                             "write e.g. --set stress_corrosion.beta1=0.002")
    key, raw = (s.strip() for s in text.split("=", 1))
    try:
        value = tomllib.loads(f"v = {raw}")["v"]
    except tomllib.TOMLDecodeError:
        value = raw
    return key, value


def _nest(dotted: str, value) -> dict:
    """``a.b.c`` -> {"a": {"b": {"c": value}}}; quoted parts ("a/b") kept whole."""
    parts = []
    buf, quoted = "", False
    for ch in dotted:
        if ch == '"':
            quoted = not quoted
        elif ch == "." and not quoted:
            parts.append(buf)
            buf = ""
        else:
            buf += ch
    parts.append(buf)
    out = value
    for part in reversed(parts):
        out = {part: out}
    return out


def default_files() -> list:
    """The shipped parameter files, in merge order."""
    return [PARAMS_DIR / name for name in DEFAULT_FILES]


def shipped_values() -> dict:
    """The shipped parameters, flattened: {"section.key": value} (unvalidated, as the files write them)."""
    return flat_values(default_files())


def flat_values(files, overrides=()) -> dict:
    """Parameter ``files`` merged in order, then ``overrides`` (``section.key=value`` strings or (key, value)
    pairs), as {"section.key": value}: the columns of a yade-batch row."""
    out = {}
    for path in files:
        out.update(flatten(read_toml(path)))
    for item in overrides:
        key, value = parse_override(item) if isinstance(item, str) else item
        out[key] = value
    return out


def load_parameters(files=None, overrides=(), extra_files=()) -> Parameters:
    """Load, merge and validate parameters.

    Parameters
    ----------
    files : list of paths, optional
        Files merged in order (later wins). Default: :func:`default_files`.
    overrides : iterable of str or (key, value)
        ``section.key=value`` strings or pairs applied last (as ``--set`` on the CLI); a
        :class:`FlagOverride` pair is named by its flag in errors.
    extra_files : list of paths
        Files merged after ``files`` (the CLI's ``--params``).
    """
    files = list(default_files() if files is None else files) + list(extra_files)
    merged, origins = {}, {}
    for path in files:
        _merge(merged, read_toml(path), origins, str(path))
    _check_overridden_file_values(merged, origins, overrides)
    for text in overrides:
        key, value = parse_override(text) if isinstance(text, str) else text
        origin = override_origin(text)
        flat_known = flatten(merged)
        if renamed_key_fix(key):
            raise ParameterError(origin, key, "renamed key", renamed_key_fix(key))
        if key not in flat_known and not _is_new_pair_key(key):
            close = nearest_key(key, flat_known)
            raise ParameterError(origin, key, "no such parameter",
                                 f"did you mean {close}?" if close else "use a dotted key that exists in the "
                                 "parameter files, e.g. stress_corrosion.beta1")
        _check_override_value(key, value, origin)
        _merge(merged, _nest(key, value), origins, origin)
    return build_parameters(merged, origins, tuple(str(p) for p in files))


def _check_overridden_file_values(merged: Mapping, origins: Mapping, overrides):
    """A file's value is checked even where a flag or ``--set`` replaces it: a file is valid whatever overrides it
    (else the same file fails on the next run without the flag).  Schema keys only (their unit and check); the
    mineral tables (contacts, grains, composition) are checked by their own builders whenever they are read."""
    flat = flatten(merged)
    for item in overrides:
        key = (parse_override(item) if isinstance(item, str) else item)[0]
        origin = origins.get(key.replace('"', ""))
        if key not in flat or origin is None:
            continue
        try:
            spec = field_spec(key)
        except ParameterError:
            continue
        _check_value(flat[key], spec, origin, key)


def _check_override_value(key: str, value, origin: str):
    """An override's value is checked as it is given, even where a later one (a flag after ``--set``) replaces it:
    a ``--set specimen.width=nan`` hidden by ``--width`` is refused, not dropped unseen.  Schema keys only."""
    try:
        spec = field_spec(key)
    except ParameterError:
        return   # a mineral table's key: checked by its own builder
    _check_value(value, spec, origin, key)


def check_conflicting_overrides(overrides) -> None:
    """ParameterError if one key is given two different values on one command line (``--set`` and a flag that
    sets it, e.g. ``--set numerics.engine=static --engine yade``, or ``--set`` twice): neither silently wins.
    ``overrides``: the command line's (``section.key=value`` strings or :class:`FlagOverride` pairs), in order."""
    first = {}
    for item in overrides:
        key, value = parse_override(item) if isinstance(item, str) else item
        if key not in first:
            first[key] = (value, item)
            continue
        earlier, given = first[key]
        if earlier != value:
            raise ParameterError(_typed(item, key, value), key,
                                 f"also given as {_typed(given, key, earlier)}: two values ({earlier!r} and {value!r})",
                                 f"give {key} once: drop one of the two")


def _typed(item, key: str, value) -> str:
    """How the user typed override ``item``: ``--set key=value`` or the flag (``--engine``)."""
    flag = override_origin(item)
    return f"--set {key}={value}" if flag == "--set" else flag


def _is_new_pair_key(key: str) -> bool:
    return key.startswith("contacts.")


#: Sections of one test's protocol that no other command reads, added to the schema after runs were made: a
#: parameter tree without one (the params.json of an older run, read back by ``creep --resume`` or the
#: analysis) takes the shipped values, so that it still loads.  A parameter file never lacks them: files are
#: merged over the shipped ones.
LATER_PROTOCOL_SECTIONS = ("brazilian", "confinement")


def _shipped_section(section: str):
    """The shipped files' table ``section`` (None if they have none)."""
    merged = {}
    for path in default_files():
        _merge(merged, read_toml(path), {}, str(path))
    return merged.get(section)


def build_parameters(merged: Mapping, origins: Mapping, sources=()) -> Parameters:
    """Validate a merged nested dict into :class:`Parameters`."""
    known = set(SECTION_CLASSES) | {"composition", "grains", "contacts"}
    for section in merged:
        if section not in known:
            raise ParameterError(_section_origin(origins, section), section, "unknown section",
                                 f"remove it or use one of {sorted(known)}")
    merged = dict(merged)
    for section in known:
        if section not in merged and section in LATER_PROTOCOL_SECTIONS:
            shipped = _shipped_section(section)
            if shipped is not None:
                merged[section] = shipped
                origins = {**origins, **{f"{section}.{k}": "shipped defaults" for k in shipped}}
                continue
        if section not in merged:
            raise ParameterError(" + ".join(sources) or "parameters", section, "missing section",
                                 f"add a [{section}] table (see {PARAMS_DIR})")
    typed = {name: _build(cls, merged[name], origins, name) for name, cls in SECTION_CLASSES.items()}
    composition = _composition(merged["composition"], origins)
    minerals = tuple(composition)
    grains = {}
    for mineral, table in merged["grains"].items():
        if mineral not in composition:
            raise ParameterError(origins.get(f"grains.{mineral}.young", "parameters"), f"grains.{mineral}",
                                 "mineral not in [composition]", f"add it to [composition] or remove it")
        grains[mineral] = _build(GrainParams, table, origins, f"grains.{mineral}")
    for mineral in minerals:
        if mineral not in grains:
            raise ParameterError(_section_origin(origins, "grains"), f"grains.{mineral}", "missing mineral",
                                 f"add a [grains.{mineral}] table (paper Table 1)")
    typed["contacts"] = _contacts(merged["contacts"], origins, minerals)
    sc = typed["stress_corrosion"]
    if sc.dt_min > sc.dt_max:
        raise ParameterError(origins.get("stress_corrosion.dt_min", "parameters"), "stress_corrosion.dt_min",
                             f"dt_min = {sc.dt_min:g} s exceeds dt_max = {sc.dt_max:g} s",
                             "make dt_min <= dt_max")
    typed["stress_corrosion"] = _rate_constants(sc, origins)
    _check_law(sc, origins)
    _check_grain_size(typed["specimen"], origins)
    _check_weibull_modulus(typed["calibration"], origins)
    check_fem_only(typed["resolution"], typed["numerics"], origins)
    check_combination(typed["numerics"], origins)
    return Parameters(composition=composition, grains=grains, sources=tuple(sources), **typed)


def _on_command_line(origin) -> bool:
    """Whether a value's origin is the command line (``--set`` or a flag such as ``--height``), not a file."""
    return isinstance(origin, str) and origin.startswith("--")


def _check_grain_size(sp: SpecimenParams, origins: Mapping):
    """A grain must be smaller than the specimen's width and height (at or above, the specimen is a few
    cells at most) and leave at least two cells (a lone cell has no face to bond). The 3D box depth may
    be thinner (one layer).  The refusal names what the user gave: the side when the command line gave it
    and a file the grain size (``--height 1e-5`` is the flag's fault, not the file's), else the grain size.
    A box whose cell count overflows a float (``--width 1e308``) is refused naming its largest side."""
    name, side = min([("width", sp.width), ("height", sp.height)], key=lambda s: s[1])
    grain_origin = origins.get("specimen.grain_size", "parameters")
    side_origin = origins.get(f"specimen.{name}", "parameters")
    if sp.grain_size >= side and _on_command_line(side_origin) and not _on_command_line(grain_origin):
        raise ParameterError(side_origin, f"specimen.{name}",
                             f"{side:g} m is at or below the grain size (specimen.grain_size = {sp.grain_size:g} m, "
                             f"{grain_origin})", f"give a {name} above the grain size (paper: 31.7 x 63.4 mm with "
                             "1 mm grains; e.g. 10e-3 m), or a smaller grain size")
    if sp.grain_size >= side:
        raise ParameterError(grain_origin, "specimen.grain_size",
                             f"{sp.grain_size:g} m is at or above the specimen's {name} ({side:g} m)",
                             f"make specimen.grain_size smaller than specimen.{name} (paper: 1 mm in a 31.7 mm "
                             f"wide specimen) or enlarge the specimen")
    if sp.min_edge_fraction > 0 and sp.dimension != 2:
        raise ParameterError(origins.get("specimen.min_edge_fraction", "parameters"), "specimen.min_edge_fraction",
                             f"{sp.min_edge_fraction:g} with specimen.dimension = 3: edge collapse is built for "
                             "plane (2D) tessellations only", "set specimen.min_edge_fraction = 0 for the 3D box")
    box = [sp.width, sp.height] + ([sp.thickness] if sp.dimension == 3 else [])
    count = cell_count(box, sp.grain_size)
    if not math.isfinite(count):
        sides = [("width", sp.width), ("height", sp.height)] + ([("thickness", sp.thickness)] if sp.dimension == 3
                                                                 else [])
        name, side = max(sides, key=lambda s: s[1])
        raise ParameterError(origins.get(f"specimen.{name}", "parameters"), f"specimen.{name}",
                             f"{side:g} m makes a specimen of more cells than a float counts (grain size "
                             f"{sp.grain_size:g} m)", f"give the {name} in m (paper: 31.7 x 63.4 mm, i.e. "
                             "31.7e-3 x 63.4e-3)")
    if round(count) < 2:
        raise ParameterError(origins.get("specimen.grain_size", "parameters"), "specimen.grain_size",
                             f"{sp.grain_size:g} m gives a specimen of one cell (a lone cell has no face to bond)",
                             "make specimen.grain_size smaller or enlarge the specimen")


def _check_weibull_modulus(cal, origins: Mapping):
    """The Weibull modulus of contact strength is 0 (no scatter) or at least
    :data:`~grainfrac_yade.contact_strength.MIN_WEIBULL_MODULUS`."""
    m = cal.strength_weibull_modulus
    if 0 < m < MIN_WEIBULL_MODULUS:
        raise ParameterError(origins.get("calibration.strength_weibull_modulus", "parameters"),
                             "calibration.strength_weibull_modulus",
                             f"{m:g} is below {MIN_WEIBULL_MODULUS:g} (the exponential distribution, CV 1): most faces "
                             "would be all but unbonded", f"give 0 (no scatter) or a modulus >= {MIN_WEIBULL_MODULUS:g} "
                             "(e.g. 3: CV 0.36)")


def require_plane(params: Parameters, command: str):
    """GrainfracError unless the specimen is 2D: ``command`` runs plane specimens only."""
    if params.specimen.dimension != 2:
        raise GrainfracError(f"specimen.dimension = {params.specimen.dimension}: the {command} command runs plane "
                             "(2D) specimens only; fix: set specimen.dimension = 2 (the specimen command builds "
                             "3D specimens)")


def _check_law(sc: StressCorrosionParams, origins: Mapping):
    """The activation threshold belongs to the strength laws: the area law has none.  A reading other than the
    bond's own needs a law that keeps the driving stress apart from the one its criteria read."""
    if sc.reading != "node" and sc.law not in FACE_READING_LAWS:
        raise ParameterError(origins.get("stress_corrosion.reading", "parameters"), "stress_corrosion.reading",
                             f"{sc.reading!r} with law = {sc.law!r} (that law fails a bond where its driving stress "
                             "meets its strength: one stress for both)",
                             f"set stress_corrosion.reading = \"node\", or law = {' or '.join(FACE_READING_LAWS)}")
    if sc.law == "area":
        for key in ("threshold_ratio", "threshold_stress"):
            if getattr(sc, key) > 0:
                raise ParameterError(origins.get(f"stress_corrosion.{key}", "parameters"), f"stress_corrosion.{key}",
                                     f"{getattr(sc, key):g} with law = \"area\" (the area law has no activation "
                                     "threshold)", "set it to 0, or choose law hillig_charles or normalised")


def _rate_constants(sc: StressCorrosionParams, origins: Mapping) -> StressCorrosionParams:
    """With ``rate_form = "physical"``, beta1 and beta2 are computed from paper Eq. 6 at the temperature."""
    if sc.rate_form == "beta":
        return sc
    for key, unit in (("rate_prefactor", "Pa/s"), ("activation_energy", "J/mol"), ("activation_volume", "m^3/mol")):
        if getattr(sc, key) <= 0:
            raise ParameterError(origins.get(f"stress_corrosion.{key}", "parameters"), f"stress_corrosion.{key}",
                                 "must be > 0 with rate_form = physical (the paper gives only beta1, beta2 at 25 C)",
                                 f"set it [{unit}] from your data, e.g. with arrhenius.physical_from_betas")
    beta1, beta2 = betas_from_physical(sc.rate_prefactor, sc.activation_energy, sc.activation_volume, sc.temperature)
    return dataclasses.replace(sc, beta1=beta1, beta2=beta2)


def _composition(table: Mapping, origins: Mapping) -> dict:
    out = {}
    for mineral, value in table.items():
        out[mineral] = _check_value(value, {"check": "fraction", "unit": "1"},
                                    origins.get(f"composition.{mineral}", "parameters"), f"composition.{mineral}")
    if not out:
        raise ParameterError(_section_origin(origins, "composition"), "composition", "no minerals",
                             "list each mineral's area fraction")
    total = sum(out.values())
    if abs(total - 1.0) > FRACTION_SUM_TOLERANCE:
        raise ParameterError(_section_origin(origins, "composition"), "composition",
                             f"area fractions sum to {total:.6g}, not 1",
                             "make the fractions add up to 1 (paper: 0.071, 0.511, 0.318, 0.100)")
    return out


def _contacts(table: Mapping, origins: Mapping, minerals: tuple) -> dict:
    given = {}
    for name, row in table.items():
        parts = name.split("/")
        if len(parts) != 2 or any(p not in minerals for p in parts):
            raise ParameterError(origins.get(f"contacts.{name}.normal_stiffness", "parameters"),
                                 f'contacts."{name}"', "not a pair of known minerals",
                                 f'name it "a/b" with a and b from {list(minerals)}')
        key = pair_key(*parts)
        if key in given:
            raise ParameterError(origins.get(f"contacts.{name}.normal_stiffness", "parameters"),
                                 f'contacts."{name}"', "pair given twice", "keep one of the two tables")
        given[key] = _build(ContactParams, row, origins, f'contacts."{name}"')
    contacts = {}
    for a, b in combinations_with_replacement(minerals, 2):
        key = pair_key(a, b)
        if key in given:
            contacts[key] = given[key]
        elif a == b:
            raise ParameterError(_section_origin(origins, "contacts"), f'contacts."{a}/{a}"',
                                 "missing pure-mineral contact", f'add a [contacts."{a}/{a}"] table (paper Table 2)')
        else:
            pa, pb = pair_key(a, a), pair_key(b, b)
            if pa not in given or pb not in given:
                continue  # reported when the loop reaches the pure pair
            contacts[key] = average_contact(given[pa], given[pb])
    return contacts


__all__ = ["RENAMED_KEYS", "renamed_key_fix", "ADDED_KEYS", "migrate_tree", "flatten", "parse_override", "FlagOverride", "check_conflicting_overrides", "override_origin", "default_files", "shipped_values", "flat_values", "load_parameters", "LATER_PROTOCOL_SECTIONS", "build_parameters", "require_plane"]
