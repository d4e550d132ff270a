"""Build a grain specimen and its YADE scene; write specimen.json and specimen.png.

    yade -x yade_scripts/specimen.py                      # defaults (paper-size specimen)
    yade-batch params/specimen_small.table yade_scripts/specimen.py
Columns: any parameter path (e.g. specimen.width), plus seed, out, study.
"""
import os
import sys

# YADE runs this file as `yade -x FILE` (``__file__`` is /usr/bin/yade, no ``-m``): the repository's
# folder on sys.path is the only way to find the package from a checkout that is not installed.
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(sys.argv[0]))))

from grainfrac_yade.commands.specimen import run_specimen_in_yade  # noqa: E402
from grainfrac_yade.engines.registry import engine  # noqa: E402

run_specimen_in_yade(engine("yade").batch_rows)   # yade-batch rows: YADE reads the table
