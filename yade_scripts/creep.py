"""Constant-load creep test to failure, one run per yade-batch row.

    yade -x yade_scripts/creep.py                       (defaults: needs a ratio or stress column)
    python3 -m grainfrac_yade batch params/lifetime_small.table --test creep --jobs 2   # every row checked first
    mkdir -p results/lifetime_small && yade-batch -j 2 --log 'results/lifetime_small/%.log' params/lifetime_small.table yade_scripts/creep.py
Columns: ratio or stress [Pa] (not both), optional ucs [Pa], seed, study, out, and any parameter path
(e.g. stress_corrosion.clock). Each row writes results/<study>/<row name>/.
"""
import os
import sys

# YADE runs this file as `yade -x FILE` (``__file__`` is /usr/bin/yade, no ``-m``): the repository's
# folder on sys.path is the only way to find the package from a checkout that is not installed.
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(sys.argv[0]))))

from grainfrac_yade.commands.creep import run_creep_in_yade  # noqa: E402
from grainfrac_yade.engines.registry import engine  # noqa: E402

run_creep_in_yade(engine("yade").batch_rows)   # yade-batch rows: YADE reads the table
