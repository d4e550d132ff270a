"""How a command reports a run's end in one line: its outcome, what its engine counted, a time in a readable unit,
and the line of a run that ended as a numerical failure (exit status 3)."""
from __future__ import annotations

from ..analysis.durations import readable_duration
from ..errors import EXIT_NUMERICAL_FAILURE


def seconds(value: float) -> str:
    """A time in s, with the unit that reads best beside it where that is not s: "1.2e+07 s (140 d)"."""
    readable = readable_duration(value)
    return f"{value:.4g} s" + (f" ({readable})" if readable and not readable.endswith(" s") else "")


def outcome(summary: dict) -> str:
    """One phrase: numerical failure, lifetime, failure on loading, or not failed by the end."""
    if summary.get("numerical_failure"):
        return f"no result ({summary['failure_reason']})"
    if summary.get("failed_before_test"):
        return f"failed before the test ({summary['failure_reason']})"
    if summary.get("failed_on_loading"):
        return "failed on loading (during the ramp)"
    if summary["failed"]:
        first = ", in the relaxation after its first creep event" if summary.get("failed_in_first_relaxation") else ""
        return f"lifetime {seconds(summary['lifetime_s'])}{first}"
    return f"not failed by {seconds(summary['creep_time_end_s'])}"


def steps_phrase(summary: dict) -> str:
    """"1234 DEM steps" or, for an engine without dynamics, "170 equilibria solved" (summary ``steps_counted``;
    "steps" for a run written before the key)."""
    return f"{summary['steps']} {summary.get('steps_counted', 'steps')}"


def numerical_failure_line(test: str, summary: dict, out) -> str:
    """The one line (stderr) of a run that ended as a numerical failure: the test, the engine, what it did before,
    the reason, and where its summary.json (``numerical_failure: true``) is."""
    reason = str(summary.get("failure_reason") or summary.get("end_reason")).removeprefix("numerical failure: ")
    return (f"numerical failure: {test}, {summary.get('engine', 'yade')} engine: no result ({reason}); exit status "
            f"{EXIT_NUMERICAL_FAILURE}, summary.json says numerical_failure: true -> {out}")
