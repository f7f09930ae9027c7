"""The results page (notebook 10) and every sentence of the notebooks: our tables beside the paper's, where each
number came from, and plain sentences computed from the numbers.

The page reads what notebooks 01-09 wrote under ``results/<profile>/`` (a missing file is reported, never fatal)
and the paper's published values (:mod:`bgfn.paper`; shown beside ours, never used to choose anything). Modules:
:mod:`~bgfn.report.reading`, :mod:`~bgfn.report.tables`, :mod:`~bgfn.report.provenance`,
:mod:`~bgfn.report.sentences`, :mod:`~bgfn.report.profile_comparison`, :mod:`~bgfn.report.glance`,
:mod:`~bgfn.report.figures`, :mod:`~bgfn.report.sections`, :mod:`~bgfn.report.verdict` and the page's first screen;
``*_words`` modules word each notebook's results (:mod:`~bgfn.report.nav_words`, ...): the lower layers return
numbers, tables and codes. The page's pieces in one namespace: :mod:`~bgfn.report.page`. This file imports
nothing: a notebook that imports one ``*_words`` module depends on that module alone.
"""
