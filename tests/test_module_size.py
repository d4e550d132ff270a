"""No module of the package is over :data:`MAX_LINES` lines: one grown past it is split by concern."""
from __future__ import annotations

from conftest import ROOT

#: The most lines a module of grainfrac_yade may have (the project's rule, docs/maintainers.md).
MAX_LINES = 500


def _sizes() -> dict:
    package = ROOT / "grainfrac_yade"
    return {p.relative_to(package).as_posix(): len(p.read_text().splitlines()) for p in package.rglob("*.py")}


def test_no_module_is_over_the_line_limit():
    sizes = _sizes()
    assert len(sizes) > 100   # the package was found
    over = {name: n for name, n in sizes.items() if n > MAX_LINES}
    assert not over, f"modules over {MAX_LINES} lines (split them by concern): {over}"

