"""The generated references in docs/reference/ equal what their generators write today (no YADE).

When a test here fails, the schema, a shipped parameter file or the CLI changed: regenerate with
    python3 -m grainfrac_yade.paramdoc > docs/reference/parameters.md
    python3 -m grainfrac_yade.commanddoc > docs/reference/commands.md
"""
import dataclasses
from pathlib import Path

from grainfrac_yade import params
from grainfrac_yade.commanddoc import command_reference
from grainfrac_yade.paramdoc import parameter_reference, shipped_comments

REFERENCE = Path(__file__).resolve().parent.parent / "docs" / "reference"


def test_parameter_reference_is_current():
    committed = (REFERENCE / "parameters.md").read_text()
    assert committed == parameter_reference(), \
        "docs/reference/parameters.md is stale: python3 -m grainfrac_yade.paramdoc > docs/reference/parameters.md"


def test_command_reference_is_current():
    committed = (REFERENCE / "commands.md").read_text()
    assert committed == command_reference(), \
        "docs/reference/commands.md is stale: python3 -m grainfrac_yade.commanddoc > docs/reference/commands.md"


def test_parameter_reference_names_every_schema_key():
    text = parameter_reference()
    for section, cls in params.SECTION_CLASSES.items():
        assert f"## `[{section}]`" in text
        for f in dataclasses.fields(cls):
            assert f"| `{f.name}` | " in text, f"{section}.{f.name} missing"
    for cls in (params.GrainParams, params.ContactParams):
        for f in dataclasses.fields(cls):
            assert f"| `{f.name}` | " in text


def test_comment_reader_ignores_hash_inside_strings(tmp_path):
    f = tmp_path / "x.toml"
    f.write_text('[a]\nname = "x#y"   # m, the comment\n[b."p/q"]\nk = 1\n')
    assert shipped_comments([f]) == {"a.name": ("params/x.toml", "m, the comment"), "b.p/q.k": ("params/x.toml", "")}


def test_command_reference_lists_every_command():
    from grainfrac_yade.cli import build_parser
    from grainfrac_yade.commanddoc import _subcommands
    text = command_reference()
    names = [name for name, _, _ in _subcommands(build_parser())]
    assert "creep" in names and "specimen" in names
    for name in names:
        assert f"\n## {name}\n" in text


def test_generated_references_name_no_path_of_this_checkout():
    """The pages are compared with what a fresh clone generates, wherever it is: no absolute path."""
    root = str(Path(__file__).resolve().parents[1])
    for page in ("parameters.md", "commands.md"):
        assert root not in (Path(__file__).resolve().parents[1] / "docs" / "reference" / page).read_text(), page
