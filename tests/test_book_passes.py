"""The book in two passes (book/_ext/code_page.py, ``make``'s draft): the same HTML as a build of every page.

A small Sphinx project with what the book's code pages use (autosummary over a package, autodoc, viewcode) and
the book's extension: a package with a module of constants only (viewcode tags none of its objects) and a module
of functions (index entries in the search index), a page that the draft shows as a placeholder with a missing
figure. Built once with every page, and again as ``make reproduce`` builds it: the draft, then the ``pages`` pass.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from bgfn.config import PROJECT_ROOT

EXT = PROJECT_ROOT / "book" / "_ext"

CONF = """
import sys
sys.path[:0] = [{ext!r}, {src!r}]
extensions = ["sphinx.ext.autodoc", "sphinx.ext.autosummary", "sphinx.ext.viewcode", "code_page"]
autosummary_generate = True
autodoc_default_options = {{"members": True}}
viewcode_follow_imported_members = False
html_theme = "basic"
"""
PACKAGE = {
    "demo/__init__.py": '"""A package."""\n',
    "demo/constants.py": '"""Constants only."""\n\n#: The speed of light, m/s.\nC = 299_792_458.0\n',
    "demo/functions.py": '"""Functions."""\n\n\ndef twice(x):\n    """Twice ``x``."""\n    return 2 * x\n',
}
#: more pages than Sphinx reads one at a time (5), so that the pages pass reads in parallel, as the book's does
OTHER_PAGES = {f"chapter{i}": f"Chapter {i}\n=========\n\nText {i}.\n" for i in range(1, 5)}
INDEX = "Demo\n====\n\n.. toctree::\n\n   page\n   code\n" + "".join(f"   {p}\n" for p in OTHER_PAGES)
CODE = "Code\n====\n\n.. autosummary::\n   :toctree: api\n   :recursive:\n\n   demo\n"
PAGE = "Results\n=======\n\nThe results of the run: {body}\n"
PLACEHOLDER = PAGE.format(body="not yet.\n\n.. figure:: figures/not_drawn_yet.png\n")
FINAL = PAGE.format(body="twice 2 is 4.\n\n.. index:: single: results; twice\n")


def _project(root: Path) -> tuple[Path, Path]:
    src, pkg = root / "src", root / "pkg"
    for name, text in PACKAGE.items():
        (pkg / name).parent.mkdir(parents=True, exist_ok=True)
        (pkg / name).write_text(text)
    src.mkdir()
    (src / "conf.py").write_text(CONF.format(ext=str(EXT), src=str(pkg)))
    (src / "index.rst").write_text(INDEX)
    (src / "code.rst").write_text(CODE)
    for name, text in OTHER_PAGES.items():
        (src / f"{name}.rst").write_text(text)
    return src, pkg


def _build(src: Path, out: Path, book_pass: str | None, *flags: str) -> subprocess.CompletedProcess:
    env = {k: v for k, v in os.environ.items() if k != "BGFN_BOOK_PASS"}
    if book_pass:
        env["BGFN_BOOK_PASS"] = book_pass
    # two processes, as the book is built (a module of constants keeps its source page only when Sphinx reads the
    # pages in parallel)
    return subprocess.run([sys.executable, "-m", "sphinx", "-b", "html", "-W", "-j", "2", *flags, str(src), str(out)],
                          capture_output=True, text=True, env=env, timeout=300)


def _files(out: Path) -> dict[str, bytes]:
    return {str(p.relative_to(out)): p.read_bytes() for p in sorted(out.rglob("*"))
            if p.is_file() and ".doctrees" not in p.parts}


def test_the_draft_and_the_pages_pass_make_the_book_a_build_of_every_page_makes(tmp_path):
    src, _ = _project(tmp_path / "one")
    (src / "page.rst").write_text(FINAL)
    one = _build(src, tmp_path / "one" / "out", None, "-E")
    assert one.returncode == 0, one.stderr

    src, _ = _project(tmp_path / "two")
    out = tmp_path / "two" / "out"
    (src / "page.rst").write_text(PLACEHOLDER)
    # the placeholder's missing figure fails a build with -W ...
    plain = _build(src, tmp_path / "two" / "plain", None, "-E")
    assert plain.returncode != 0 and "not_drawn_yet.png" in plain.stderr
    # ... but not the draft, which leaves out the warnings of every page but the code pages
    draft = _build(src, out, "draft", "-E")
    assert draft.returncode == 0, draft.stderr
    assert "[autosummary] generating autosummary" in draft.stdout
    (src / "page.rst").write_text(FINAL)
    pages = _build(src, out, "pages")
    assert pages.returncode == 0, pages.stderr
    assert "[autosummary] generating autosummary" not in pages.stdout      # the draft's stubs kept: no module imported
    # read in parallel, as the book's pages pass is (Sphinx names each process's first and last page)
    assert any(" .. " in line for line in pages.stdout.splitlines() if line.startswith("reading sources"))

    first, second = _files(tmp_path / "one" / "out"), _files(out)
    assert sorted(first) == sorted(second)
    differ = [name for name in first if first[name] != second[name]]
    assert not differ, f"the two passes' book differs from one build's in {differ}"
    # what the Sphinx habits the extension mends would have lost: a module of constants in the source pages' index,
    # the code pages' index entries in the search index
    assert b"demo/constants.html" in first["_modules/index.html"]
    assert b"twice() (in module demo.functions)" in first["searchindex.js"]


def test_a_warning_in_a_code_page_fails_the_draft(tmp_path):
    src, pkg = _project(tmp_path)
    (src / "page.rst").write_text(PLACEHOLDER)
    (pkg / "demo" / "functions.py").write_text('"""Functions."""\n\n\ndef twice(x):\n    """Twice *x."""\n')
    draft = _build(src, tmp_path / "out", "draft", "-E")
    assert draft.returncode != 0 and "functions" in draft.stderr


def test_a_pass_the_extension_does_not_know_is_refused(tmp_path):
    src, _ = _project(tmp_path)
    (src / "page.rst").write_text(FINAL)
    run = _build(src, tmp_path / "out", "drafts", "-E")
    assert run.returncode != 0 and "BGFN_BOOK_PASS='drafts'" in run.stderr


def test_a_page_retitled_after_the_draft_fails_the_pages_pass(tmp_path):
    # the code pages' navigation, which the pages pass does not write again, would show the old title
    src, _ = _project(tmp_path)
    (src / "page.rst").write_text(PLACEHOLDER.replace("Results\n=======", "Draft\n====="))
    assert _build(src, tmp_path / "out", "draft", "-E").returncode == 0
    (src / "page.rst").write_text(FINAL)
    pages = _build(src, tmp_path / "out", "pages")
    assert pages.returncode != 0 and "title changed since the draft" in pages.stderr
