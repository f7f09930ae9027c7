"""What each executed notebook of a profile depends on, for make: the profile sections it reads and the modules it imports.

``python tools/notebook_deps.py PROFILE`` writes, under ``results/<profile>/``:

- ``.sections/<section>.json``: the resolved value (base chain merged, defaults filled: :func:`bgfn.config.read_profile`)
  of each top-level key of the profile, ``evaluate``'s subsections in files of their own
  (``evaluate.odometer.json``, ...), each rewritten only when its content changed, so that its time changes only
  with a real change of the setting;
- ``.data-fingerprint``: the fingerprint of the profile's CSV drives, and ``.fleet-fingerprint`` that of its
  fleet's (read by notebook 11 only; :func:`bgfn.data.names.drive_fingerprints`), each rewritten only when it
  changed;
- ``.deps.mk``: one make rule per notebook naming the section files it reads (:data:`NOTEBOOK_SECTIONS`), the
  profile files it reads besides its own (:data:`OTHER_PROFILES`) and the package's modules it imports, followed
  transitively through ``src/bgfn`` (its own ``import`` statements, at any depth, and the module names it hands
  to the runner's workers as strings).

The Makefile includes ``.deps.mk`` and remakes it on every run (the script is cheap), so an edited setting reruns
only the notebooks that read it, and an edited module only the notebooks that import it.
"""

from __future__ import annotations

import argparse
import ast
import json
import sys
from pathlib import Path

from bgfn.config import profile_chain, read_profile
from bgfn.data.names import drive_fingerprints
from bgfn.errors import DataError

#: Sections whose subsections (the mappings among their keys) get files of their own: a study's knobs
#: (``evaluate.odometer``, ``evaluate.sweep``, ...) then rerun only the notebooks that read them.
SPLIT_SECTIONS: tuple[str, ...] = ("evaluate",)
#: Top-level keys no notebook's result depends on (where the runs go: :mod:`bgfn.parallel`), so no file.
UNREAD_KEYS: tuple[str, ...] = ("parallel",)

_DRIVES = ("data", "seed", "outage_windows")        # what loading a drive and its outages reads
_EVALUATE = ("nav", "train", "evaluate", "evaluate.pseudo_gps")
#: The profile sections each notebook reads (directly or through the package), declared here and checked by
#: tests/test_notebook_deps.py against the section files the profile produces. ``description``: the notebook
#: prints it. ``train`` in 08: the sweep's starts leave room for the networks' input window
#: (:func:`bgfn.studies.outage_sweep.sweep.profile_sweep_plan`). Notebook 10, the results page, reads the whole
#: profile (:func:`bgfn.report.read_results`).
NOTEBOOK_SECTIONS: dict[str, tuple[str, ...]] = {
    "01_data_prep": (*_DRIVES, "description"),
    "02_kf_baseline": (*_DRIVES, "nav", "description"),
    "03_bgfn_training": (*_DRIVES, "nav", "train", "description"),
    "04_outage_evaluation": (*_DRIVES, *_EVALUATE, "description"),
    "05_energy_estimate": (*_DRIVES, *_EVALUATE, "energy", "description"),
    "06_outage_sweep": (*_DRIVES, *_EVALUATE, "evaluate.sweep", "evaluate.oracle", "variants", "variant_runs",
                        "description"),
    "07_learned_odometer": (*_DRIVES, *_EVALUATE, "evaluate.sweep", "evaluate.odometer", "energy", "description"),
    "08_ins_fidelity": (*_DRIVES, *_EVALUATE, "evaluate.sweep", "evaluate.nees_scan"),
    "09_own_logs": _DRIVES,
    "10_results": ("*",),
    "11_fleet": (*_DRIVES, *_EVALUATE, "evaluate.sweep", "evaluate.odometer", "fleet", "description"),
}
#: Profiles a notebook reads besides its own (their files and base chains): 03 estimates the paper's training
#: time from the ``paper`` profile; 09 runs the gallery's logs under the ``own`` and ``own-walker`` profiles.
OTHER_PROFILES: dict[str, tuple[str, ...]] = {
    "03_bgfn_training": ("paper",),
    "09_own_logs": ("own", "own-walker"),
}

