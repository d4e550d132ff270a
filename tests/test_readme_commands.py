"""Every command line of README.md names what exists: a command the CLI knows, with flags its parser accepts
and parameters that validate, files and folders of the repository, and study folders an earlier line writes.

Pure checks (no YADE, nothing run): the README lines themselves are run from a fresh clone by hand (they take
minutes); this keeps a renamed flag, file or study from breaking them unnoticed.  Command lines are the
indented code lines and the inline code that calls ``yade-batch``; ``&&`` separates the commands of one line.
"""
import re
import shlex
from pathlib import Path

import pytest

from grainfrac_yade.cli import build_parser
from grainfrac_yade.commands._args import load_params_from_args
from grainfrac_yade.commands.batch import check_table

ROOT = Path(__file__).resolve().parent.parent
README = ROOT / "README.md"
PROGRAM = ["python3", "-m", "grainfrac_yade"]


def readme_commands() -> list:
    """The README's commands in reading order, each as a list of words."""
    text = README.read_text()
    lines = [line.strip() for line in text.splitlines() if line.startswith("    ") and line.strip()]
    lines += yade_batch_code(text)
    return [shlex.split(part) for line in lines for part in line.split("&&")]


def yade_batch_code(text: str) -> list:
    """The inline code spans of ``text`` that call yade-batch, on one line each."""
    return [" ".join(code.split()) for code in re.findall(r"`([^`]+)`", text) if "yade-batch " in code]


COMMANDS = readme_commands()


def _studies_of(table: Path, test=None) -> set:
    """The study folders (results/<study>) a batch table writes; every row checked as ``batch`` checks it."""
    _, rows = check_table(table, test)
    return {f"results/{controls['study']}" for _, controls in rows.values()}


def test_the_readme_has_the_tour_commands():
    programs = [c[:3] for c in COMMANDS]
    assert programs.count(PROGRAM) >= 7 and ["bash", "setup.sh"] in [c[:2] for c in COMMANDS]
    assert any(c[0] == "yade-batch" for c in COMMANDS)


@pytest.mark.parametrize("words", [c for c in COMMANDS if c[:3] == PROGRAM], ids=" ".join)
def test_each_grainfrac_line_parses_and_its_parameters_validate(words):
    args = build_parser().parse_args(words[3:])   # a refused flag exits (SystemExit 2)
    if getattr(args, "with_params", False):
        load_params_from_args(args)               # --set keys, geometry, cell count
    for value in [getattr(args, "table", None), *getattr(args, "params", [])]:
        if value:
            assert (ROOT / value).is_file(), value


def test_every_file_a_readme_line_names_exists():
    for words in COMMANDS:
        for word in words:
            if re.match(r"^(params|yade_scripts|docs|tests)/", word) or word.endswith((".sh", ".table", ".toml")):
                assert (ROOT / word).exists(), (word, " ".join(words))


def test_a_study_folder_is_written_by_an_earlier_line_before_it_is_analysed():
    written = set()
    for words in COMMANDS:
        if words[:4] == PROGRAM + ["batch"]:
            written |= _studies_of(ROOT / words[4], build_parser().parse_args(words[3:]).test)
        if words[:4] == PROGRAM + ["analyze"]:
            folders = [w for w in words[4:] if not w.startswith("-")]
            assert folders and all(f.rstrip("/") in written for f in folders), (words, written)


def test_yade_batch_lines_make_their_log_folder_first():
    text = README.read_text()
    for code in yade_batch_code(text) + [l for l in text.splitlines() if l.startswith("    ") and "yade-batch " in l]:
        log = re.search(r"--log '([^']+)/%\.log'", code)
        assert log and f"mkdir -p {log.group(1)}" in code, code


def test_the_test_command_selects_a_registered_marker():
    line = next(c for c in COMMANDS if "pytest" in c)
    marker = line[line.index("-m", line.index("pytest")) + 1].replace("not ", "")
    assert re.search(rf"^\s+{marker}:", (ROOT / "pytest.ini").read_text(), re.M), marker
