"""Brazilian disc test, one run per yade-batch row.

    yade -x yade_scripts/brazilian.py
    python3 -m grainfrac_yade batch params/brazilian_ldb.table --test brazilian --jobs 2   # every row checked first
    mkdir -p results/brazilian_ldb && yade-batch -j 2 --log 'results/brazilian_ldb/%.log' params/brazilian_ldb.table yade_scripts/brazilian.py
Columns: any parameter path (e.g. brazilian.diameter, specimen.grain_size), plus seed, out, study.
Each row writes results/<study>/<row name>/ (summary.json, history.csv, cracks.csv, figures).
"""
import os
import sys

# YADE runs this file as `yade -x FILE` (``__file__`` is /usr/bin/yade, no ``-m``): the repository's
# folder on sys.path is the only way to find the package from a checkout that is not installed.
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(sys.argv[0]))))

from grainfrac_yade.commands.brazilian import run_brazilian_in_yade  # noqa: E402
from grainfrac_yade.engines.registry import engine  # noqa: E402

run_brazilian_in_yade(engine("yade").batch_rows)   # yade-batch rows: YADE reads the table
