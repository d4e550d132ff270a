"""The only part of grainfrac_yade that imports YADE.

YADE 2023.02a (Debian bookworm) is built for Debian's ``/usr/bin/python3``;
its Python package lives outside ``sys.path`` (see shared/yade_notes.md).
:func:`load_yade` is the one place that knows where.
"""
from __future__ import annotations

import contextlib
import io
import os
import sys

from ...errors import GrainfracError

#: Where Debian's yade package installs its Python modules (double precision build).
YADE_PY_PATH = "/usr/lib/x86_64-linux-gnu/yade-double/py"
#: The interpreter YADE is built for.
DEBIAN_PYTHON = "/usr/bin/python3"
#: OpenMP threads per YADE run unless the user sets OMP_NUM_THREADS: one thread makes a run
#: deterministic (shared/yade_notes.md, determinism; with 2 threads a 6 x 12 mm UCS peak moved
#: by 5 %, 268.8 vs 282.2 MPa, measured 2026-11-23); studies run in parallel across runs instead.
DEFAULT_THREADS = "1"

_yade = None
#: What YADE's import printed (its "Using python version ..." banner), kept off the console: a command's output
#: is the project's own lines.  Under ``yade -x`` (batch rows) the binary prints it first, into the row's log.
import_output = ""


def use_default_threads():
    """OMP_NUM_THREADS = :data:`DEFAULT_THREADS` unless the user set it.  Must come before anything loads the
    OpenMP runtime, which reads it once: Debian's matplotlib loads it (libgomp), and a YADE imported after a
    figure module then ran 2 threads (not reproducible, and 16 x the CPU time on a loaded machine)."""
    os.environ.setdefault("OMP_NUM_THREADS", DEFAULT_THREADS)


def load_yade():
    """Import YADE once and return the ``yade`` module; clear error if impossible."""
    global _yade
    if _yade is not None:
        return _yade
    use_default_threads()
    if YADE_PY_PATH not in sys.path:
        sys.path.insert(0, YADE_PY_PATH)
    global import_output
    try:
        with contextlib.redirect_stdout(io.StringIO()) as printed:   # YADE's "Using python version ..." banner
            import yade  # noqa: F401
            from yade import wrapper  # noqa: F401
        import_output = printed.getvalue()
    except ImportError as exc:
        raise GrainfracError(
            f"YADE cannot be imported in {sys.executable} ({exc}); fix: run with {DEBIAN_PYTHON} "
            "after `apt-get install yade` (see README)") from None
    _yade = yade
    return yade
