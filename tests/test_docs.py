"""The documentation describes the layout as it is, and the notebooks stay thin (logic lives in src/bgfn)."""

from __future__ import annotations

import importlib.util
import re
import subprocess
import sys

import nbformat
import pytest
import yaml

from bgfn.config import PROJECT_ROOT

SRC = PROJECT_ROOT / "src" / "bgfn"
BOOK = PROJECT_ROOT / "book"
README = PROJECT_ROOT / "README.md"
NOTEBOOKS = sorted((PROJECT_ROOT / "notebooks").glob("*.ipynb"))
#: A notebook is prose, a parameters cell and calls into the package.
MAX_CODE_LINES = 80
#: A newcomer reads the README in two minutes; measurements and their history go to benchmarks/MEASUREMENTS.md.
MAX_README_LINES = 120


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
    # the results page ends every profile's chain; a notebook after it runs only for a profile with its own section
    # (11_fleet: a fleet: section)
    chain = [n for n in names if n <= "10_results"]
    assert names[:5] == PAPER_NOTEBOOKS and chain[-1] == "10_results", names
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
    block = _block(README, "## Layout")
    for package, stem in _modules():
        name = f"{package}/" if package else f"{stem}.py"
        assert name in block, f"README.md's layout block does not name {name}"


def test_readme_is_short_and_leaves_measurements_to_their_page():
    text = README.read_text(encoding="utf-8")
    assert len(text.splitlines()) <= MAX_README_LINES, f"README.md: keep it to {MAX_README_LINES} lines"
    history = re.findall(r"`[0-9a-f]{7,40}`|\b20\d\d-\d\d-\d\d\b|CPU family", text)
    assert not history, f"README.md: commits, dates and machines belong in benchmarks/MEASUREMENTS.md: {history}"
    links = [link for link in re.findall(r"\]\(([^)#\s]+)", text) if not re.match(r"[a-z]+://", link)]
    assert "benchmarks/MEASUREMENTS.md" in links and "CONTRIBUTING.md" in links
    missing = [link for link in links if not (PROJECT_ROOT / link).exists()]
    assert not missing, f"README.md links to missing files: {missing}"


# ----------------------------------------------------------------------------------------------- the code page
def _dotted_modules() -> list[str]:
    """Every module and package of bgfn, dotted, from the files (``__main__`` is private: no page)."""
    names = []
    for p in sorted(SRC.rglob("*.py")):
        if "__pycache__" in p.parts or p.name == "__main__.py":
            continue
        parts = p.relative_to(SRC.parent).with_suffix("").parts
        names.append(".".join(parts[:-1] if p.name == "__init__.py" else parts))
    return names


def code_label(module: str) -> str:
    """The label of a module's page (book/_templates/autosummary/module.rst): ``code-`` and the name, '.' '_' -> '-'."""
    return "code-" + module.replace(".", "-").replace("_", "-")


def _code_toctree() -> str:
    """The folder the code page's recursive autosummary writes its module pages to, checked on the way."""
    code = (BOOK / "code.md").read_text(encoding="utf-8")
    m = re.search(r"^\.\. autosummary::\n((?:[ \t]+\S.*\n|\n)+)", code, re.M)
    assert m, "book/code.md: no autosummary directive"
    body = m.group(1)
    assert ":recursive:" in body and body.split()[-1] == "bgfn", "book/code.md: autosummary, recursive, over bgfn"
    return re.search(r":toctree:\s*(\S+)", body).group(1)


def test_code_page_is_generated_at_build_time():
    sphinx = yaml.safe_load((BOOK / "_config.yml").read_text())["sphinx"]
    assert {"sphinx.ext.autodoc", "sphinx.ext.autosummary", "sphinx.ext.napoleon"} <= set(sphinx["extra_extensions"])
    assert sphinx["config"]["autosummary_generate"] is True
    folder = _code_toctree()
    # the generated pages are never committed, and the draft and a build of every page start without the last
    # one's (the pages pass keeps the draft's: tests/test_book_passes.py)
    assert f"book/{folder}/" in (PROJECT_ROOT / ".gitignore").read_text().splitlines()
    assert (PROJECT_ROOT / "Makefile").read_text().count(f"rm -rf book/{folder}") == 2


def test_code_page_has_a_labelled_page_for_every_module(tmp_path):
    _code_toctree()
    # autosummary's page generator, as the book build runs it (with the book's extension), in a process of its own
    generate = ("import sys; sys.path.insert(0, sys.argv[1]); import code_page; code_page.prefer_modules(); "
                "from sphinx.ext.autosummary.generate import main; main(sys.argv[2:])")
    run = subprocess.run([sys.executable, "-c", generate, str(BOOK / "_ext"), "-o", str(tmp_path),
                          "-t", str(BOOK / "_templates"), str(BOOK / "code.md")],
                         capture_output=True, text=True, cwd=PROJECT_ROOT)
    assert run.returncode == 0, run.stderr[-2000:]
    assert "failed to import" not in run.stdout + run.stderr, (run.stdout + run.stderr)[-2000:]
    for module in _dotted_modules():
        page = tmp_path / f"{module}.rst"
        assert page.is_file(), f"the code page has no page for {module}"
        text = page.read_text()
        assert f".. _{code_label(module)}:" in text and f".. automodule:: {module}" in text, text[:300]


def test_book_links_to_code_name_existing_modules():
    labels = {code_label(m) for m in _dotted_modules()}
    pages = {p.name: p.read_text(encoding="utf-8") for p in sorted(BOOK.glob("*.md"))}
    for nb in NOTEBOOKS:
        pages[nb.name] = "\n".join(c.source for c in nbformat.read(nb, as_version=4).cells if c.cell_type == "markdown")
    stale = [f"{page}: {target}" for page, text in pages.items()
             for target in re.findall(r"<(code-[\w-]+)>`", text) if target not in labels]
    assert not stale, "links to the code page that name no module of bgfn:\n  " + "\n  ".join(stale)


def _code_page_extension():
    spec = importlib.util.spec_from_file_location("code_page", BOOK / "_ext" / "code_page.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_docstrings_absolute_values_and_spilling_tables_are_made_literal():
    ext = _code_page_extension()
    assert ext._escape_bars("max |east| and |north|, ``|x|``") == r"max \|east\| and \|north\|, ``|x|``"
    assert ext._escape_bars("| a line block |") == "| a line block |"
    assert ext._escape_bars("|north| first") == r"\|north\| first"
    good = ["=====  =====", "key    value", "=====  =====", ""]
    assert ext._literal_tables(good) == good
    spill = ["text", "", "=====  =====", "key    value", "a_long_key  value", "=====  =====", "", "after"]
    out = ext._literal_tables(spill)
    assert out[:4] == ["text", "", "::", ""] and out[4:8] == ["   " + line for line in spill[2:6]]
    assert out[-1] == "after"


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
