"""Uniaxial compression test, one run per yade-batch row.

    yade -x yade_scripts/ucs.py
    python3 -m grainfrac_yade batch params/resolution_small.table --test ucs --jobs 2   # every row checked first
    mkdir -p results/resolution && yade-batch -j 2 --log 'results/resolution/%.log' params/resolution_small.table yade_scripts/ucs.py
Columns: any parameter path (e.g. resolution.spheres_per_cell, specimen.grain_size), plus seed, out, study.
Each row writes results/<study>/<row name>/ (summary.json, history.csv, figures).
"""
import os
import sys

# YADE runs this file as `yade -x FILE` (``__file__`` is /usr/bin/yade, no ``-m``): the repository's
# folder on sys.path is the only way to find the package from a checkout that is not installed.
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(sys.argv[0]))))

from grainfrac_yade.commands.ucs import run_ucs_in_yade  # noqa: E402
from grainfrac_yade.engines.registry import engine  # noqa: E402

run_ucs_in_yade(engine("yade").batch_rows)   # yade-batch rows: YADE reads the table
