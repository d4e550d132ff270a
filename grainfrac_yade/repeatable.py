"""A process whose floating-point sums run in the same order every time: the same run, the same numbers.

YADE's finite-element cells sum their node forces in an order that follows where objects lie in memory, so
two processes of one fem row gave different results (4 x 8 mm fem UCS, seed 1: 324.13-325.24 MPa over 12
processes).  Where objects lie depends on the address-space layout, which Linux randomises per process, and on
Python's string hashing, which is seeded per process.  With both fixed, every process of one command lays its
objects out alike and gives the same results bit for bit (7 of 7 processes, docs/studies/static_engine.md
"Repeatable processes").  Rigid cells never depended on either.

:func:`repeatable_environment` turns the randomisation off for the calling process (Linux ``personality``
flag ``ADDR_NO_RANDOMIZE``, kept across ``exec`` and inherited by children such as yade-batch's rows) and returns
the environment with ``PYTHONHASHSEED=0``; ``python3 -m grainfrac_yade`` re-executes itself with both
(``__main__``).  :func:`process_is_repeatable` says whether the running process has both (run.json records it).
Same machine, same libraries and the same command: the same numbers; another machine may differ in the last
digits.
"""
from __future__ import annotations

import ctypes
import ctypes.util
import os

#: Linux personality flag: no address-space layout randomisation for this process and what it executes.
ADDR_NO_RANDOMIZE = 0x0040000
#: The hash seed of a repeatable process (any fixed value would do; 0 also turns Python's hash seeding off).
HASH_SEED = "0"
#: Environment variable: "0" keeps the randomised process (nothing re-executed for it).
OPT_OUT = "GRAINFRAC_REPEATABLE"


def _personality() -> int | None:
    """The process's personality flags, or None where it cannot be read (not Linux)."""
    try:
        with open("/proc/self/personality") as f:
            return int(f.read().strip(), 16)
    except (OSError, ValueError):
        return None


def process_is_repeatable() -> bool:
    """True if this process runs without address-space randomisation and with the fixed hash seed."""
    flags = _personality()
    return flags is not None and bool(flags & ADDR_NO_RANDOMIZE) and os.environ.get("PYTHONHASHSEED") == HASH_SEED


def repeatable_environment(environ=None) -> dict | None:
    """Turn address-space randomisation off for this process (and what it executes next) and return ``environ``
    (default: this process's) with the fixed hash seed; None where that cannot be done (not Linux, the call
    refused) or was declined (``GRAINFRAC_REPEATABLE=0``) or is already so (nothing to re-execute)."""
    env = dict(os.environ if environ is None else environ)
    flags = _personality()
    if env.get(OPT_OUT) == "0" or flags is None:
        return None
    if flags & ADDR_NO_RANDOMIZE and env.get("PYTHONHASHSEED") == HASH_SEED:
        return None
    if not flags & ADDR_NO_RANDOMIZE:
        name = ctypes.util.find_library("c")
        try:
            libc = ctypes.CDLL(name, use_errno=True)
            if libc.personality(ctypes.c_ulong(flags | ADDR_NO_RANDOMIZE)) == -1:
                return None
        except (OSError, AttributeError):
            return None
    env["PYTHONHASHSEED"] = HASH_SEED
    return env
