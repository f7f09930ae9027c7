"""Sphinx extension of the book: what its code page (autosummary over ``bgfn``) needs beyond Sphinx's own.

- **Every module gets its page.** Autosummary resolves ``package.name`` as an attribute of the package before it
  tries the submodule, so a package that re-exports a function under its module's name (``bgfn.report``'s
  ``provenance``) would hide that module's page; here a name that is a submodule resolves to the module.
- **Docstrings as written.** The docstrings are written for a reader of the source (numpydoc, read by napoleon).
  Two habits of that source are not reStructuredText, and the book treats warnings as errors, so they are made
  literal here rather than in the modules: ``|x|`` (an absolute value, which reStructuredText reads as a
  substitution) and a simple table whose text runs into the margin between two columns (shown as the
  preformatted text it is in the source). And a ``#:`` comment whose first line holds a colon ("what: why")
  stays a sentence: napoleon would read the words before the colon as the attribute's type.
- **Two passes** (``BGFN_BOOK_PASS``, set by ``make``): the code pages depend on the code alone, so ``make
  reproduce`` builds the book once beside the last notebooks (``draft``: every other page a placeholder, whose
  warnings are left out) and then only reads those other pages again (``pages``), with the code pages, their
  autosummary stubs and their source pages kept from the draft.
"""

from __future__ import annotations

import importlib
import importlib.util
import logging
import os
import pickle
import re

from docutils import nodes
from sphinx.util import logging as sphinx_logging

#: The environment variable naming the book's pass (tools/build_book.py): ``draft`` or ``pages``; unset: one pass.
PASS_ENV = "BGFN_BOOK_PASS"
_LOGGER = sphinx_logging.getLogger(__name__)
#: The folder of the code pages (autosummary's stubs, book/api/), as Sphinx names their documents.
CODE_PAGES = "api/"

#: ``|x|`` not preceded by a backslash or a word character: an absolute value, not a substitution.
_BARS = re.compile(r"(?<![\\\w|`])\|([^|\s`][^|`\n]*?)\|(?![\w|`])")
#: The border of a simple table: runs of ``=`` separated by blanks.
_BORDER = re.compile(r"^(\s*)=+(?:\s+=+)+\s*$")


def _escape_bars(line: str) -> str:
    if re.match(r"\s*(\|(\s|$)|\+[-=])", line):        # a line block or a grid table: its bars are markup
        return line
    return _BARS.sub(r"\\|\1\\|", line)


def _margins(border: str) -> list[range]:
    """The blank runs between the columns of a simple table's border, the last column's end excluded."""
    return [range(m.start(), m.end()) for m in re.finditer(r"(?<==)\s+(?==)", border.rstrip())]


def _literal_tables(lines: list[str]) -> list[str]:
    """Each simple table with text in a column margin, as a literal block (the source's layout, verbatim)."""
    out, i = [], 0
    while i < len(lines):
        m = _BORDER.match(lines[i])
        if not m:
            out.append(lines[i])
            i += 1
            continue
        # the table ends at a border followed by a blank line (or the docstring's end)
        end = next((j for j in range(i + 1, len(lines)) if _BORDER.match(lines[j])
                    and (j + 1 == len(lines) or not lines[j + 1].strip())), i)
        rows = [line for line in lines[i:end + 1] if not _BORDER.match(line)]
        margins = _margins(lines[i])
        spills = any(k < len(row) and row[k] != " " for row in rows for gap in margins for k in gap)
        if spills:
            indent = m.group(1)
            out += [f"{indent}::", ""] + [f"{indent}   {line}" for line in lines[i:end + 1]] + [""]
        else:
            out += lines[i:end + 1]
        i = end + 1
    return out


def _no_inline_type(app, what, name, obj, options, lines: list[str]) -> None:
    # napoleon takes "<type>: <text>" on an attribute's first line as its type; after a blank line it does not
    if what in ("data", "attribute", "property") and lines:
        lines.insert(0, "")


def _plain(app, what, name, obj, options, lines: list[str]) -> None:
    lines[:] = _literal_tables([_escape_bars(line) for line in lines])


def _submodule(name: str) -> bool:
    parent, _, _ = name.rpartition(".")
    try:
        return bool(parent) and importlib.util.find_spec(name) is not None
    except (ImportError, ValueError):                   # the parent is not a package, or not importable
        return False


