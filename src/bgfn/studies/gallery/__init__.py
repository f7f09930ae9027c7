"""Your own logs: a gallery of CSV folders written as a user would bring them, each run as a user would.

:mod:`~bgfn.studies.gallery.logs` writes the folders (other mountings, rates, platforms);
:mod:`~bgfn.studies.gallery.runs` runs each through the loader and the filter.
"""

