"""``status``: rows of a SLURM study finished, running, failed and pending.

    python3 -m grainfrac_yade status results/NAME [--json]

From the run folders and task records first (a summary.json is finished, a failed.json failed),
then from ``squeue`` (queued and running tasks) and ``sacct`` (how ended tasks ended) where they
answer; without them the states come from the files alone, and the output says so.
"""
from __future__ import annotations

import json
import os
from pathlib import Path

from ..runs.slurm import STATES
from ..runs.slurm_states import study_states


def register(sub, common):
    p = sub.add_parser("status", help="SLURM study: rows finished, running, failed, pending (files + squeue/sacct)")
    p.add_argument("folder", help="study folder written by submit (results/NAME)")
    p.add_argument("--json", action="store_true", help="print the states as JSON (one object)")
    p.set_defaults(func=cmd_status)


def status_report(folder) -> dict:
    """The states of a submitted study as one JSON-ready dict."""
    record, states, queue, acct = study_states(folder)
    counts = {s: sum(1 for x in states if x.state == s) for s in STATES}
    return {"study": record["study"], "folder": str(folder), "table": record["source_table"],
            "script": record["script"], "jobs": [{k: sub[k] for k in ("job_id", "rows", "submitted", "sbatch")}
                                                 for sub in record.get("submissions", [])],
            "counts": counts, "rows": [s.to_dict() for s in states],
            "squeue": queue.note if queue.available else f"not available: {queue.note}",
            "sacct": acct.note if acct.available else f"not available: {acct.note}"}


def _short(path: str) -> str:
    """``path`` relative to the current folder when inside it."""
    rel = os.path.relpath(path)
    return path if rel.startswith("..") else rel


def cmd_status(args) -> int:
    rep = status_report(Path(args.folder))
    if args.json:
        print(json.dumps(rep, indent=2))
        return 0
    c = rep["counts"]
    print(f"study {rep['study']} ({rep['folder']}): {len(rep['rows'])} rows of {rep['table']}, script "
          f"{Path(rep['script']).name}")
    for job in rep["jobs"]:
        print(f"  job {job['job_id']}: rows {','.join(map(str, job['rows']))}, submitted {job['submitted']}")
    print(f"finished {c['finished']}, running {c['running']}, failed {c['failed']}, pending {c['pending']}")
    width = max(len(r["job"] or "-") for r in rep["rows"])
    for r in rep["rows"]:
        where = _short(r["folder"]) if r["folder"] else "(no run folder yet)"
        detail = f": {r['detail']}" if r["detail"] else ""
        print(f"  row {r['row']:>3} (line {r['line']:>3})  {r['state']:<8}  {(r['job'] or '-'):<{width}}  "
              f"{where}{detail}")
    notes = [f"squeue {rep['squeue']}" for _ in [0] if rep["squeue"].startswith("not available")]
    notes += [f"sacct {rep['sacct']}" for _ in [0] if rep["sacct"].startswith("not available")]
    if notes:
        print("note: " + "; ".join(notes) + " (states of ended tasks from their run folders and task records)")
    if c["failed"] or (c["pending"] and not rep["jobs"]):
        print(f"resubmit the rows without a summary.json: python3 -m grainfrac_yade submit {rep['table']} "
              f"--study {rep['study']}")
    return 0
