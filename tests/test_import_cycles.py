"""The package's modules import each other one way only: no import cycle, counting every import however it
is written (``tests/import_cycles.py`` finds them from the source with ``ast``): inside functions, in a
lazy ``__getattr__``, by ``importlib.import_module`` (a registry's loop over literal names), and the
package ``__init__`` that importing ``pkg.sub`` runs."""
import textwrap

from import_cycles import cycles, graph, import_list, imports


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
