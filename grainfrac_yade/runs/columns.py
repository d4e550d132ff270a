"""Names of the step counter and the engine's time in histories and summaries, for any engine, and the names
runs written before had (read as today's by the analysis, resumes and migrations).

A scene counts ``steps`` (DEM steps of a dynamic engine, solves of a static one) and has a ``time`` (DEM time,
or a static engine's load parameter): :class:`grainfrac_yade.engines.Scene`.
"""
from __future__ import annotations

#: History column of the step count at the row, and of the engine's time [s].
STEP, TIME = "step", "time_s"
#: Summary key of the steps the run took.
STEPS = "steps"
#: What a scene's ``steps`` count, by whether its engine integrates motion (the engine's ``dynamic``): summary
#: key ``steps_counted`` and the commands' result lines.  A static (or hybrid) engine solves equilibria; the hybrid's
#: dynamic stints count their DEM steps apart (``dynamic_stint_dem_steps``).
STEPS_COUNTED = {True: "DEM steps", False: "equilibria solved"}
#: The summary key of :data:`STEPS_COUNTED`'s words.
STEPS_COUNTED_KEY = "steps_counted"


def steps_counted(engine) -> str:
    """What the ``steps`` of a run on ``engine`` (an :class:`grainfrac_yade.engines.EngineModule`,
    :func:`grainfrac_yade.engines.registry.engine_for`) count."""
    return STEPS_COUNTED[bool(engine.dynamic)]


#: History columns renamed: the old name -> today's (UCS and Brazilian histories had ``dem_step`` and
#: ``dem_time_s``, creep histories ``dem_steps``).
HISTORY_RENAMED = {"dem_step": STEP, "dem_time_s": TIME, "dem_steps": STEP}
#: Summary keys renamed: the old name -> today's.
SUMMARY_RENAMED = {"dem_steps": STEPS}


def history_as_today(history):
    """A history (a DataFrame, or a dict of columns or a row) with its old column names read as today's (the
    same object if none is old)."""
    old = [k for k in HISTORY_RENAMED if k in history]
    if not old:
        return history
    if hasattr(history, "rename"):
        return history.rename(columns={k: HISTORY_RENAMED[k] for k in old})
    return {HISTORY_RENAMED.get(k, k): v for k, v in history.items()}


def summary_as_today(summary: dict) -> dict:
    """A summary.json with its old keys read as today's."""
    if not any(k in summary for k in SUMMARY_RENAMED):
        return summary
    return {SUMMARY_RENAMED.get(k, k): v for k, v in summary.items()}
