"""A changed setting reruns only the notebooks that read it: ``make -n`` over a copy of the repository's make inputs
(no notebook runs: the executed notebooks are files touched in order), after one key of a smoke-based profile is
edited (tools/notebook_deps.py writes the sections; the Makefile includes its rules)."""

from __future__ import annotations

import hashlib
import importlib.util
import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

from bgfn.config import PROJECT_ROOT

pytestmark = pytest.mark.skipif(shutil.which("make") is None, reason="GNU make not installed")

PROFILE = "deps-check"
NOTEBOOKS = sorted(p.stem for p in (PROJECT_ROOT / "notebooks").glob("[0-9][0-9]_*.ipynb"))
ALL = {n[:2] for n in NOTEBOOKS if n[:2] <= "10"}        # 11 (a fleet) runs only for a profile with a fleet: section


def _tool():
    spec = importlib.util.spec_from_file_location("notebook_deps", PROJECT_ROOT / "tools" / "notebook_deps.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _checkout(tmp_path: Path) -> Path:
    """What make reads (Makefile, lock, profiles, notebooks, tools, the package's sources, the paper's data) and a
    venv holding only its stamp: the interpreter running this test stands in (PY=... on make's line)."""
    repo = tmp_path / "repo"
    for name in ("Makefile", "requirements.lock"):
        (repo / name).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(PROJECT_ROOT / name, repo / name)
    for folder in ("params", "notebooks", "tools", "data/paper", "data/measured"):
        if (PROJECT_ROOT / folder).is_dir():
            shutil.copytree(PROJECT_ROOT / folder, repo / folder)
    shutil.copytree(PROJECT_ROOT / "src" / "bgfn", repo / "src" / "bgfn",
                    ignore=shutil.ignore_patterns("__pycache__"))
    lock_hash = hashlib.sha256((repo / "requirements.lock").read_bytes()).hexdigest()[:16]
    venv = repo / ".venv"
    (venv / "etc" / "ipython").mkdir(parents=True)
    (venv / f".installed-{lock_hash}").touch()
    (venv / "etc" / "ipython" / "ipython_kernel_config.py").touch()
    (repo / "params" / f"{PROFILE}.yaml").write_text(f"base: smoke\n", encoding="utf-8")
    return repo


def _would_run(repo: Path) -> set[str]:
    """The notebooks (their numbers) ``make -n`` would run for the profile."""
    env = {**os.environ, "BGFN_ROOT": str(repo), "PYTHONPATH": str(PROJECT_ROOT / "src")}
    res = subprocess.run(["make", "-n", "_notebooks", f"PROFILE={PROFILE}", f"PY={sys.executable}"], cwd=repo,
                         env=env, capture_output=True, text=True, timeout=600)
    assert res.returncode == 0, res.stdout + res.stderr
    return set(re.findall(rf"==> \[{PROFILE}\] papermill notebooks/(\d\d)_\w+\.ipynb", res.stdout))


def _all_run_long_ago(repo: Path) -> None:
    """Every file older than the executed notebooks, which were made in order (01 first): an up-to-date run."""
    old = time.time() - 1000
    for path in repo.rglob("*"):
        if path.is_file():
            os.utime(path, (old, old))
    executed = repo / "results" / PROFILE / "notebooks"
    executed.mkdir(parents=True, exist_ok=True)
    for i, name in enumerate(NOTEBOOKS):
        path = executed / f"{name}.ipynb"
        path.touch()
        os.utime(path, (old + 10 + i, old + 10 + i))
    checked = repo / "results" / PROFILE / ".profile-checked"
    checked.touch()
    os.utime(checked, (old + 5, old + 5))


def _edit(repo: Path, yaml_text: str) -> None:
    path = repo / "params" / f"{PROFILE}.yaml"
    path.write_text(path.read_text(encoding="utf-8") + yaml_text, encoding="utf-8")


def test_one_edited_key_reruns_only_the_notebooks_that_read_it(tmp_path):
    repo = _checkout(tmp_path)
    assert _would_run(repo) == ALL                          # nothing executed yet: every notebook
    _all_run_long_ago(repo)
    assert _would_run(repo) == set()                        # up to date: the section files were not rewritten

    _edit(repo, "evaluate:\n  odometer: {sigmas_mps: [0.1, 2.0]}\n")
    assert _would_run(repo) == {"07", "10"}                 # the odometer study and the results page

    _all_run_long_ago(repo)
    _edit(repo, "train:\n  optimizer: {epochs: 3}\n")
    assert _would_run(repo) == {"03", "04", "05", "06", "07", "08", "10"}   # not 01, 02 (drives, GPS/INS), 09

    _all_run_long_ago(repo)
    _edit(repo, "parallel: {jobs: 1}\n")                   # where the runs go: no result depends on it
    assert _would_run(repo) == set()

    _all_run_long_ago(repo)
    module = repo / "src" / "bgfn" / "report" / "verdict_page.py"
    module.write_text(module.read_text(encoding="utf-8") + "\n", encoding="utf-8")
    rerun = _would_run(repo)                                # a report module: 10 (and 03's sentences, then 04-06)
    assert "10" in rerun and not rerun & {"01", "02", "07", "08", "09"}

    _all_run_long_ago(repo)
    _edit(repo, "data:\n  t_end: 139250.0\n")
    assert _would_run(repo) == ALL                          # the drives: every notebook (through 01)


def test_an_edited_fleet_drive_reruns_only_the_fleet_study(tmp_path):
    repo = _checkout(tmp_path)
    drive = tmp_path / "fleet drive"                      # only its files' names, sizes and times are read
    drive.mkdir()
    (drive / "imu.csv").write_text("time\n0.0\n", encoding="utf-8")
    _edit(repo, f"fleet:\n  drives: ['{drive}']\n")
    assert _would_run(repo) == ALL | {"11"}               # nothing executed yet (the fingerprints written)
    _all_run_long_ago(repo)
    assert _would_run(repo) == set()
    os.utime(drive / "imu.csv")                           # `touch imu.csv`: the fleet's drive, in no other list
    assert _would_run(repo) == {"11"}
    _all_run_long_ago(repo)
    _edit(repo, "data:\n  t_end: 139250.0\n")
    assert _would_run(repo) == ALL | {"11"}               # the profile's own drives: every notebook


def test_every_notebook_declares_sections_the_profile_has():
    tool = _tool()
    assert sorted(tool.NOTEBOOK_SECTIONS) == NOTEBOOKS
    from bgfn.config import read_profile
    available = tool.section_values(read_profile("quick"))
    for name, sections in tool.NOTEBOOK_SECTIONS.items():
        assert set(sections) - {"*"} <= set(available), name
    assert "parallel" not in available
    assert {"evaluate", "evaluate.odometer", "evaluate.sweep", "evaluate.oracle", "evaluate.pseudo_gps"} <= set(available)
    assert "odometer" not in available["evaluate"]          # a subsection lives in its own file only


def test_a_rule_picked_outage_carries_the_training_margin_it_checks():
    tool = _tool()
    from bgfn.config import read_profile
    cfg = read_profile("quick")                             # rtklib-drive0708: {rule: cruise_and_manoeuvre}
    windows = tool.section_values(cfg)["outage_windows"]
    assert windows["train.margin_s"] == cfg["train"]["margin_s"]


def test_a_section_file_is_rewritten_only_when_its_content_changes(tmp_path):
    tool = _tool()
    path = tmp_path / "s.json"
    assert tool.write_if_changed(path, "1\n")
    os.utime(path, (1000, 1000))
    assert not tool.write_if_changed(path, "1\n") and path.stat().st_mtime == 1000
    assert tool.write_if_changed(path, "2\n") and path.stat().st_mtime > 1000


def test_imports_are_followed_through_the_package(tmp_path):
    tool = _tool()
    src = tmp_path / "src"
    (src / "bgfn" / "a").mkdir(parents=True)
    (src / "bgfn" / "__init__.py").write_text("")
    (src / "bgfn" / "a" / "__init__.py").write_text("from .b import f\n")
    (src / "bgfn" / "a" / "b.py").write_text("def f():\n    from bgfn import c\n")
    (src / "bgfn" / "c.py").write_text("import numpy\n")
    (src / "bgfn" / "d.py").write_text("")
    files = {p.relative_to(src).as_posix() for p in tool.module_closure(src, {"bgfn.a"})}
    assert files == {"bgfn/__init__.py", "bgfn/a/__init__.py", "bgfn/a/b.py", "bgfn/c.py"}   # not d.py