def prefer_modules() -> None:
    """Make autosummary (its directive and its page generator) resolve a submodule's name to the module."""
    import sphinx.ext.autosummary as autosummary
    import sphinx.ext.autosummary.generate as generate

    original = autosummary.import_by_name
    if getattr(original, "prefers_modules", False):
        return

    def import_by_name(name, prefixes=(None,)):
        for prefix in prefixes:
            full = f"{prefix}.{name}" if prefix else name
            if _submodule(full):
                return full, importlib.import_module(full), None, full
        return original(name, prefixes)

    import_by_name.prefers_modules = True
    autosummary.import_by_name = generate.import_by_name = import_by_name


class _PlaceholderWarnings(logging.Filter):
    """Drops a warning located in a page other than a code page: in the draft those pages are placeholders (the
    notebooks unexecuted, their figures not drawn yet), and the ``pages`` pass reads and checks them again."""

    def __init__(self, app) -> None:
        super().__init__()
        self.app = app
        self.pages = os.path.join(str(app.srcdir), "")
        self.code = os.path.join(str(app.srcdir), CODE_PAGES)

    def path(self, record) -> str:
        """The file a record names (its location: a document's name, with a line or not; a node; a path)."""
        location = getattr(record, "location", None)
        if isinstance(location, tuple):
            location = location[0]
        if isinstance(location, nodes.Node):
            return str(sphinx_logging.get_node_location(location) or "")
        env = getattr(self.app, "env", None)
        if location and ":" not in str(location) and env is not None:
            return str(env.doc2path(str(location)))
        return str(location or "")

    def filter(self, record) -> bool:
        where = self.path(record)
        return not (where.startswith(self.pages) and not where.startswith(self.code))


def _drop_placeholder_warnings(app) -> None:
    # first, before Sphinx counts the warning (the build fails on any counted one) and -W makes it an error
    for handler in logging.getLogger(sphinx_logging.NAMESPACE).handlers:
        if isinstance(handler, sphinx_logging.WarningStreamHandler):
            handler.filters.insert(0, _PlaceholderWarnings(app))


def _pages_again(app, env, added, changed, removed) -> list[str]:
    """Every page but the code pages, read again (``env-get-outdated``)."""
    return sorted(d for d in env.found_docs if not d.startswith(CODE_PAGES))


def _keep_stubs(app) -> None:
    """The draft wrote the code pages' stubs from the same sources: autosummary does not import every module to
    write them again. Its generator reads the setting at builder-inited (priority 500); the setting is put back
    after it, so the saved environment's configuration stays the draft's (a changed one would read every page)."""
    configured = []

    def off(app) -> None:
        configured.append(app.config.autosummary_generate)
        app.config.autosummary_generate = False

    def back(app) -> None:
        app.config.autosummary_generate = configured.pop()

    app.connect("builder-inited", off, priority=100)
    app.connect("builder-inited", back, priority=900)


def _keep_empty_source_entries(app) -> None:
    """viewcode forgets, whenever a page is read again, every module none of whose objects it could tag (a module
    of constants: ``bgfn.schema``); a build that reads every page in parallel, as the book's does, keeps them in the
    source pages' index. They are put back after the reading."""
    saved: dict = {}

    def before(app, env, docnames) -> None:          # env-before-read-docs: before the pages are purged
        saved.update((m, e) for m, e in getattr(env, "_viewcode_modules", {}).items() if e and not e[2])

    def after(app, env) -> None:                     # env-updated: after every page was read
        modules = getattr(env, "_viewcode_modules", None)
        if modules is not None:
            for name, entry in saved.items():
                modules.setdefault(name, entry)

    app.connect("env-before-read-docs", before)
    app.connect("env-updated", after)