PACKAGE = "bgfn"


def section_values(cfg: dict) -> dict[str, object]:
    """The section files' contents: each top-level key of the resolved profile (:data:`UNREAD_KEYS` aside), the
    subsections of :data:`SPLIT_SECTIONS` apart from the rest of their section. ``outage_windows`` holds
    ``train.margin_s`` too when an entry is a rule: the rule's check reads it
    (:func:`bgfn.nav.outages.picked_outages`)."""
    out: dict[str, object] = {}
    for key, value in cfg.items():
        if key in UNREAD_KEYS:
            continue
        if key in SPLIT_SECTIONS and isinstance(value, dict):
            rest = {k: v for k, v in value.items() if not isinstance(v, dict)}
            out[key] = rest
            out.update({f"{key}.{k}": v for k, v in value.items() if isinstance(v, dict)})
        else:
            out[key] = value
    windows = cfg.get("outage_windows")
    if isinstance(windows, dict) and any(isinstance(v, dict) for v in windows.values()):
        out["outage_windows"] = {"outage_windows": windows, "train.margin_s": cfg["train"]["margin_s"]}
    return out


def write_if_changed(path: Path, text: str) -> bool:
    """Write ``text`` to ``path`` (through a temporary file) unless it holds exactly that already."""
    if path.is_file() and path.read_text(encoding="utf-8") == text:
        return False
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp")
    tmp.write_text(text, encoding="utf-8")
    tmp.replace(path)
    return True


def notebook_sections(notebook: str, available) -> list[str]:
    """The section names ``notebook`` reads, among ``available`` (``*``: all of them)."""
    if notebook not in NOTEBOOK_SECTIONS:
        raise DataError(Path(__file__).name, "NOTEBOOK_SECTIONS", f"an entry for notebook {notebook}", "none")
    wanted = NOTEBOOK_SECTIONS[notebook]
    if "*" in wanted:
        return sorted(available)
    return [s for s in wanted if s in available]


# ---------------------------------------------------------------- imports
def _module_file(src: Path, name: str) -> Path | None:
    """The file of module ``name`` under ``src`` (``a.b`` -> ``a/b.py`` or ``a/b/__init__.py``), or None."""
    base = src.joinpath(*name.split("."))
    for candidate in (base.with_suffix(".py"), base / "__init__.py"):
        if candidate.is_file():
            return candidate
    return None


def _imported_names(tree: ast.AST, module: str | None, is_package: bool) -> set[str]:
    """Module names an AST imports (at any depth: functions' imports too), the package's own only, with the
    candidates ``from x import y`` may name (``x.y`` when it is a module), and string constants equal to a
    module's name (modules handed to the runner's workers, :meth:`bgfn.parallel.Runner.start`)."""
    names: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                parts = (module or "").split(".")
                keep = len(parts) - node.level + (1 if is_package else 0)
                base = ".".join(parts[:keep] + ([node.module] if node.module else []))
            else:
                base = node.module or ""
            names.add(base)
            names.update(f"{base}.{a.name}" for a in node.names)
        elif isinstance(node, ast.Constant) and isinstance(node.value, str) and node.value.startswith(PACKAGE + "."):
            names.add(node.value)
    return {n for n in names if n == PACKAGE or n.startswith(PACKAGE + ".")}


_DIRECT: dict[tuple[Path, str], tuple[Path | None, set[str]]] = {}


def _direct_imports(src: Path, name: str) -> tuple[Path | None, set[str]]:
    """Module ``name``'s file under ``src`` and the package's modules it names (parsed once per run)."""
    key = (src, name)
    if key not in _DIRECT:
        path = _module_file(src, name)
        names: set[str] = set()
        if path is not None:
            tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
            names = _imported_names(tree, name, path.name == "__init__.py")
        _DIRECT[key] = (path, names)
    return _DIRECT[key]


