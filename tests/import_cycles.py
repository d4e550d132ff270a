"""Import cycles among the modules of ``grainfrac_yade``, found from the source with ``ast``.

Every import counts, wherever and however it is written: at module level or inside a function (an
import written inside a function hides a cycle from Python's loader but not from a reader), in a lazy
module ``__getattr__``, and by ``importlib.import_module`` with a literal name, an f-string such as
``f"{__name__}.{name}"`` whose loop variable runs over a literal list (a registry), or, when the name
is not literal, any module of that package.  Importing ``pkg.sub`` from outside ``pkg`` runs
``pkg/__init__.py`` first, so it counts as an import of ``pkg`` too.

``python3 tests/import_cycles.py`` prints each cycle (a strongly connected component of the import
graph with more than one module), the module count, the largest module and the imports written inside
functions (all, and those of the package's own modules); ``tests/test_import_cycles.py`` asserts that
there is no cycle and that every in-function import of the package's own modules is an allowed one.
"""
from __future__ import annotations

import ast
import sys
from pathlib import Path

PACKAGE = "grainfrac_yade"
ROOT = Path(__file__).resolve().parent.parent / PACKAGE

#: Libraries heavy or optional enough that a module may import them, or a module of the package that loads
#: them, inside the function that needs them (docs/maintainers.md): a command's start-up stays short.
HEAVY = ("matplotlib", "pandas", "vtk", "vtkmodules", "PIL", "scipy.stats")

#: How an import is written (``Import.kind``).
TOP, FUNCTION, IMPORTLIB = "top", "function", "importlib"


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


def _parents(target: str, importer: str, known: dict) -> list:
    """Packages whose ``__init__`` importing ``target`` runs and that ``importer`` is not already inside."""
    out = []
    parts = target.split(".")
    for i in range(1, len(parts)):
        pkg = ".".join(parts[:i])
        if pkg in known and pkg != importer and not importer.startswith(pkg + "."):
            out.append(pkg)
    return out


class Import:
    """One import statement or call: the importing module, its line, the dotted name, how it is written."""

    def __init__(self, module, line, target, kind, in_function):
        self.module, self.line, self.target, self.kind, self.in_function = module, line, target, kind, in_function

    def __repr__(self):
        where = "in a function" if self.in_function else "at module level"
        return f"{self.module}:{self.line} imports {self.target} ({self.kind}, {where})"


def _literal_strings(node) -> list | None:
    """The strings of a literal tuple/list/set of strings, else None."""
    if isinstance(node, (ast.Tuple, ast.List, ast.Set)) and all(
            isinstance(e, ast.Constant) and isinstance(e.value, str) for e in node.elts):
        return [e.value for e in node.elts]
    return None


def _string_values(tree) -> dict:
    """{name: [strings]} for names bound to literal lists of strings: ``NAME = ("a", "b")`` and
    ``for name in ("a", "b")`` (or over such a NAME); ``{"NAME[]": [strings]}`` for the values of a
    literal dict ``NAME = {key: "a", ...}``."""
    values = {}
    for node in ast.walk(tree):
        if isinstance(node, ast.Assign) and len(node.targets) == 1 and isinstance(node.targets[0], ast.Name):
            lit = _literal_strings(node.value)
            if lit is not None:
                values.setdefault(node.targets[0].id, []).extend(lit)
            if isinstance(node.value, ast.Dict) and all(
                    isinstance(v, ast.Constant) and isinstance(v.value, str) for v in node.value.values):
                values.setdefault(node.targets[0].id + "[]", []).extend(v.value for v in node.value.values)
    for node in ast.walk(tree):
        if isinstance(node, (ast.For, ast.comprehension)) and isinstance(node.target, ast.Name):
            lit = _literal_strings(node.iter)
            if lit is None and isinstance(node.iter, ast.Name):
                lit = values.get(node.iter.id)
            if lit is not None:
                values.setdefault(node.target.id, []).extend(lit)
    return values


def _call_names(arg, name: str, values: dict) -> list | None:
    """The module names an ``import_module`` argument can take; a trailing ``*`` means any module of
    that package; None if it cannot be read."""
    if isinstance(arg, ast.Constant) and isinstance(arg.value, str):
        return [arg.value]
    if isinstance(arg, ast.Name) and arg.id == "__name__":
        return [name]
    if isinstance(arg, ast.Name):
        return values.get(arg.id)
    if isinstance(arg, ast.Subscript) and isinstance(arg.value, ast.Name):
        return values.get(arg.value.id + "[]")
    if isinstance(arg, ast.FormattedValue):
        return _call_names(arg.value, name, values)
    parts = None
    if isinstance(arg, ast.JoinedStr):
        parts = arg.values
    elif isinstance(arg, ast.BinOp) and isinstance(arg.op, ast.Add):
        parts = [arg.left, arg.right]
    if parts is None:
        return None
    out = [""]
    for p in parts:
        vals = _call_names(p, name, values)
        if vals is None:
            return [o + "*" for o in out]   # the rest is unknown: any module under the prefix so far
        out = [o + v for o in out for v in vals]
    return out


