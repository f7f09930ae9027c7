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
"""

from __future__ import annotations

import importlib
import importlib.util
import re

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


def setup(app):
    prefer_modules()
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
