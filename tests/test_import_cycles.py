"""The package's modules import each other one way only: no import cycle, counting every import however it
is written (``tests/import_cycles.py`` finds them from the source with ``ast``): inside functions, in a
lazy ``__getattr__``, by ``importlib.import_module`` (a registry's loop over literal names), and the
package ``__init__`` that importing ``pkg.sub`` runs."""
import subprocess
import sys
import textwrap
from pathlib import Path

from import_cycles import HEAVY, PACKAGE, cycles, graph, heavy_libraries, imports, in_function_imports, modules


def _group(reason, *pairs):
    return {pair: reason for pair in pairs}


_RESTRUCTURED = ("a command or adapter module being restructured behind the scene interface: its imports "
                 "move to the top with that change")

#: Imports written inside functions, as (importer, imported) without the package prefix (a library by its
#: top-level name), each with the reason it stays there.  YADE, a heavy or optional library
#: (:data:`IN_FUNCTION_LIBRARIES`) or a module of the package that loads one when imported needs no
#: entry; nor does an ``importlib`` registry.  Every other in-function import fails the test below: move
#: it to the top of its module (where it makes no cycle), or add it here with its reason.
ALLOWED = {
    **_group("cli.py's module level loads no numpy: main() sets the one-thread default (OMP_NUM_THREADS, "
             "read once by OpenBLAS and the OpenMP runtime) before anything loads it",
             ("cli", "commands._args")),
    **_group("guarded by ImportError: a cluster's batch code may predate checkpoints",
             ("runs.slurm_states", "runs.runio")),
    **_group("cli.py sets the one-thread default of YADE's OpenMP runtime (engines.yade.use_default_threads) "
             "before anything loads it", ("cli", "engines.yade")),
    **_group(_RESTRUCTURED,
             ("commands.bench", "commands._args"), ("commands.bench", "errors"), ("commands.bench", "numpy"),
             ("commands.bench", "geometry.specimen"), ("commands.bench", "grains"), ("commands.bench", "params"),
             ("commands.bench", "runs.runio"),
             ("commands.brazilian", "commands._args"), ("commands.brazilian", "params"), ("commands.brazilian", "runs.runio"),
             ("commands.brazilian", "runs.batchrun"), ("commands.creep", "runs.batchrun"), ("commands.ucs", "runs.batchrun"),
             ("commands.creep", "params"), ("commands.creep", "argparse"), ("commands.creep", "sys"),
             ("commands.specimen", "params"),
             ("commands.ucs", "params"),
             ("engines.yade.batch", "runs.runio"),
             ("engines.yade.bench_timing", "engines.yade.platens"), ("engines.yade.bench_timing", "engines.yade.scene")),
}


def test_the_finder_sees_a_cycle():
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]


def _imports(tmp_path, name, source, known):
    path = tmp_path / ("__init__.py" if name in ("p", "p.cmds", "p.an") else name.rpartition(".")[2] + ".py")
    path.write_text(textwrap.dedent(source))
    return imports(name, path, dict.fromkeys(known, None))


KNOWN = ("p", "p.cli", "p.cmds", "p.cmds.run", "p.cmds.bench", "p.an", "p.an.study", "p.an.sub", "p.anim")


def test_a_registry_loop_over_literal_names_counts(tmp_path):
    """The old command registry: ``commands/__init__`` imports its commands by name in a loop."""
    src = """
        def register_all():
            import importlib
            for name in ("run", "bench"):
                importlib.import_module(f"{__name__}.{name}")
    """
    assert _imports(tmp_path, "p.cmds", src, KNOWN) == {"p.cmds.run", "p.cmds.bench"}


def test_an_import_module_of_an_unknown_name_counts_every_module_of_the_package(tmp_path):
    src = """
        import importlib
        def model(name):
            return importlib.import_module(f"{__name__}.{name}")
    """
    assert _imports(tmp_path, "p.cmds", src, KNOWN) == {"p.cmds.run", "p.cmds.bench"}


def test_a_lazy_getattr_by_table_counts(tmp_path):
    src = """
        from importlib import import_module
        LAZY = {"analyze": "study"}
        def __getattr__(name):
            return getattr(import_module(f"{__name__}.{LAZY[name]}"), name)
    """
    assert _imports(tmp_path, "p.an", src, KNOWN) == {"p.an.study"}


def test_importing_a_submodule_from_outside_counts_its_package(tmp_path):
    src = """
        def f():
            from .an.sub import x
    """
    assert _imports(tmp_path, "p.anim", src, KNOWN) == {"p.an.sub", "p.an"}
    # from inside the package it does not: the package is being imported already
    assert _imports(tmp_path, "p.an.study", "from .sub import x\n", KNOWN) == {"p.an.sub"}


def test_the_two_loops_a_plain_scan_missed_are_cycles(tmp_path):
    """The loops that the package had: cli -> commands (registry) -> bench -> cli (an in-function import),
    and analysis (lazy ``__getattr__``) -> study -> animation -> analysis (a submodule's package)."""
    g = {"p.cli": {"p.cmds"}, "p.cmds": {"p.cmds.bench"}, "p.cmds.bench": {"p.cli"},
         "p.an": {"p.an.study"}, "p.an.study": {"p.anim"}, "p.anim": {"p.an.sub", "p.an"}}
    assert cycles(g) == [["p.an", "p.an.study", "p.anim"], ["p.cli", "p.cmds", "p.cmds.bench"]]


