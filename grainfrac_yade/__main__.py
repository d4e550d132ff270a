"""``python3 -m grainfrac_yade``: runs the CLI under Debian's Python (where YADE lives).

When started by another interpreter (e.g. a pyenv python3 first on PATH, with
its own numpy), re-executes itself with ``/usr/bin/python3`` so that numpy,
scipy, pandas, matplotlib and YADE all come from Debian.
"""
import os
import sys

DEBIAN_PYTHON = "/usr/bin/python3"


def _reexec_under_debian_python():
    if os.environ.get("GRAINFRAC_NO_REEXEC") or os.path.realpath(sys.executable) == os.path.realpath(DEBIAN_PYTHON):
        return
    if not os.path.exists(DEBIAN_PYTHON):
        return
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    env = dict(os.environ, GRAINFRAC_NO_REEXEC="1")
    env["PYTHONPATH"] = root + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
    os.execve(DEBIAN_PYTHON, [DEBIAN_PYTHON, "-m", "grainfrac_yade", *sys.argv[1:]], env)


if __name__ == "__main__":
    _reexec_under_debian_python()
    from grainfrac_yade.cli import main
    sys.exit(main())
