"""Typed, validated model parameters loaded from TOML files in ``params/``.

* :mod:`.schema`: every section's fields with unit, check and meaning (``_spec``), and what a valid
  value is;
* :mod:`.loading`: merging files and ``--set`` overrides into a validated :class:`Parameters`, and
  reading the parameter trees of older runs (renamed, added and retired keys);
* :mod:`.files`: reading TOML and writing parameter files.

Everything is importable from here: ``from grainfrac_yade.params import load_parameters``.
"""
from .files import *  # noqa: F401,F403
from .files import __all__ as _files
from .loading import *  # noqa: F401,F403
from .loading import __all__ as _loading
from .schema import *  # noqa: F401,F403
from .schema import __all__ as _schema

__all__ = [*_schema, *_loading, *_files]
