"""The documentation describes the layout as it is, and the notebooks stay thin (logic lives in src/bgfn)."""

from __future__ import annotations

import re

import nbformat
import pytest

from bgfn.config import PROJECT_ROOT

SRC = PROJECT_ROOT / "src" / "bgfn"
NOTEBOOKS = sorted((PROJECT_ROOT / "notebooks").glob("*.ipynb"))
#: A notebook is prose, a parameters cell and calls into the package.
MAX_CODE_LINES = 80


def _block(path, heading: str) -> str:
    """The first fenced code block after ``heading`` in a Markdown file."""
    text = path.read_text(encoding="utf-8")
    after = text[text.index(heading):]
    return re.search(r"```\n(.*?)```", after, re.S).group(1)


def _modules():
    """(package or None, module stem) of every module file of the package."""
    for p in sorted(SRC.rglob("*.py")):
        if p.name in ("__init__.py", "__main__.py") or "__pycache__" in p.parts:
            continue
        rel = p.relative_to(SRC)
        yield (rel.parts[0] if len(rel.parts) > 1 else None), p.stem


@pytest.mark.parametrize("nb", NOTEBOOKS, ids=lambda p: p.stem)
def test_notebooks_are_thin(nb):
    code = [c for c in nbformat.read(nb, as_version=4).cells if c.cell_type == "code"]
    lines = sum(1 for c in code for line in c.source.splitlines() if line.strip())
    assert lines <= MAX_CODE_LINES, f"{nb.name}: {lines} code lines; move logic into src/bgfn"
    assert "parameters" in code[0].metadata.get("tags", [])


#: The paper's five steps in the brief's order; every other notebook comes after them.
PAPER_NOTEBOOKS = ["01_data_prep", "02_kf_baseline", "03_bgfn_training", "04_outage_evaluation", "05_energy_estimate"]


def test_the_papers_notebooks_come_first_and_hold_no_study():
    """A reader who edits notebook 01-05 meets only the paper's pipeline: no import of a study beyond the paper,
    no section titled beyond the paper; the studies, own logs and the results page follow in that order."""
    names = [p.stem for p in NOTEBOOKS]
    assert names[:5] == PAPER_NOTEBOOKS and names[-1] == "10_results", names
    for nb in NOTEBOOKS[:5]:
        cells = nbformat.read(nb, as_version=4).cells
        code = "\n".join(c.source for c in cells if c.cell_type == "code")
        assert "studies" not in code, f"{nb.name} imports a study beyond the paper"
        headings = [line for c in cells if c.cell_type == "markdown" for line in c.source.splitlines()
                    if line.startswith("#")]
        assert not [h for h in headings if "beyond the paper" in h.lower()], (nb.name, headings)
    for nb in NOTEBOOKS[5:8]:
        code = "\n".join(c.source for c in nbformat.read(nb, as_version=4).cells if c.cell_type == "code")
        assert "bgfn.studies" in code, f"{nb.name}: a study notebook calls its package in bgfn.studies"


def test_readme_layout_names_every_package_and_top_level_module():
    block = _block(PROJECT_ROOT / "README.md", "## Layout")
    for package, stem in _modules():
        name = f"{package}/" if package else f"{stem}.py"
        assert name in block, f"README.md's layout block does not name {name}"
    words = {5: "five", 6: "six", 7: "seven", 8: "eight"}
    assert f"built from {words[len(NOTEBOOKS)]} ordered notebooks" in (PROJECT_ROOT / "README.md").read_text()


def test_contributing_layout_names_every_module():
    block = _block(PROJECT_ROOT / "CONTRIBUTING.md", "## Layout")
    lines = block.splitlines()
    for package, stem in _modules():
        if package is None:
            assert f"{stem}.py" in block, f"CONTRIBUTING.md's layout misses src/bgfn/{stem}.py"
            continue
        start = next(i for i, line in enumerate(lines) if line.startswith(f"  {package}/"))
        end = next((i for i in range(start + 1, len(lines)) if re.match(r"^  \S", lines[i])), len(lines))
        assert f"{stem}.py" in "\n".join(lines[start:end]), f"CONTRIBUTING.md's layout misses {package}/{stem}.py"


def test_result_files_are_named_once():
    # the notebooks write and the results page reads results/<profile>/ files through bgfn.config's names;
    # the Makefile (which cannot import them) copies the findings under the same name
    from bgfn.config import RUN_RECORDS, SHARED_TABLES

    names = list(RUN_RECORDS.values()) + list(SHARED_TABLES.values())
    spelled = [f"{p.relative_to(PROJECT_ROOT)}: {name}" for p in sorted(SRC.rglob("*.py")) + NOTEBOOKS
               if p.name != "config.py"
               for name in names if re.search(rf"[\"']{re.escape(name)}[\"']", _code(p))]
    assert not spelled, "spell these result files through bgfn.config.RUN_RECORDS / SHARED_TABLES:\n" + "\n".join(spelled)
    assert f'$(RES)/{RUN_RECORDS["findings"]}' in (PROJECT_ROOT / "Makefile").read_text()


def _code(path) -> str:
    """The code of a module or notebook (a notebook's code cells only: its prose may name files)."""
    if path.suffix == ".ipynb":
        return "\n".join(c.source for c in nbformat.read(path, as_version=4).cells if c.cell_type == "code")
    return path.read_text(encoding="utf-8")