def test_the_package_has_no_import_cycle():
    g = graph()
    assert "grainfrac_yade.grains.fem" in g and "grainfrac_yade.elastic" in g["grainfrac_yade.grains.fem"]
    # the registries are seen: the CLI's commands, the grain models, the laws, the analysis' lazy names
    assert "grainfrac_yade.commands.creep" in g["grainfrac_yade.commands"]
    assert "grainfrac_yade.grains.fem" in g["grainfrac_yade.grains"]
    assert "grainfrac_yade.law.area" in g["grainfrac_yade.law"]
    assert "grainfrac_yade.analysis.study" in g["grainfrac_yade.analysis"]
    assert cycles(g) == []


def _short(name):
    return name[len(PACKAGE) + 1:]


#: Libraries a function may import where it needs them: YADE (through ``load_yade``), and the heavy or
#: optional ones (``import_cycles.HEAVY``, and scipy's optimisers and geometry where only one branch needs them).
IN_FUNCTION_LIBRARIES = ("yade",) + HEAVY + ("scipy",)


def _library_allowed(target):
    return any(target == lib or target.startswith(lib + ".") for lib in IN_FUNCTION_LIBRARIES)


def test_in_function_imports_are_only_the_allowed_ones():
    """docs/maintainers.md: imports inside functions only for YADE and heavy or optional libraries (or a
    module of the package that loads one); anything else is at the top of its module or in ALLOWED."""
    known, memo = modules(), {}
    found = {}
    for i in in_function_imports(own_only=False):
        if i.target.startswith(PACKAGE + ".") or i.target == PACKAGE:
            if heavy_libraries(i.target, known, memo):
                continue
            found.setdefault((_short(i.module), _short(i.target)), i)
        elif not _library_allowed(i.target):
            found.setdefault((_short(i.module), i.target.split(".")[0]), i)
    stray = sorted(f"{i} (no reason in ALLOWED)" for pair, i in found.items() if pair not in ALLOWED)
    assert not stray, "\n".join(stray)
    stale = sorted(pair for pair in ALLOWED if pair not in found)
    assert not stale, f"ALLOWED entries no longer needed (remove them): {stale}"


def test_the_heavy_libraries_are_seen():
    known = modules()
    assert heavy_libraries(f"{PACKAGE}.analysis.study", known) >= {"matplotlib", "pandas"}
    assert heavy_libraries(f"{PACKAGE}.analysis", known) == set()   # its names load on first use


def test_the_cli_module_loads_no_numpy():
    """main() sets the one-thread default before numpy (OpenBLAS) or the OpenMP runtime is loaded."""
    code = "import sys, grainfrac_yade.cli; print(sorted(m for m in ('numpy', 'scipy', 'matplotlib') if m in sys.modules))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         cwd=Path(__file__).resolve().parent.parent).stdout
    assert out.strip() == "[]"


#: The engines' sub-packages under ``engines/`` (docs/maintainers.md, "The layers"), each with the other engines
#: it may import: the hybrid extends the static engine's scene.
ENGINE_PACKAGES = {"yade": (), "static": (), "hybrid": ("static",)}
#: What an engine may import of ``engines/`` itself: the scene interface, and the dynamic engines by name.
ENGINE_SHARED = ("engines", "engines._interface", "engines.dynamic")
#: Imports of an engine's sub-package from outside ``engines/``, each with its reason.
OUTSIDE_ENGINE_IMPORTS = {("cli", "engines.yade"): "the one-thread default, set before numpy loads (ALLOWED)"}


def _engine_of(short):
    return next((e for e in ENGINE_PACKAGES if short == f"engines.{e}" or short.startswith(f"engines.{e}.")), None)


def test_the_engines_stand_side_by_side():
    """The engines are one family: one sub-package each under ``engines/``, the registry naming a module of
    each; an engine imports the pure core (the kernel it shares with the tests' protocols among it), the interface
    and the dynamic engines by name, never the registry, the tests' protocols, the commands, the CLI or another
    engine (but the hybrid the static one); nothing outside ``engines/``
    imports an engine's sub-package but :data:`OUTSIDE_ENGINE_IMPORTS` (the commands go through the registry)."""
    from grainfrac_yade.engines.registry import ENGINE_MODULES
    assert {name: module.split(".")[2] for name, module in ENGINE_MODULES.items()} == {e: e for e in ENGINE_PACKAGES}
    g = graph()
    assert {_short(m).split(".")[1] for m in g if _engine_of(_short(m))} == set(ENGINE_PACKAGES)
    wrong = []
    for module, targets in g.items():
        mine = _engine_of(_short(module))
        for target in map(_short, targets):
            theirs = _engine_of(target)
            if mine:
                core = not (target.startswith(("engines", "commands", "protocols")) or target == "cli")
                ok = core or target in ENGINE_SHARED or theirs in (mine,) + ENGINE_PACKAGES[mine]
            else:
                ok = theirs is None or _short(module).startswith("engines.") or \
                    (_short(module), target) in OUTSIDE_ENGINE_IMPORTS
            if not ok:
                wrong.append(f"{_short(module)} imports {target}")
    assert not wrong, "\n".join(sorted(wrong))
