"""Parameter files: reading TOML, and writing a file that the loader reads back to the same values."""
from __future__ import annotations

import json
import tomllib
from pathlib import Path
from typing import Any, Mapping

from ..atomic import write_text_atomically
from ..errors import GrainfracError, ParameterError
from .schema import PARAMS_DIR, _check_value, field_spec

def read_toml(path) -> dict:
    """Read one TOML file; a missing or malformed file raises ParameterError."""
    path = Path(path)
    try:
        with open(path, "rb") as fh:
            return tomllib.load(fh)
    except FileNotFoundError:
        raise ParameterError(str(path), "(file)", "file not found",
                             f"check the path; shipped files are in {PARAMS_DIR}") from None
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError(str(path), "(syntax)", f"not valid TOML ({exc})",
                             "fix the syntax at that line") from None
    except UnicodeDecodeError as exc:
        raise ParameterError(str(path), "(file)", f"not a text file (byte {exc.start} is not UTF-8)",
                             "give a TOML parameter file (UTF-8 text), e.g. "
                             f"{PARAMS_DIR / 'presets' / 'fem.toml'}") from None
    except IsADirectoryError:
        raise ParameterError(str(path), "(file)", "a folder, not a file",
                             f"give a TOML parameter file; shipped files are in {PARAMS_DIR}") from None


def _toml_value(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, float):
        return repr(value)            # shortest text that reads back to the same double
    if isinstance(value, int):
        return str(value)
    if isinstance(value, str):
        return json.dumps(value)      # a TOML basic string
    raise TypeError(f"no TOML form for {type(value).__name__}")


def parameter_file_text(values: Mapping[str, Any], header=(), notes: Mapping[str, str] | None = None) -> str:
    """A TOML parameter file (to merge with ``--params``) that sets ``values`` ({"section.key": value}).

    Each value is checked as the loader checks it; each line carries its unit and meaning from the
    schema, and ``notes[key]`` (e.g. where the value came from); ``header`` lines become comments.
    """
    notes = notes or {}
    lines = [f"# {h}" if h else "#" for h in header]
    by_section = {}
    for dotted, value in values.items():
        spec = field_spec(dotted)
        typed = _check_value(value, spec, "parameter file", dotted)
        by_section.setdefault(dotted.split(".")[0], []).append((dotted, typed, spec))
    for section, rows in by_section.items():
        lines += ["", f"[{section}]"]
        for dotted, typed, spec in rows:
            unit = spec["unit"] if spec["unit"] not in ("", "1") else "-"
            note = f"; {notes[dotted]}" if dotted in notes else ""
            lines.append(f"{dotted.split('.', 1)[1]} = {_toml_value(typed)}    # {unit}, {spec['doc']}{note}")
    return "\n".join(lines) + "\n"


def write_parameter_file(path, values: Mapping[str, Any], header=(), notes: Mapping[str, str] | None = None):
    """Write :func:`parameter_file_text` to ``path`` (atomically) and check that it loads; return the path."""
    text = parameter_file_text(values, header, notes)
    loaded = tomllib.loads(text)
    for dotted, value in values.items():
        section, key = dotted.split(".", 1)
        if loaded[section][key] != value:
            raise GrainfracError(f"{path}: {dotted} would read back as {loaded[section][key]!r}, not {value!r}")
    return write_text_atomically(path, text)


__all__ = ["read_toml", "parameter_file_text", "write_parameter_file"]