def _is_import_module(call) -> bool:
    f = call.func
    return ((isinstance(f, ast.Attribute) and f.attr == "import_module") or
            (isinstance(f, ast.Name) and f.id in ("import_module", "__import__")))


def import_list(name: str, path: Path, known: dict) -> list:
    """Every :class:`Import` written in module ``name`` (of any module, the package's or not)."""
    is_pkg = path.name == "__init__.py"
    base = name.split(".") if is_pkg else name.split(".")[:-1]
    tree = ast.parse(path.read_text(), str(path))
    values = _string_values(tree)
    out = []

    def visit(node, in_function):
        for child in ast.iter_child_nodes(node):
            inner = in_function or isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda))
            if isinstance(child, ast.Import):
                for a in child.names:
                    out.append(Import(name, child.lineno, a.name, FUNCTION if in_function else TOP, in_function))
            elif isinstance(child, ast.ImportFrom):
                if child.level:
                    stem = base[:len(base) - child.level + 1]
                    mod = ".".join(stem + ([child.module] if child.module else []))
                else:
                    mod = child.module or ""
                for a in child.names:
                    # ``from pkg import sub`` imports the submodule; ``from mod import name`` the module
                    t = f"{mod}.{a.name}" if f"{mod}.{a.name}" in known else mod
                    out.append(Import(name, child.lineno, t, FUNCTION if in_function else TOP, in_function))
            elif isinstance(child, ast.Call) and _is_import_module(child) and child.args:
                targets = _call_names(child.args[0], name, values)
                package = next((k.value for k in child.keywords if k.arg == "package"), None)
                for t in targets or []:
                    if t.startswith(".") and isinstance(package, ast.Name) and package.id == "__name__":
                        t = ".".join(base) + t
                    if t.endswith("*"):
                        prefix = t[:-1].rstrip(".")
                        for m in known:
                            if m.startswith(prefix + ".") and "." not in m[len(prefix) + 1:]:
                                out.append(Import(name, child.lineno, m, IMPORTLIB, in_function))
                    else:
                        out.append(Import(name, child.lineno, t, IMPORTLIB, in_function))
            visit(child, inner)

    visit(tree, False)
    return out


def imports(name: str, path: Path, known: dict) -> set:
    """Package modules that module ``name`` imports (anywhere in its source, however written), with the
    packages whose ``__init__`` those imports run."""
    out = set()
    for imp in import_list(name, path, known):
        hit = _resolve(imp.target, known)
        if hit and hit != name:
            out.add(hit)
            out.update(_parents(hit, name, known))
    return out


def graph() -> dict:
    known = modules()
    return {n: imports(n, p, known) for n, p in known.items()}


def in_function_imports(own_only: bool = True) -> list:
    """The imports written inside functions (of the package's own modules only, unless ``own_only`` is
    False), as :class:`Import` with ``target`` the package module imported."""
    known = modules()
    out = []
    for n, p in known.items():
        for imp in import_list(n, p, known):
            if not imp.in_function or imp.kind == IMPORTLIB:
                continue
            hit = _resolve(imp.target, known)
            if hit:
                imp.target = hit
                out.append(imp)
            elif not own_only:
                out.append(imp)
    return out


def heavy_libraries(name: str, known: dict | None = None, _memo: dict | None = None) -> set:
    """The :data:`HEAVY` libraries that importing module ``name`` loads: its module-level imports, and
    theirs in turn (with the package ``__init__`` each runs)."""
    known = modules() if known is None else known
    memo = {} if _memo is None else _memo
    if name in memo:
        return memo[name]
    memo[name] = set()   # a module being visited adds nothing twice
    out = set()
    for imp in import_list(name, known[name], known):
        if imp.in_function:
            continue
        hit = _resolve(imp.target, known)
        if hit is None:
            out.update(h for h in HEAVY if imp.target == h or imp.target.startswith(h + "."))
        elif hit != name:
            for m in [hit] + _parents(hit, name, known):
                out |= heavy_libraries(m, known, memo)
    memo[name] = out
    return out


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
    every = in_function_imports(own_only=False)
    own = [i for i in every if i.target.startswith(PACKAGE)]
    statements = len({(i.module, i.line) for i in every})
    own_statements = len({(i.module, i.line) for i in own})
    print(f"modules: {len(known)}; largest: {largest} ({lines[largest]} lines); "
          f"over 600 lines: {sum(v > 600 for v in lines.values())}; cycles: {len(found)}; "
          f"in-function import statements: {statements}, of the package's own modules: {own_statements}")
    for c in found:
        print("  cycle:", " <-> ".join(c))
    if "-v" in sys.argv[1:]:
        for i in own:
            print("  in a function:", i)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
