"""Analysis of run folders (no YADE): collect summaries into tables, draw the paper's figures."""
from .collect import collect_runs, group_stats  # noqa: F401
