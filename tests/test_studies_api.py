"""The study scripts use the package only through its declared API for scripts (:mod:`grainfrac_yade.api`): no
engine sub-module, no other module of the package, no name with a leading underscore (read from the imports by
``ast``; no YADE, no run)."""
import ast
import subprocess
import sys

import pytest

from conftest import ROOT
from grainfrac_yade import api

STUDIES = ROOT / "studies"


def violations(source: str, where: str = "<source>") -> list:
    """Each import of ``source`` that goes around the API: ``from grainfrac_yade.<not api> import ...``,
    ``import grainfrac_yade.<not api>``, a name the API does not export, or any private name (a leading
    underscore), the study scripts' imports of each other included."""
    out = []
    for node in ast.walk(ast.parse(source, where)):
        if isinstance(node, ast.Import):
            for alias in node.names:
                if alias.name.split(".")[0] == "grainfrac_yade" and alias.name != "grainfrac_yade.api":
                    out.append(f"{where}:{node.lineno}: import {alias.name}")
        elif isinstance(node, ast.ImportFrom):
            names = [alias.name for alias in node.names]
            module = node.module or ""
            private = [n for n in [*names, *module.split(".")] if n.startswith("_") and not n.endswith("__")]
            if private:
                out.append(f"{where}:{node.lineno}: private {private} from {'.' * node.level}{module}")
            if node.level or module.split(".")[0] != "grainfrac_yade":
                continue
            if module == "grainfrac_yade":
                if names != ["api"]:
                    out.append(f"{where}:{node.lineno}: from grainfrac_yade import {names}")
            elif module != "grainfrac_yade.api":
                out.append(f"{where}:{node.lineno}: from {module} import {names}")
            else:
                out += [f"{where}:{node.lineno}: {n} is not in grainfrac_yade.api" for n in names if n not in api.__all__]
    return out


@pytest.mark.parametrize("source, found", [
    ("from grainfrac_yade.engines.static.cascade import Path", 1),
    ("import grainfrac_yade.engines.yade.scene", 1),
    ("def f():\n    from grainfrac_yade.elastic import _triangle_b", 2),   # another module, and a private name
    ("from grainfrac_yade.api import _EXPORTS", 2),
    ("from grainfrac_yade.api import no_such_name", 1),
    ("from .static_engine_probe import _helper", 1),
    ("from grainfrac_yade import cli", 1),
    ("from grainfrac_yade.api import build_specimen, engine_for\nfrom grainfrac_yade import api\nimport numpy", 0),
])
def test_the_checker_finds_imports_around_the_api(source, found):
    assert len(violations(source)) == found, violations(source)


def test_study_scripts_import_only_the_api():
    files = sorted(STUDIES.glob("*.py"))
    assert len(files) > 10
    bad = [v for f in files for v in violations(f.read_text(), str(f.relative_to(ROOT)))]
    assert not bad, "\n".join(bad)


def test_every_exported_name_resolves_without_yade():
    """Each name of the API is where :data:`grainfrac_yade.api.EXPORTS` says, and loading them all loads no YADE
    (a fresh interpreter: this one may have loaded it for other tests)."""
    code = ("import sys; from grainfrac_yade import api; missing = [n for n in api.__all__ if getattr(api, n, None) "
            "is None]; print(missing, 'yade' in sys.modules)")
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT)
    assert res.returncode == 0, res.stderr
    assert res.stdout.split() == ["[]", "False"]
