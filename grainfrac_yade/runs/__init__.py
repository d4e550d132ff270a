"""Run folders, batch tables and SLURM (pure core; no YADE).

* :mod:`.runio`: run folders: ``run.json`` first, atomic writes, ``summary.json`` last; code versions
  and the parameter digests that key batch rows;
* :mod:`.batchrun`: batch tables (reading, checking, writing) and running them through yade-batch;
* :mod:`.columns`: the names of the step counter and the engine's time in histories and summaries, and their
  older names;
* :mod:`.slurm`: SLURM job arrays of a table's rows; :mod:`.slurmtask`: the task each array job runs.
"""
