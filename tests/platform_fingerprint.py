"""The software and CPU a stored exact result was made on, and the stored set matching this machine.

A one-thread YADE run is deterministic on one machine, but not across CPUs: numpy dispatches its
ufuncs (exp, log, ...) to the widest SIMD extension the CPU has, and glibc picks its libm variants
by CPU, so a last bit can differ, and past the first bond break the DEM is chaotic.  Measured: the
reference creep runs made on an Intel Xeon, rerun on an AMD EPYC with AVX-512 (same Debian
packages), gave lifetimes x 2.2 and x 1.001 apart and a 6 x 12 mm UCS 1e-6 apart.  Two AMD EPYCs with
the same model string and SIMD target differ too (a CPU of family 26 did not reproduce the set written
on an earlier "AMD EPYC, AVX512_ICL": lifetimes x 2.2 apart), so the fingerprint holds the CPU's family,
model and stepping as well (``cpu_id``, from /proc/cpuinfo).  So exact
results are stored per fingerprint under ``tests/data/reference/<set>/`` and compared exactly only
on a machine with the same fingerprint; elsewhere each test states what it compares instead.
"""
import json
import platform
import re
import subprocess
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))   # also when tests/reference_creep.py runs as a script
from grainfrac_yade.commands.bench import cpu_model  # noqa: E402  (the CPU's model name, as the benchmark records it)

REFERENCE = Path(__file__).resolve().parent / "data" / "reference"
#: What must be equal for an exact comparison (see module doc).
FINGERPRINT_KEYS = ("machine", "cpu", "cpu_id", "simd", "libc", "python", "numpy", "yade_package")
#: /proc/cpuinfo fields that tell CPUs with one model string apart.
CPU_ID_FIELDS = ("cpu family", "model", "stepping")


def numpy_simd() -> str:
    """The widest SIMD target numpy dispatches to on this CPU (e.g. ``AVX512_ICL``, ``AVX2``)."""
    try:
        from numpy.core._multiarray_umath import __cpu_dispatch__, __cpu_features__
    except ImportError:
        return "unknown"
    usable = [t for t in __cpu_dispatch__ if __cpu_features__.get(t)]
    return usable[-1] if usable else "baseline"


def cpu_id() -> str:
    """The first CPU's family, model and stepping from /proc/cpuinfo ("unknown" where it is not readable)."""
    try:
        lines = Path("/proc/cpuinfo").read_text().split("\n\n")[0].splitlines()
    except OSError:
        return "unknown"
    fields = {k.strip(): v.strip() for k, _, v in (line.partition(":") for line in lines)}
    return " ".join(f"{k.split()[-1]} {fields[k]}" for k in CPU_ID_FIELDS if k in fields) or "unknown"


def this_platform() -> dict:
    yade = subprocess.run(["dpkg-query", "-W", "-f=${Version}", "yade"], capture_output=True, text=True).stdout
    return {"machine": platform.machine(), "cpu": cpu_model(), "cpu_id": cpu_id(), "simd": numpy_simd(),
            "libc": "-".join(platform.libc_ver()), "python": platform.python_version(), "numpy": np.__version__,
            "yade_package": yade}


def fingerprint(record: dict) -> tuple:
    return tuple(record.get(k) for k in FINGERPRINT_KEYS)


def set_name(record: dict) -> str:
    """A folder name for a stored set: CPU model, its family/model/stepping (where recorded) and SIMD target
    (two machines with the same model string and SIMD target need two folders)."""
    cpu = f"{record['cpu']} {record.get('cpu_id', '')} {record['simd']}"
    return re.sub(r"[^a-z0-9]+", "_", cpu.lower()).strip("_")


def stored_sets() -> list:
    """Every stored set's folder, oldest first by name."""
    return sorted(p.parent for p in REFERENCE.glob("*/platform.json"))


def matching_set():
    """The folder of the stored set made on this machine's fingerprint, or None."""
    here = fingerprint(this_platform())
    for folder in stored_sets():
        if fingerprint(json.loads((folder / "platform.json").read_text())) == here:
            return folder
    return None


def write_platform(folder: Path, note: str = "") -> Path:
    """Create ``folder`` (if needed) with this machine's ``platform.json``."""
    folder.mkdir(parents=True, exist_ok=True)
    record = {**this_platform(), **({"note": note} if note else {})}
    (folder / "platform.json").write_text(json.dumps(record, indent=1) + "\n")
    return folder
