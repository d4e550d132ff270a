"""Atomic file writes: a reader sees a file whole or not at all (pure standard library)."""
from __future__ import annotations

import os
from pathlib import Path


def write_atomically(path, write) -> Path:
    """Call ``write(tmp)`` on a temporary name beside ``path``, flush it to disk, rename it to ``path``."""
    path = Path(path)
    tmp = path.with_name(path.name + ".tmp")
    write(tmp)
    with open(tmp, "rb+") as fh:
        os.fsync(fh.fileno())
    os.replace(tmp, path)
    return path


def write_text_atomically(path, text: str) -> Path:
    """Write ``text`` to ``path`` atomically."""
    return write_atomically(path, lambda tmp: Path(tmp).write_text(text))
