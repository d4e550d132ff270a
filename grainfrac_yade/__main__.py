"""``python3 -m grainfrac_yade``: runs the CLI under Debian's Python (where YADE lives), in a repeatable process.

When started by another interpreter (e.g. a pyenv python3 first on PATH, with
its own numpy), re-executes itself with ``/usr/bin/python3`` so that numpy,
scipy, pandas, matplotlib and YADE all come from Debian.  And it re-executes
itself without address-space randomisation and with a fixed hash seed
(:mod:`grainfrac_yade.repeatable`), so that one command gives the same numbers
in every process, finite-element cells included; ``GRAINFRAC_REPEATABLE=0``
keeps the randomised process.
"""
import os
import sys

from grainfrac_yade.repeatable import repeatable_environment

DEBIAN_PYTHON = "/usr/bin/python3"


def _reexec():
    if os.environ.get("GRAINFRAC_NO_REEXEC"):
        return
    env = repeatable_environment()
    python = sys.executable
    if os.path.exists(DEBIAN_PYTHON) and os.path.realpath(python) != os.path.realpath(DEBIAN_PYTHON):
        python = DEBIAN_PYTHON
    elif env is None:
        return
    env = dict(os.environ if env is None else env, GRAINFRAC_NO_REEXEC="1")
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    env["PYTHONPATH"] = root + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
    os.execve(python, [python, "-m", "grainfrac_yade", *sys.argv[1:]], env)


if __name__ == "__main__":
    _reexec()
    from grainfrac_yade.cli import main
    sys.exit(main())
