"""docs/studies/README.md lists every study page: each ``docs/studies/*.md`` (but the index itself) has a row of its
table, and every row names a page that exists.  Pure file checks (no YADE); the pages are those present when the
test runs, so a page added later needs its row."""
import re
from pathlib import Path

STUDIES = Path(__file__).resolve().parent.parent / "docs" / "studies"
INDEX = STUDIES / "README.md"
#: A row of the index table: its first cell is a link to a page of this folder.
ROW = re.compile(r"^\|\s*\[[^\]]+\]\(([^)#\s/]+\.md)\)\s*\|", re.M)


def indexed_pages(text: str) -> list:
    """The pages the index table's rows link in their first cell, in order."""
    return ROW.findall(text)


def test_row_reader_reads_first_cells_only():
    text = ("| page | what |\n|---|---|\n| [a.md](a.md) | see [b.md](b.md) |\n"
            "text [c.md](c.md)\n| [../x.md](../x.md) | outside |\n")
    assert indexed_pages(text) == ["a.md"]


def test_every_study_page_has_a_row_in_the_index():
    listed = set(indexed_pages(INDEX.read_text()))
    pages = {p.name for p in STUDIES.glob("*.md")} - {INDEX.name}
    assert pages, "no study pages found"
    missing = sorted(pages - listed)
    assert not missing, f"docs/studies/README.md has no row for: {', '.join(missing)}"


def test_every_row_names_a_page_that_exists_once():
    rows = indexed_pages(INDEX.read_text())
    assert len(rows) == len(set(rows)), "a page has two rows"
    absent = [name for name in rows if not (STUDIES / name).is_file()]
    assert not absent, f"rows for pages that do not exist: {', '.join(absent)}"
