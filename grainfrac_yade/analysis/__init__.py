"""Analysis of run folders (no YADE): collect summaries into tables, fit lifetimes, draw the paper's figures.

Modules: :mod:`.collect` (run folders -> DataFrame), :mod:`.lifetimes` (run outcomes, scatter per
ratio), :mod:`.fits` (static-fatigue laws), :mod:`.labdata` (lab CSV, paper reference values),
:mod:`.figures` and :mod:`.crackmaps` (PNG), :mod:`.report` (markdown), :mod:`.runparams`
(params.json -> Parameters, the run's specimen rebuilt and verified), :mod:`.rescale` (creep times
at another beta1, exact for event-clock runs of a strength law), :mod:`.study` (``analyze_study``:
study folder(s) -> report.md; imports matplotlib).
"""
from .collect import collect_runs, group_stats  # noqa: F401
from .fits import coefficient_table, fit_lifetimes, fit_line  # noqa: F401
from .lifetimes import classify_runs, lifetime_stats  # noqa: F401


def __getattr__(name):
    if name == "analyze_study":   # lazily: pulls in matplotlib
        from .study import analyze_study
        return analyze_study
    raise AttributeError(name)
