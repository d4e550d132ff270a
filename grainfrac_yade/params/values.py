"""What a valid parameter value is: each schema check (:func:`_check_value`), the values the schema no longer
offers, and the key a misspelt one most likely means."""
from __future__ import annotations

import difflib
import math
from typing import Any, Mapping

from ..errors import ParameterError

#: Similarity (difflib ratio) above which a misspelt key is matched to a valid one.
NEAREST_KEY_CUTOFF = 0.6


def _check_value(value: Any, spec: Mapping, source: str, key: str):
    """Check one value against its field metadata; return it typed."""
    check, unit = spec["check"], spec["unit"]
    unit_txt = f" [{unit}]" if unit and unit != "1" else ""

    def fail(problem, fix):
        raise ParameterError(source, key, problem, fix)

    if check == "bool":
        if not isinstance(value, bool):
            fail(f"{value!r} is not true or false", "write true or false")
        return value
    if check == "choice":
        choices = spec["choices"]
        retired = RETIRED_VALUES.get(key, {}).get(value)
        if retired:
            fail(*retired)
        if value not in choices:
            fail(f"{value!r} is not one of {list(choices)}", f"use one of {list(choices)}")
        return value
    if check.endswith("_int"):
        if isinstance(value, bool) or not isinstance(value, int):
            fail(f"{value!r} is not an integer", "give a whole number")
        if check == "positive_int" and value < 1:
            fail(f"{value} must be >= 1", "give a positive whole number")
        if check == "nonnegative_int" and value < 0:
            fail(f"{value} must be >= 0", "give a whole number >= 0")
        return value
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        fail(f"{value!r} is not a number", f"give a number{unit_txt}")
    value = float(value)
    if not math.isfinite(value):
        fail(f"{value} is not finite", f"give a finite number{unit_txt}")
    rules = {
        "positive": (value > 0, f"must be > 0 (got {value:g})", f"give a positive value{unit_txt}"),
        "nonnegative": (value >= 0, f"must be >= 0 (got {value:g})", f"give a value >= 0{unit_txt}"),
        "at_least_one": (value >= 1, f"must be >= 1 (got {value:g})", f"give a value >= 1{unit_txt}"),
        "fraction": (0 <= value <= 1, f"must lie in [0, 1] (got {value:g})", "give a fraction between 0 and 1"),
        "fraction_below_half": (0 <= value < 0.5, f"must lie in [0, 0.5) (got {value:g})",
                                "give a fraction in [0, 0.5) (an edge of half the grain size or more is no sliver)"),
        "fraction_below_one": (0 <= value < 1, f"must lie in [0, 1) (got {value:g})", "give a fraction in [0, 1)"),
        "unit_interval": (0 < value <= 1, f"must lie in (0, 1] (got {value:g})", "give a value in (0, 1]"),
        "unit_interval_open": (0 < value < 1, f"must lie in (0, 1) (got {value:g})", "give a value in (0, 1)"),
        "poisson": (-1 < value < 0.5, f"must lie in (-1, 0.5) (got {value:g})", "give a Poisson's ratio below 0.5"),
        "angle": (0 <= value < 90, f"must lie in [0, 90) degrees (got {value:g})", "give an angle in degrees"),
    }
    ok, problem, fix = rules[check]
    if not ok:
        fail(problem, fix)
    return value


def nearest_key(word: str, keys) -> str | None:
    """The valid key ``word`` most likely misspells: one whose last dotted part is ``word``, else the
    most similar whole key or last part (difflib, :data:`NEAREST_KEY_CUTOFF`); None if none is close."""
    keys = list(keys)
    same_tail = [k for k in keys if k.rsplit(".", 1)[-1] == word]
    if same_tail:
        return same_tail[0]
    close = difflib.get_close_matches(word, keys, n=1, cutoff=NEAREST_KEY_CUTOFF)
    if close:
        return close[0]
    tails = {k.rsplit(".", 1)[-1]: k for k in keys}
    close = difflib.get_close_matches(word.rsplit(".", 1)[-1], list(tails), n=1, cutoff=NEAREST_KEY_CUTOFF)
    return tails[close[0]] if close else None


#: Values the schema no longer offers: dotted key -> {value: (problem, fix)}.  A parameter file, ``--set``
#: or batch table that names one is refused in one line; a params.json of an older run that names one
#: still shows in the analysis tables (they read params.json as it is), but cannot be rebuilt or resumed.
RETIRED_VALUES = {"resolution.grain_model": {
    "deformable": ("'deformable' (the spring lattice) was retired: fem cells superseded it (they agree with "
                   "the mesh reference within 2 %, the lattice missed nu by 8-11 % and tension by 2-3 x)",
                   "use resolution.grain_model = \"fem\" (params/presets/fem.toml, converged; "
                   "fem_coarse.toml, fast; docs/models.md)")}}