def module_closure(src: Path, roots: set[str]) -> list[Path]:
    """The files of ``roots`` and of every module of the package they import, transitively (a module's parent
    packages too: importing ``a.b`` runs ``a/__init__.py``)."""
    seen: dict[str, Path] = {}
    done: set[str] = set()
    todo = sorted(roots)
    while todo:
        name = todo.pop()
        parts = name.split(".")
        for i in range(1, len(parts) + 1):          # the parents first: each is imported on the way
            sub = ".".join(parts[:i])
            if sub in done:
                continue
            done.add(sub)
            path, names = _direct_imports(src, sub)
            if path is None:
                continue                            # an attribute imported from a module, not a module
            seen[sub] = path
            todo.extend(names - done)
    return sorted(seen.values())


def notebook_code(path: Path) -> str:
    """A notebook's code cells as one Python source (IPython's ``%``/``!`` lines left out)."""
    nb = json.loads(path.read_text(encoding="utf-8"))
    lines = []
    for cell in nb.get("cells", []):
        if cell.get("cell_type") == "code":
            src = "".join(cell.get("source", []))
            lines += [ln for ln in src.splitlines() if not ln.lstrip().startswith(("%", "!"))]
    return "\n".join(lines) + "\n"


def notebook_modules(path: Path, src: Path) -> list[Path]:
    """The package's files a notebook imports, transitively."""
    tree = ast.parse(notebook_code(path), filename=str(path))
    return module_closure(src, _imported_names(tree, None, False))


# ---------------------------------------------------------------- the files make reads
def write_profile_deps(profile: str, results: Path, notebooks_dir: Path = Path("notebooks"),
                       src: Path = Path("src")) -> list[str]:
    """Write the section files, the data fingerprint and ``.deps.mk`` of ``profile`` under ``results``; returns
    the names of the section files that changed."""
    cfg = read_profile(profile)
    values = section_values(cfg)
    sections_dir = results / ".sections"
    changed = [name for name, value in values.items()
               if write_if_changed(sections_dir / f"{name}.json",
                                   json.dumps(value, indent=1, sort_keys=True, default=str) + "\n")]
    for stale in sections_dir.glob("*.json"):       # a subsection the profile no longer has
        if stale.stem not in values:
            stale.unlink()
            changed.append(stale.stem)
    drives, fleet = drive_fingerprints(cfg)       # what notebooks 01-10 read; what only notebook 11 reads
    write_if_changed(results / ".data-fingerprint", drives + "\n")
    write_if_changed(results / ".fleet-fingerprint", fleet + "\n")

    lines = [f"# Written by tools/notebook_deps.py for profile {profile}: what each executed notebook depends on."]
    for path in sorted(notebooks_dir.glob("[0-9][0-9]_*.ipynb")):
        name = path.stem
        files = [f"{sections_dir}/{s}.json" for s in notebook_sections(name, values)]
        files += [str(p) for other in OTHER_PROFILES.get(name, ()) for p in _relative(profile_chain(other))]
        files += [str(p) for p in notebook_modules(path, src)]
        lines.append(f"{results}/notebooks/{name}.ipynb: " + " \\\n  ".join(dict.fromkeys(files)))
    write_if_changed(results / ".deps.mk", "\n".join(lines) + "\n")
    return changed


def _relative(paths) -> list[Path]:
    """``paths`` relative to the current directory (make's paths are the repository root's)."""
    here = Path.cwd().resolve()
    out = []
    for p in paths:
        p = Path(p).resolve()
        out.append(p.relative_to(here) if p.is_relative_to(here) else p)
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("profile", help="a profile name (params/<name>.yaml)")
    parser.add_argument("--results", help="the profile's results folder (default results/<profile>)")
    args = parser.parse_args(argv)
    try:
        changed = write_profile_deps(args.profile, Path(args.results or f"results/{args.profile}"))
    except DataError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    if changed:
        print(f"    settings changed since the last run: {', '.join(sorted(changed))}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
