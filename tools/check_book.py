#!/usr/bin/env python3
"""Check a built HTML book: every image exists, every internal link resolves, the key pages have content.

Usage: ``python tools/check_book.py [book/_build/html] [--results PAGE] [--screenshots DIR]``

For every ``*.html`` page under the build folder (theme templates in ``_static/`` etc. excluded):

- ``<img src>`` (and ``<source src>``): a relative/absolute-path URL must name an existing file;
  ``data:`` URIs are accepted, remote images (``http(s)://``) are errors (the book must read offline).
- ``<a href>``: links without scheme/host (internal) must name an existing file (a folder means its
  ``index.html``); a ``#fragment`` must be an ``id`` (or ``<a name>``) in the target page.
- ``<link href>`` / ``<script src>`` that are internal must name an existing file.
- every image file that a page shows is non-empty (images of notebook outputs included: myst-nb writes them to
  ``_images/`` and the page's ``<img>`` points there);
- the book must contain at least one executed-notebook page (``notebooks/*.html``) and no page may show a
  Python traceback cell output (a notebook that failed but was built anyway);
- the index page (``index.html``, or the page its ``<meta http-equiv="refresh">`` redirects to) and the
  results page (``--results PAGE``, default the first of ``notebooks/10_results.html``, ``results.html``,
  ``notebooks/*results*.html``) each contain at least one ``<table>`` and one ``<img>``.

``--screenshots DIR`` (optional, not used by CI): when a Chromium binary is found (``chromium``,
``chromium-browser``, ``google-chrome``), render the index and results pages headless to ``DIR/*.png`` and check
that each screenshot is a valid PNG that is not blank (more than a few distinct byte values); without Chromium
the step is skipped with a note.

Exit status 0 when all is fine, 1 with a list of problems otherwise, 2 on bad usage. Standard library only.
"""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
import zlib
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import unquote, urlsplit


class _PageParser(HTMLParser):
    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.ids: set[str] = set()
        self.refs: list[tuple[str, str, int]] = []  # (kind, url, line)
        self.tracebacks = 0
        self.tables = 0
        self.images = 0
        self.redirect: str | None = None

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        a = {k: (v or "") for k, v in attrs}
        line = self.getpos()[0]
        if "id" in a:
            self.ids.add(a["id"])
        if tag == "a" and "name" in a:
            self.ids.add(a["name"])
        if tag == "table":
            self.tables += 1
        if tag == "meta" and a.get("http-equiv", "").lower() == "refresh":
            m = re.search(r"url\s*=\s*([^;]+)", a.get("content", ""), re.I)
            if m:
                self.redirect = m.group(1).strip().strip("'\"")
        if tag in ("img", "source") and "src" in a:
            self.images += tag == "img"
            self.refs.append(("img", a["src"], line))
        elif tag == "a" and "href" in a:
            self.refs.append(("a", a["href"], line))
        elif tag == "link" and "href" in a:
            self.refs.append(("asset", a["href"], line))
        elif tag == "script" and "src" in a:
            self.refs.append(("asset", a["src"], line))
        classes = a.get("class", "").split()
        if "output" in classes and "traceback" in classes:
            self.tracebacks += 1


def _parse(path: Path) -> _PageParser:
    parser = _PageParser()
    parser.feed(path.read_text(encoding="utf-8", errors="replace"))
    parser.close()
    return parser


#: Build folders that hold theme templates and copies, not pages of the book.
_SKIP_DIRS = {"_static", "_sources", "_images", "_downloads"}


def _pages(root: Path) -> list[Path]:
    return sorted(p for p in root.rglob("*.html") if not _SKIP_DIRS & set(p.relative_to(root).parts[:-1]))


#: Candidates for the results page, in order of preference (``--results`` overrides).
RESULTS_CANDIDATES: tuple[str, ...] = ("notebooks/10_results.html", "results.html")


