"""The Makefile refuses what it cannot do before it makes anything, and works from any directory."""

from __future__ import annotations

import shutil
import subprocess

import pytest

from bgfn.config import PROJECT_ROOT

MAKEFILE = PROJECT_ROOT / "Makefile"
pytestmark = pytest.mark.skipif(shutil.which("make") is None, reason="GNU make not installed")


def _make(*args, cwd):
    return subprocess.run(["make", "--no-print-directory", *args], cwd=cwd, capture_output=True, text=True,
                          timeout=60)


def test_make_f_from_another_directory_runs_in_the_repository(tmp_path):
    res = _make("-f", str(MAKEFILE), "-n", "reproduce", "PROFILE=smoke", cwd=tmp_path)
    assert res.returncode == 0, res.stderr
    assert "unknown PROFILE" not in res.stderr and "bgfn.data fetch" in res.stdout     # the real recipe
    assert list(tmp_path.iterdir()) == []                          # nothing made where make was called


@pytest.mark.parametrize("profile", ["../params/smoke", "smoke/x", "/abs", ".hidden"])
def test_a_profile_that_is_not_a_plain_name_is_refused(profile, tmp_path):
    res = _make("-n", "reproduce", f"PROFILE={profile}", cwd=PROJECT_ROOT)
    assert res.returncode != 0 and "is not a profile name" in res.stderr
    assert not (PROJECT_ROOT / "params" / "smoke" / "notebooks").exists()


def test_a_path_with_a_space_fails_at_once_and_makes_nothing(tmp_path):
    repo = tmp_path / "my checkout"
    repo.mkdir()
    for name in ("Makefile", "requirements.lock"):
        shutil.copy(PROJECT_ROOT / name, repo / name)
    res = _make("venv", cwd=repo)
    assert res.returncode != 0 and "contains a space" in res.stderr
    assert sorted(p.name for p in repo.iterdir()) == ["Makefile", "requirements.lock"]   # no half-made .venv


def test_debris_of_an_interrupted_run_is_removed_and_results_are_kept(tmp_path):
    res_dir = tmp_path / "results" / "p"
    (res_dir / "notebooks").mkdir(parents=True)
    (res_dir / "tables").mkdir()
    debris = [res_dir / "notebooks" / ".03_bgfn_training.running-4242.ipynb",
              res_dir / "tables" / ".outage_field.csv.k2j3.tmp.csv", res_dir / ".energy.json.x9.tmp.json"]
    kept = [res_dir / "notebooks" / "03_bgfn_training.ipynb", res_dir / "tables" / "outage_field.csv"]
    for p in debris + kept:
        p.write_text("x")
    res = _make("clean-debris", f"RES={res_dir}", cwd=PROJECT_ROOT)
    assert res.returncode == 0, res.stderr
    assert not any(p.exists() for p in debris) and all(p.exists() for p in kept)
    assert res.stdout.count("removed debris") == 3
