"""The package's modules import each other one way only: no import cycle, counting the imports written
inside functions too (``tests/import_cycles.py`` finds them from the source with ``ast``)."""
from import_cycles import cycles, graph


def test_the_finder_sees_a_cycle():
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]


def test_the_package_has_no_import_cycle():
    g = graph()
    assert "grainfrac_yade.grains.fem" in g and "grainfrac_yade.elastic" in g["grainfrac_yade.grains.fem"]
    assert cycles(g) == []