def index_page(root: Path) -> Path | None:
    """``index.html``, or the page its meta-refresh redirects to (Jupyter Book's index is a redirect)."""
    index = root / "index.html"
    if not index.is_file():
        return None
    target = _parse(index).redirect
    if target:
        path = (root / urlsplit(target).path).resolve()
        return path if path.is_file() else None
    return index


def results_page(root: Path, name: str | None = None) -> Path | None:
    """The results page: ``name`` if given, else the first of :data:`RESULTS_CANDIDATES` or
    ``notebooks/*results*.html`` that exists."""
    if name:
        return root / name if (root / name).is_file() else None
    for cand in RESULTS_CANDIDATES:
        if (root / cand).is_file():
            return root / cand
    found = sorted((root / "notebooks").glob("*results*.html")) if (root / "notebooks").is_dir() else []
    return found[0] if found else None


def check_content(root: Path, results: str | None = None) -> list[str]:
    """The index and results pages must each show at least one table and one image."""
    root = root.resolve()
    problems = []
    pages = {"index page": index_page(root), "results page": results_page(root, results)}
    for what, page in pages.items():
        if page is None:
            problems.append(f"{root}: no {what}" + (f" ({results})" if what == "results page" and results else
                                                   " (index.html missing or its redirect target missing)"
                                                   if what == "index page" else
                                                   f" (none of {', '.join(RESULTS_CANDIDATES)})"))
            continue
        info = _parse(page)
        rel = page.relative_to(root)
        if info.tables < 1:
            problems.append(f"{rel} ({what}): no <table>")
        if info.images < 1:
            problems.append(f"{rel} ({what}): no <img>")
    return problems


def _chromium() -> str | None:
    for name in ("chromium", "chromium-browser", "google-chrome", "google-chrome-stable"):
        path = shutil.which(name)
        if path:
            return path
    return None


def _png_distinct_bytes(path: Path) -> int:
    """Number of distinct byte values in a PNG's decompressed image data (a blank page has very few)."""
    data = path.read_bytes()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError("not a PNG file")
    pos, idat = 8, b""
    while pos + 8 <= len(data):
        length = int.from_bytes(data[pos:pos + 4], "big")
        ctype = data[pos + 4:pos + 8]
        if ctype == b"IDAT":
            idat += data[pos + 8:pos + 8 + length]
        pos += 12 + length
    return len(set(zlib.decompress(idat)))


def screenshots(root: Path, out_dir: Path, results: str | None = None, width: int = 1280,
                height: int = 2400) -> tuple[list[str], list[str]]:
    """Render the index and results pages with headless Chromium; returns (problems, notes)."""
    exe = _chromium()
    if exe is None:
        return [], ["screenshots skipped: no chromium binary found"]
    out_dir.mkdir(parents=True, exist_ok=True)
    problems, notes = [], []
    for name, page in (("index", index_page(root.resolve())), ("results", results_page(root.resolve(), results))):
        if page is None:
            continue
        png = out_dir / f"{name}.png"
        png.unlink(missing_ok=True)
        cmd = [exe, "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
               f"--window-size={width},{height}", f"--screenshot={png}", page.as_uri()]
        try:
            subprocess.run(cmd, capture_output=True, timeout=120, check=False)
        except (OSError, subprocess.SubprocessError) as exc:
            problems.append(f"{name}: chromium failed: {exc}")
            continue
        if not png.is_file():
            problems.append(f"{name}: chromium wrote no screenshot ({' '.join(cmd)})")
            continue
        try:
            distinct = _png_distinct_bytes(png)
        except (ValueError, zlib.error) as exc:
            problems.append(f"{png}: unreadable screenshot ({exc})")
            continue
        if distinct < 16:
            problems.append(f"{png}: screenshot looks blank ({distinct} distinct byte values)")
        notes.append(f"screenshot {png} ({distinct} distinct byte values)")
    return problems, notes


