"""``jupyter-book build`` with Sphinx reading and writing the pages on every core (``make book``).

Jupyter Book 1.x's command line has no ``-j``; its build function has (``jobs``): this runs the command line with
the cores passed to it (``python tools/build_book.py book --all -W -n --keep-going``). Sphinx reads and writes in
parallel only when every extension says it may (``book/_ext/code_page.py`` says so for two that say nothing).
"""

from __future__ import annotations

import functools
import os
import sys

import jupyter_book.sphinx
from jupyter_book.cli.main import main


def cores() -> int:
    """The cores this process may run on (Sphinx forks one reader/writer per core)."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)


if __name__ == "__main__":
    # the command line imports build_sphinx from this module when it runs, so the cores reach it
    jupyter_book.sphinx.build_sphinx = functools.partial(jupyter_book.sphinx.build_sphinx, jobs=cores())
    sys.argv = ["jupyter-book", "build", *sys.argv[1:]]
    main()
