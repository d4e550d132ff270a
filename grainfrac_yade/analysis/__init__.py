"""Analysis of run folders (no YADE): collect summaries into tables, fit lifetimes, draw the paper's figures.

Modules: :mod:`.collect` (run folders -> DataFrame), :mod:`.lifetimes` (run outcomes, scatter per
ratio), :mod:`.fits` (static-fatigue laws), :mod:`.labdata` (lab CSV, paper reference values),
:mod:`.figures` and :mod:`.crackmaps` (PNG), :mod:`.report` (markdown), :mod:`.runparams`
(params.json -> Parameters, the run's specimen rebuilt and verified), :mod:`.rescale` (creep times
at another beta1, exact for event-clock runs of a strength law), :mod:`.study` (``analyze_study``:
study folder(s) -> report.md; imports matplotlib).  One run's results from its history (pure numpy):
:mod:`.creep_analysis` (creep stages, damage index), :mod:`.ucs_analysis`, :mod:`.brazilian_analysis`.
The lab fit (:mod:`.lab_fit`), the accuracy study's plan (:mod:`.accuracy_study`; its results:
:mod:`.accuracy`), pictures of specimens and crack maps (:mod:`.plotting`), the crack-growth animation
(:mod:`.animation`).

The names below are loaded on first use (:data:`LAZY`), so that importing one pure-numpy module of
this package (a test's results from its history, say) does not load pandas, scipy.stats or matplotlib.
"""
from importlib import import_module

#: The package's own names: {name: the module of this package that defines it}, imported on first use.
LAZY = {"collect_runs": "collect", "group_stats": "collect",
        "coefficient_table": "fits", "fit_lifetimes": "fits", "fit_line": "fits",
        "classify_runs": "lifetimes", "lifetime_stats": "lifetimes",
        "analyze_study": "study"}   # study pulls in matplotlib


def __getattr__(name):
    if name in LAZY:
        return getattr(import_module(f"{__name__}.{LAZY[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(list(globals()) + list(LAZY))
