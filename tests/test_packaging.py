"""pyproject.toml: the console command points at the CLI's main, the version is the package's (no YADE)."""
import importlib
import inspect
import tomllib
from pathlib import Path

import grainfrac_yade

ROOT = Path(__file__).resolve().parent.parent


def _project():
    with open(ROOT / "pyproject.toml", "rb") as fh:
        return tomllib.load(fh)


def test_console_command_is_the_cli_main():
    data = _project()
    target = data["project"]["scripts"]["grainfrac-yade"]
    module, _, name = target.partition(":")
    main = getattr(importlib.import_module(module), name)
    # console scripts call main() with no argument and exit with its return value
    assert list(inspect.signature(main).parameters) == ["argv"]
    assert inspect.signature(main).parameters["argv"].default is None


def test_metadata():
    data = _project()
    project = data["project"]
    assert project["name"] == "grainfrac-yade"
    assert project["requires-python"] == ">=3.11"
    assert project["dependencies"] == []          # Debian packages, installed by setup.sh
    assert data["tool"]["setuptools"]["dynamic"]["version"]["attr"] == "grainfrac_yade.__version__"
    assert grainfrac_yade.__version__


def test_console_command_exits_with_the_cli_status(capsys):
    from grainfrac_yade.cli import main
    assert main(["ucs", "--set", "specimen.widht=1", "--out", "/nonexistent/never"]) == 2
    assert "did you mean specimen.width" in capsys.readouterr().err
