"""The executed notebooks as the book shows them: one parameters cell per page.

papermill keeps a notebook's own ``parameters`` cell and inserts a copy with the run's values below it; the book
would show both. :func:`one_parameters_cell` writes the run's values into the notebook's own cell (its comments
kept) and drops the copy; ``make book`` applies it to the copies under ``book/notebooks/``. The same step refuses a
notebook that printed a warning (:func:`warnings_in`): a ``RuntimeWarning`` or ``UserWarning`` there is a defect of
ours the reader would otherwise see. No machine path reaches a page (:func:`without_machine_paths`): the
repository's folder is cut from the outputs, and an own log's folder becomes its dataset id. A page of the table of
contents whose notebook runs only for some profiles (:data:`OPTIONAL_PAGES`) is, where it did not run, a page that
says so (:func:`absent_pages`).
``python -m bgfn.report.book_notebooks [--profile P] [--absent DIR] FILE.ipynb ...`` rewrites each file in place,
writes those pages into ``DIR``, then exits 1 naming every warning found.
"""

from __future__ import annotations

import ast
import json
import re
import sys
from pathlib import Path

from bgfn.config import PROJECT_ROOT, read_profile
from bgfn.data.names import dataset_folder, dataset_id
from bgfn.errors import DataError
from bgfn.io import atomic_write_text
from bgfn.report import fleet_page

#: The book's pages whose notebook runs only for a profile with its section (notebook 11: ``fleet:``), each with the
#: Markdown page shown in its place where it did not run (``profile -> text``).
OPTIONAL_PAGES = {"11_fleet": fleet_page.absent_page}

#: The tags papermill reads and writes.
PARAMETERS_TAG, INJECTED_TAG = "parameters", "injected-parameters"
_ASSIGNMENT = re.compile(r"^(?P<name>[A-Za-z_]\w*)\s*=\s*(?P<value>.*?)(?P<comment>\s+#.*)?$")


def _tags(cell: dict) -> list:
    return cell.get("metadata", {}).get("tags", [])


def _source(cell: dict) -> str:
    src = cell.get("source", "")
    return "".join(src) if isinstance(src, list) else src


def injected_values(source: str) -> dict[str, str]:
    """``name -> value expression`` of the top-level assignments of papermill's injected cell."""
    out = {}
    for node in ast.parse(source).body:
        if isinstance(node, ast.Assign) and len(node.targets) == 1 and isinstance(node.targets[0], ast.Name):
            out[node.targets[0].id] = ast.get_source_segment(source, node.value)
    return out


def one_parameters_cell(nb: dict) -> dict:
    """``nb`` with the injected values written into its own parameters cell and the injected cell removed
    (unchanged when either cell is missing). A value injected for a name the cell does not assign is appended
    to it, so nothing the run used is hidden."""
    cells = nb.get("cells", [])
    own = next((c for c in cells if PARAMETERS_TAG in _tags(c)), None)
    injected = next((c for c in cells if INJECTED_TAG in _tags(c)), None)
    if own is None or injected is None:
        return nb
    values = injected_values(_source(injected))
    lines, seen = [], set()
    for line in _source(own).splitlines():
        m = _ASSIGNMENT.match(line)
        if m and m["name"] in values:
            seen.add(m["name"])
            line = f"{m['name']} = {values[m['name']]}{m['comment'] or ''}"
        lines.append(line)
    lines += [f"{k} = {v}" for k, v in values.items() if k not in seen]
    own["source"] = "\n".join(lines)
    nb["cells"] = [c for c in cells if c is not injected]
    return nb


_WARNING = re.compile(r"\b\w*Warning: .*")


def warnings_in(nb: dict) -> list[str]:
    """``cell <k>: <the warning line>`` for every warning a code cell printed (its stderr stream)."""
    out = []
    for k, cell in enumerate(nb.get("cells", [])):
        for o in cell.get("outputs", []):
            if o.get("output_type") == "stream" and o.get("name") == "stderr":
                text = o.get("text", "")
                out += [f"cell {k}: {m.group(0)[:200]}" for m in _WARNING.finditer("".join(text) if isinstance(
                    text, list) else text)]
    return out


def machine_paths(profile: str | None) -> dict[str, str]:
    """``{machine path: what a page shows}``: each own-log folder of ``profile`` (its ``data.datasets``) by its
    dataset id, the repository's folder by nothing (its files by their relative paths); longest first."""
    out: dict[str, str] = {}
    if profile:
        try:
            names = read_profile(profile)["data"]["datasets"]
        except DataError:
            names = []
        for name in names:
            folder = dataset_folder(name)
            if folder is not None:
                for shown in {str(name), str(folder), str(folder.resolve())}:
                    out[shown] = dataset_id(name)
    out[str(PROJECT_ROOT.resolve()) + "/"] = ""
    out[str(PROJECT_ROOT.resolve())] = "."
    return dict(sorted(out.items(), key=lambda kv: -len(kv[0])))


def without_machine_paths(nb: dict, paths: dict[str, str]) -> dict:
    """``nb`` with every key of ``paths`` in its cells' outputs replaced by its value (:func:`machine_paths`)."""
    def clean(value):
        if isinstance(value, str):
            for path, shown in paths.items():
                value = value.replace(path, shown)
            return value
        if isinstance(value, list):
            return [clean(v) for v in value]
        if isinstance(value, dict):
            return {k: clean(v) for k, v in value.items()}
        return value

    for cell in nb.get("cells", []):
        if "outputs" in cell:
            cell["outputs"] = clean(cell["outputs"])
    return nb


def rewrite(path: str | Path, paths: dict[str, str] | None = None) -> None:
    """Apply :func:`one_parameters_cell` and :func:`without_machine_paths` to a notebook file in place
    (atomically)."""
    path = Path(path)
    nb = one_parameters_cell(json.loads(path.read_text(encoding="utf-8")))
    nb = without_machine_paths(nb, paths if paths is not None else machine_paths(None))
    atomic_write_text(path, json.dumps(nb, indent=1, ensure_ascii=False) + "\n")


def absent_pages(folder: str | Path, profile: str) -> list[Path]:
    """For each of :data:`OPTIONAL_PAGES` without its executed notebook in ``folder``, ``<folder>/<name>.md`` saying
    that it did not run for ``profile``; the pages written."""
    folder, out = Path(folder), []
    for name, page in OPTIONAL_PAGES.items():
        if not (folder / f"{name}.ipynb").exists():
            out.append(folder / f"{name}.md")
            atomic_write_text(out[-1], page(profile))
    return out


def main(paths) -> int:
    """Rewrite each notebook (:func:`rewrite`) and write the pages of :func:`absent_pages` (``--absent DIR``); 1 when
    any notebook printed a warning (each named), else 0."""
    paths = list(paths)
    options = {"--profile": None, "--absent": None}
    while paths[:1] and paths[0] in options and len(paths) >= 2:
        options[paths[0]], paths = paths[1], paths[2:]
    profile = options["--profile"]
    if options["--absent"] is not None:
        absent_pages(options["--absent"], profile or "")
    shown = machine_paths(profile)
    found = []
    for name in paths:
        rewrite(name, shown)
        found += [f"{name}: {w}" for w in warnings_in(json.loads(Path(name).read_text(encoding="utf-8")))]
    if found:
        print("error: warnings in the executed notebooks (fix their cause; the book does not show them):\n  "
              + "\n  ".join(found), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