def check(root: Path) -> list[str]:
    """Return the problems found in the HTML build under ``root`` (empty list: all fine)."""
    root = root.resolve()
    pages = _pages(root)
    if not pages:
        return [f"{root}: no HTML pages"]
    parsed = {p: _parse(p) for p in pages}
    problems: list[str] = []
    if not (root / "index.html").is_file():
        problems.append(f"{root}: no index.html")
    if not any(p.parent.name == "notebooks" for p in pages):
        problems.append(f"{root}: no executed notebook pages (notebooks/*.html)")

    def ids_of(target: Path) -> set[str] | None:
        if target not in parsed:
            if target.suffix != ".html" or not target.is_file():
                return None
            parsed[target] = _parse(target)
        return parsed[target].ids

    repo = str(Path(__file__).resolve().parents[1])        # this checkout: its path is the machine's, never a page's
    for page, info in list(parsed.items()):
        rel = page.relative_to(root)
        if repo in page.read_text(encoding="utf-8", errors="replace"):
            problems.append(f"{rel}: shows the machine path of the repository (a page names files relative to it)")
        if info.tracebacks:
            problems.append(f"{rel}: {info.tracebacks} traceback output(s) from a failed cell")
        for kind, url, line in info.refs:
            where = f"{rel}:{line}"
            parts = urlsplit(url.strip())
            if parts.scheme == "data":
                continue
            if parts.scheme or parts.netloc:
                if kind == "img":
                    problems.append(f"{where}: remote image {url} (the book must work offline)")
                continue  # external link or CDN asset: not checked offline
            if not parts.path:
                # same-page fragment ("#x"); "#" alone is a no-op link
                if parts.fragment and parts.fragment not in info.ids and kind == "a":
                    problems.append(f"{where}: no anchor #{parts.fragment} in this page")
                continue
            path_part = unquote(parts.path)
            target = (root / path_part.lstrip("/")) if path_part.startswith("/") else (page.parent / path_part)
            target = target.resolve()
            if target.is_dir():
                target = target / "index.html"
            try:
                target.relative_to(root)
            except ValueError:
                problems.append(f"{where}: {kind} {url} points outside the book")
                continue
            if not target.is_file():
                problems.append(f"{where}: {kind} {url} -> missing {target.relative_to(root)}")
                continue
            if kind == "img" and target.stat().st_size == 0:
                problems.append(f"{where}: image {url} -> empty file {target.relative_to(root)}")
            if kind == "a" and parts.fragment:
                ids = ids_of(target)
                if ids is not None and unquote(parts.fragment) not in ids:
                    problems.append(f"{where}: no anchor #{parts.fragment} in {target.relative_to(root)}")
    return problems


def main(argv: list[str]) -> int:
    import argparse

    ap = argparse.ArgumentParser(prog="check_book.py", description=__doc__.split("\n\n")[0])
    ap.add_argument("root", nargs="?", default=None, help="the built HTML folder (default book/_build/html)")
    ap.add_argument("--results", default=None, help="results page, relative to the root")
    ap.add_argument("--screenshots", default=None, metavar="DIR", help="headless Chromium screenshots to DIR")
    try:
        args = ap.parse_args(argv)
    except SystemExit as exc:
        return 0 if exc.code == 0 else 2
    root = Path(args.root) if args.root else Path(__file__).resolve().parents[1] / "book" / "_build" / "html"
    if not root.is_dir():
        print(f"error: {root} is not a folder (build the book first: make book)", file=sys.stderr)
        return 1
    problems = check(root) + check_content(root, args.results)
    notes: list[str] = []
    if args.screenshots:
        shot_problems, notes = screenshots(root, Path(args.screenshots), args.results)
        problems += shot_problems
    n_pages = len(_pages(root))
    for note in notes:
        print(f"check_book: {note}")
    if problems:
        print(f"check_book: {len(problems)} problem(s) in {root}:", file=sys.stderr)
        for p in problems:
            print(f"  {p}", file=sys.stderr)
        return 1
    print(f"check_book: {n_pages} pages OK ({root}); index and results pages have tables and images")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
