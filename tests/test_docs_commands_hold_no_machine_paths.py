"""The commands and paths that README.md and docs/*.md show run from a clone: none
names an absolute path of the machine they were measured on.

docs/benchmarks.md printed ``PYTHONPATH=. /work/venv-bench/bin/python -m
benchmarks.envelope_vs_basilisk --day``, a venv of the machine that measured it; a
reader's clone has none.  Every code block and every inline code span of the pages is
read for a path from the root (``/work/...``, ``/home/...``, ``/usr/bin/...``); links
(``https://...``) are not paths, and a page that means an absolute path on purpose
says so below.
"""

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
_BLOCK = re.compile(r"^```\w*\n(.*?)^```", re.S | re.M)
_INLINE = re.compile(r"`([^`\n]+)`")
# A path from the root: "/" then at least one "name/" (not a URL's "//", not a ratio
# such as "rad/s", not "~/...").
_ABSOLUTE = re.compile(r"(?<![\w.:/~-])/(?:[\w.+-]+/)+[\w.+-]*")
# Absolute paths a page names on purpose: the file a hostile user hands over.
_MEANT = {"/dev/zero"}


def _paths(text: str) -> list[str]:
    spans = [m.group(1) for m in _BLOCK.finditer(text)]
    spans += [m.group(1) for m in _INLINE.finditer(_BLOCK.sub("", text))]
    return [p for span in spans for p in _ABSOLUTE.findall(span) if p not in _MEANT]


def test_the_pattern_finds_what_it_should():
    assert _paths("```sh\nPYTHONPATH=. /work/venv-bench/bin/python -m x\n```\n") == [
        "/work/venv-bench/bin/python"
    ]
    assert _paths("run `/usr/bin/time python` here") == ["/usr/bin/time"]
    assert _paths("`https://example.org/a/b`, `rad/s`, `~/x/y`, `docs/a.md`") == []


def test_no_page_names_a_path_of_the_machine():
    found = {
        str(page.relative_to(ROOT)): paths
        for page in PAGES
        if (paths := _paths(page.read_text(encoding="utf-8")))
    }
    assert not found, found
