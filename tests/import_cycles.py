"""Import cycles among the modules of ``grainfrac_yade``, found from the source with ``ast``.

Every import counts, at module level or inside a function: an import written inside a function
hides a cycle from Python's loader but not from a reader.  ``python3 tests/import_cycles.py``
prints each cycle (a strongly connected component of the import graph with more than one module)
and the module count and largest module; ``tests/test_import_cycles.py`` asserts that there are none.
"""
from __future__ import annotations

import ast
import sys
from pathlib import Path

PACKAGE = "grainfrac_yade"
ROOT = Path(__file__).resolve().parent.parent / PACKAGE


def module_name(path: Path) -> str:
    parts = path.relative_to(ROOT.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def modules() -> dict:
    """{module name: path} of every module of the package."""
    return {module_name(p): p for p in sorted(ROOT.rglob("*.py"))}


def _resolve(name: str, known: dict) -> str | None:
    """The package module that an imported dotted name lives in (the longest known prefix)."""
    while name:
        if name in known:
            return name
        name = name.rpartition(".")[0]
    return None


def imports(name: str, path: Path, known: dict) -> set:
    """Package modules that module ``name`` imports (anywhere in its source)."""
    is_pkg = path.name == "__init__.py"
    base = name.split(".") if is_pkg else name.split(".")[:-1]
    out = set()
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            targets = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                stem = base[:len(base) - node.level + 1]
                mod = ".".join(stem + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            # ``from pkg import sub`` imports the submodule; ``from mod import name`` the module
            targets = [f"{mod}.{a.name}" if f"{mod}.{a.name}" in known else mod for a in node.names]
        else:
            continue
        for t in targets:
            hit = _resolve(t, known)
            if hit and hit != name:
                out.add(hit)
    return out


def graph() -> dict:
    known = modules()
    return {n: imports(n, p, known) for n, p in known.items()}


def cycles(g: dict | None = None) -> list:
    """Strongly connected components with more than one module (Tarjan), each sorted."""
    g = graph() if g is None else g
    index, low, stack, on, out = {}, {}, [], set(), []
    counter = [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in g.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    sys.setrecursionlimit(10000)
    for v in sorted(g):
        if v not in index:
            visit(v)
    return sorted(out)


def main() -> int:
    known = modules()
    lines = {n: len(p.read_text().splitlines()) for n, p in known.items()}
    largest = max(lines, key=lines.get)
    found = cycles()
    print(f"modules: {len(known)}; largest: {largest} ({lines[largest]} lines); "
          f"over 600 lines: {sum(v > 600 for v in lines.values())}; cycles: {len(found)}")
    for c in found:
        print("  cycle:", " <-> ".join(c))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
