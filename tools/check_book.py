#!/usr/bin/env python3
"""Check a built HTML book: every image exists, every internal link resolves.

Usage: ``python tools/check_book.py [book/_build/html]``

For every ``*.html`` page under the build folder (theme templates in ``_static/`` etc. excluded):

- ``<img src>`` (and ``<source src>``): a relative/absolute-path URL must name an existing file;
  ``data:`` URIs are accepted, remote images (``http(s)://``) are errors (the book must read offline).
- ``<a href>``: links without scheme/host (internal) must name an existing file (a folder means its
  ``index.html``); a ``#fragment`` must be an ``id`` (or ``<a name>``) in the target page.
- ``<link href>`` / ``<script src>`` that are internal must name an existing file.
- the book must contain at least one executed-notebook page (``notebooks/*.html``) and no page may show a
  Python traceback cell output (a notebook that failed but was built anyway).

Exit status 0 when all is fine, 1 with a list of problems otherwise, 2 on bad usage. Standard library only.
"""

from __future__ import annotations

import sys
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import unquote, urlsplit


class _PageParser(HTMLParser):
    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.ids: set[str] = set()
        self.refs: list[tuple[str, str, int]] = []  # (kind, url, line)
        self.tracebacks = 0

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        a = {k: (v or "") for k, v in attrs}
        line = self.getpos()[0]
        if "id" in a:
            self.ids.add(a["id"])
        if tag == "a" and "name" in a:
            self.ids.add(a["name"])
        if tag in ("img", "source") and "src" in a:
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

    for page, info in list(parsed.items()):
        rel = page.relative_to(root)
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
            if kind == "a" and parts.fragment:
                ids = ids_of(target)
                if ids is not None and unquote(parts.fragment) not in ids:
                    problems.append(f"{where}: no anchor #{parts.fragment} in {target.relative_to(root)}")
    return problems


def main(argv: list[str]) -> int:
    if len(argv) > 1 or (argv and argv[0] in ("-h", "--help")):
        print(__doc__)
        return 2
    root = Path(argv[0]) if argv else Path(__file__).resolve().parents[1] / "book" / "_build" / "html"
    if not root.is_dir():
        print(f"error: {root} is not a folder (build the book first: make book)", file=sys.stderr)
        return 1
    problems = check(root)
    n_pages = len(_pages(root))
    if problems:
        print(f"check_book: {len(problems)} problem(s) in {root}:", file=sys.stderr)
        for p in problems:
            print(f"  {p}", file=sys.stderr)
        return 1
    print(f"check_book: {n_pages} pages OK ({root})")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