def _same_titles(app) -> None:
    """Every page's navigation shows the pages' titles, the code pages' too, which the ``pages`` pass does not write
    again: a page read again under another title is a warning (an error under -W); the build fails, and the next one
    builds every page. (The titles come from files the draft was built from, so this does not happen in ``make``'s
    runs.)"""
    titles: dict[str, str] = {}

    def before(app, env, docnames) -> None:
        titles.update((d, env.titles[d].astext()) for d in docnames if d in env.titles)

    def after(app, env) -> None:
        for docname, title in sorted(titles.items()):
            if docname in env.titles and env.titles[docname].astext() != title:
                _LOGGER.warning("the page's title changed since the draft (%r, now %r): the code pages' navigation "
                                "would show the old one", title, env.titles[docname].astext(), location=docname)

    app.connect("env-before-read-docs", before)
    app.connect("env-updated", after)


def _forget_vanished_words(app, *args) -> list:
    """html-collect-pages, before the search index is dumped: Sphinx prunes the pages read again from each word's
    pages, not the words, so a word only a page's last reading had (a placeholder's) is left with no page; and the
    index entries of a page no longer there stay. Both are dropped, as an index built from nothing would have them."""
    indexer = getattr(app.builder, "indexer", None)
    for mapping in (getattr(indexer, "_mapping", {}), getattr(indexer, "_title_mapping", {})):
        for word in [w for w, pages in mapping.items() if not pages]:
            del mapping[word]
    entries = getattr(indexer, "_index_entries", {})
    for docname in [d for d in entries if d not in app.env.all_docs]:
        del entries[docname]
    return []


def _save_environment(app, exception) -> None:
    """The environment saved once more when the build has finished: Sphinx saves it after reading, before the
    search index takes each page's index entries while writing, so a build that reads only some pages would
    otherwise dump an index without the others' entries. Written beside, then renamed over the last one."""
    if exception is None and app.builder.name == "html":
        from sphinx.application import ENV_PICKLE_FILENAME

        path = os.path.join(app.doctreedir, ENV_PICKLE_FILENAME)
        with open(path + ".tmp", "wb") as f:
            pickle.dump(app.env, f, pickle.HIGHEST_PROTOCOL)
        os.replace(path + ".tmp", path)


def _late_assets_first(app) -> None:
    """myst-nb's stylesheet and MathJax (sphinx-mathjax-offline) are copied when the build has finished, and Sphinx
    adds a checksum (``?v=...``) to a page's link to a file that is already there when it writes the page: copied
    first as well, every page links them alike, whatever ``_build`` held (the draft's code pages written into an
    empty one, the pages pass's pages after the draft)."""
    if app.builder.format != "html":
        return
    os.makedirs(os.path.join(app.builder.outdir, "_static"), exist_ok=True)
    if "myst_nb" in app.extensions:
        from myst_nb.sphinx_ext import add_global_html_resources

        add_global_html_resources(app, None)
    mathjax = getattr(app.extensions.get("sphinx-mathjax-offline"), "module", None)
    if mathjax is not None:
        mathjax.copy_mathjax_files(app, None)


def setup(app):
    prefer_modules()
    app.connect("builder-inited", _late_assets_first)
    app.connect("build-finished", _save_environment)
    app.connect("html-collect-pages", _forget_vanished_words)
    book_pass = os.environ.get(PASS_ENV, "")
    if book_pass == "draft":
        _drop_placeholder_warnings(app)
    elif book_pass == "pages":
        app.connect("env-get-outdated", _pages_again)
        _keep_stubs(app)
        _keep_empty_source_entries(app)
        _same_titles(app)
    elif book_pass:
        raise ValueError(f"{PASS_ENV}={book_pass!r}: expected 'draft', 'pages' or nothing")
    # around napoleon (priority 500), which turns numpydoc sections into reStructuredText
    app.connect("autodoc-process-docstring", _no_inline_type, priority=400)
    app.connect("autodoc-process-docstring", _plain, priority=900)
    # Two extensions declare nothing, so Sphinx would read and write the pages one at a time (tools/build_book.py
    # gives it the cores): sphinx-mathjax-offline only copies MathJax once the build has finished, and
    # sphinx_multitoc_numbering (loaded by sphinx_external_toc) numbers sections in the main process after reading,
    # and the book numbers none (html.use_multitoc_numbering: false).
    for name in ("sphinx-mathjax-offline", "sphinx_multitoc_numbering"):
        if name in app.extensions:
            app.extensions[name].parallel_read_safe = True
            app.extensions[name].parallel_write_safe = True
    return {"parallel_read_safe": True, "parallel_write_safe": True}
