"""README.md, CHANGELOG.md and docs/: every relative link and image resolves, anchors included; the README stays short.

Pure file checks (no YADE). Links are read outside code blocks and inline code; web links are not
fetched. An anchor (``file.md#heading``) must match a heading of the target as GitHub writes its ids
(lower case, punctuation dropped, spaces as hyphens, repeats numbered -1, -2, ...).
"""
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
#: The README's length limit: what a newcomer reads in five minutes; everything longer belongs in docs/.
README_MAX_LINES = 200
#: Pages other branches add (the ParaView how-to and the resume how-to); until they are merged a link to
#: them may be dangling. Empty this once they exist.
PENDING_PAGES: set = set()

LINK = re.compile(r"!?\[(?:[^\]\[]|\[[^\]]*\])*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")
HEADING = re.compile(r"^(#{1,6})\s+(.*?)\s*#*\s*$")


def _pages():
    return [ROOT / "README.md", ROOT / "CHANGELOG.md"] + sorted((ROOT / "docs").rglob("*.md"))


def _prose(text: str) -> str:
    """``text`` without fenced code blocks, indented code blocks and inline code."""
    text = re.sub(r"^```.*?^```", "", text, flags=re.S | re.M)
    lines = [line for line in text.splitlines() if not line.startswith("    ")]
    return re.sub(r"`[^`\n]*`", "", "\n".join(lines))


def slug(heading: str) -> str:
    """GitHub's id of a heading."""
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", heading)   # a link in a heading: its text
    text = text.replace("`", "").strip().lower()
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def anchors(page: Path) -> set:
    out, seen = set(), {}
    for line in _strip_fences(page.read_text()).splitlines():
        m = HEADING.match(line)
        if m:
            s = slug(m.group(2))
            n = seen.get(s, 0)
            out.add(s if n == 0 else f"{s}-{n}")
            seen[s] = n + 1
    return out


def _strip_fences(text: str) -> str:
    return re.sub(r"^```.*?^```", "", text, flags=re.S | re.M)


def links(page: Path):
    for m in LINK.finditer(_prose(page.read_text())):
        target = m.group(1)
        if re.match(r"^[a-z][a-z0-9+.-]*:", target):     # http:, https:, mailto:
            continue
        yield target


def test_slug_follows_github():
    assert slug("Confined (biaxial) compression and creep") == "confined-biaxial-compression-and-creep"
    assert slug("`[specimen]`") == "specimen"
    assert slug("Measured: the collapse criterion") == "measured-the-collapse-criterion"
    assert slug("Clusters (SLURM)") == "clusters-slurm"


def test_link_reader_finds_links_and_images_outside_code():
    page = ROOT / "README.md"
    text = "see [a](x.md#b) and ![f](fig.png)\n`[no](skip.md)`\n    [no](indented.md)\n"
    assert [m.group(1) for m in LINK.finditer(_prose(text))] == ["x.md#b", "fig.png"]
    assert page.exists()


@pytest.mark.parametrize("page", _pages(), ids=lambda p: str(p.relative_to(ROOT)))
def test_every_relative_link_resolves(page):
    problems = []
    for target in links(page):
        path, _, anchor = target.partition("#")
        dest = (page.parent / path).resolve() if path else page
        rel = dest.relative_to(ROOT).as_posix() if dest.is_relative_to(ROOT) else None
        if rel is None:
            problems.append(f"{target}: outside the repository")
        elif not dest.exists():
            if rel not in PENDING_PAGES:
                problems.append(f"{target}: no such file")
        elif anchor and dest.suffix == ".md" and anchor not in anchors(dest):
            problems.append(f"{target}: no heading #{anchor} in {rel}")
    assert not problems, f"{page.relative_to(ROOT)}: " + "; ".join(problems)


@pytest.mark.parametrize("page", _pages(), ids=lambda p: str(p.relative_to(ROOT)))
def test_no_paths_outside_the_repository_and_no_issue_numbers_in_headings(page):
    text = page.read_text()
    assert "../shared" not in text and "shared/reference" not in text and "shared/seeds" not in text
    for line in _strip_fences(text).splitlines():
        m = HEADING.match(line)
        if m:
            assert not re.search(r"\bissue\s*#?\d", m.group(2), re.I), line


def test_readme_is_short():
    n = len((ROOT / "README.md").read_text().splitlines())
    assert n <= README_MAX_LINES, f"README.md has {n} lines; move detail into docs/"


def test_readme_keeps_the_ci_test_command():
    """.ci/run calls the README's test command verbatim."""
    command = 'bash setup.sh && /usr/bin/python3 -m pytest -q -m "not slow" -n logical --dist loadfile'
    assert command in (ROOT / "README.md").read_text()
    assert command in (ROOT / ".ci" / "run").read_text()
