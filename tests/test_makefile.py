"""The Makefile refuses what it cannot do before it makes anything, and works from any directory."""

from __future__ import annotations

import fcntl
import os
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


def _checkout(tmp_path):
    """The Makefile, the lock and the profiles in a folder of their own (nothing else: make must refuse first)."""
    repo = tmp_path / "repo"
    (repo / "params").mkdir(parents=True)
    for name in ("Makefile", "requirements.lock"):
        shutil.copy(PROJECT_ROOT / name, repo / name)
    for p in (PROJECT_ROOT / "params").glob("*.yaml"):
        shutil.copy(p, repo / "params" / p.name)
    return repo


def test_a_base_that_names_no_profile_is_one_error_naming_the_file_to_fix(tmp_path):
    repo = _checkout(tmp_path)
    (repo / "params" / "mine.yaml").write_text("base: nosuch\n")
    res = _make("-n", "reproduce", "PROFILE=mine", cwd=repo)
    assert res.returncode != 0 and "No rule to make target" not in res.stderr
    assert "params/nosuch.yaml, which does not exist -- fix `base:` in params/mine.yaml" in res.stderr


def test_a_second_run_of_the_same_profile_refuses_at_once_naming_the_first(tmp_path):
    repo = _checkout(tmp_path)
    lock = repo / "results" / "smoke" / ".lock"
    lock.parent.mkdir(parents=True)
    live = repo / "results" / "smoke" / "notebooks" / ".03_bgfn_training.running-4242.ipynb"
    live.parent.mkdir()
    live.write_text("the first run's notebook")
    with open(lock, "w") as held:
        fcntl.flock(held, fcntl.LOCK_EX | fcntl.LOCK_NB)        # the first run holds the profile's lock
        held.write("4242\n")
        held.flush()
        res = _make("reproduce", "PROFILE=smoke", cwd=repo)
    assert res.returncode != 0 and "already running (PID 4242" in res.stderr
    assert live.exists()                                        # its live files are not cleaned as debris
    assert not (repo / ".venv").exists()                        # refused before anything was made


#: PROFILE values that would run a command if a shell (or make's own $(shell ...)) ever expanded them.
PAYLOADS = ["a||touch pwned", "`touch pwned`", "x'; touch pwned2; echo '", "$(touch pwned)", "$(shell touch pwned)",
            "a;touch pwned", "a b", "-rf", "a\ntouch pwned", '"; touch pwned; "']


@pytest.mark.parametrize("goal", [["-n", "reproduce"], ["help"], ["book"]])
@pytest.mark.parametrize("payload", PAYLOADS)
def test_a_profile_with_shell_metacharacters_runs_nothing_and_is_one_error(tmp_path, payload, goal):
    repo = _checkout(tmp_path)
    before = sorted(p.relative_to(repo) for p in repo.rglob("*"))
    for how in ("command line", "environment"):
        env = {**os.environ, "PROFILE": payload} if how == "environment" else None
        res = subprocess.run(["make", "--no-print-directory", *goal, *([] if env else [f"PROFILE={payload}"])],
                             cwd=repo, capture_output=True, text=True, timeout=60, env=env)
        assert res.returncode != 0, (how, res.stdout)
        assert res.stderr.count("is not a profile name") == 1 and res.stdout == "", (how, res.stderr)
        assert sorted(p.relative_to(repo) for p in repo.rglob("*")) == before, how     # nothing created
        assert not (PROJECT_ROOT / "pwned").exists() and not (tmp_path / "pwned").exists()


def test_a_base_chain_is_followed_to_any_depth_and_a_bad_base_name_runs_nothing(tmp_path):
    repo = _checkout(tmp_path)
    (repo / "params" / "c.yaml").write_text("base: smoke   # three levels down to quick\n")
    (repo / "params" / "d.yaml").write_text("base: 'c'\n")
    res = _make("-p", "-n", "help", "PROFILE=d", cwd=repo)
    assert "PARAMS := params/d.yaml params/c.yaml params/smoke.yaml params/quick.yaml" in res.stdout, res.stderr
    (repo / "params" / "e.yaml").write_text("base: x';touch${IFS}pwned;'\n")
    res = _make("-n", "reproduce", "PROFILE=e", cwd=repo)
    assert res.returncode != 0 and "in params/e.yaml is not a profile name" in res.stderr
    assert not (repo / "pwned").exists()
    (repo / "params" / "f.yaml").write_text("base: f\n")         # a loop ends (the profile check names it)
    assert _make("-n", "help", "PROFILE=f", cwd=repo).returncode == 0


def test_jobs_and_the_scheduler_reach_python_as_text_never_as_make_code(tmp_path):
    repo = _checkout(tmp_path)
    res = _make("-n", "help", "JOBS=$(shell touch pwned)", "DASK_SCHEDULER=$(shell touch pwned)", cwd=repo)
    assert res.returncode == 0 and not (repo / "pwned").exists()
