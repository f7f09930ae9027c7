"""The Makefile refuses what it cannot do before it makes anything, and works from any directory."""

from __future__ import annotations

import fcntl
import os
import shutil
import subprocess
import sys

import pytest

from bgfn.config import PROJECT_ROOT
from processes import alive

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


#: Every other setting a user may pass, with the words of its error.
SETTINGS = {"VENV": "is not a path", "PYTHON": "is not a path", "PY": "is not a path", "RES": "is not a path",
            "PIP_FLAGS": "is not a list of options", "PAPERMILL_FLAGS": "is not a list of options",
            "PYTEST_ARGS": "is not a list of options", "NOTEBOOK_SLOTS": "is not a count", "CI": "is not a word"}


@pytest.mark.parametrize("setting", sorted(SETTINGS))
def test_every_setting_with_shell_metacharacters_runs_nothing_and_is_one_error(tmp_path, setting):
    repo = _checkout(tmp_path)
    before = sorted(p.relative_to(repo) for p in repo.rglob("*"))
    for payload in PAYLOADS:
        if setting.endswith(("FLAGS", "ARGS")) and payload in ("a b", "-rf"):
            continue                                  # options: words, and a word may start with '-'
        for how in ("command line", "environment"):
            env = {**os.environ, setting: payload} if how == "environment" else None
            res = subprocess.run(["make", "--no-print-directory", "-n", "reproduce", "PROFILE=smoke",
                                  *([] if env else [f"{setting}={payload}"])],
                                 cwd=repo, capture_output=True, text=True, timeout=60, env=env)
            assert res.returncode != 0, (setting, payload, how, res.stdout)
            assert res.stderr.count(f"{setting} ") == 1 and res.stderr.count(SETTINGS[setting]) == 1, res.stderr
            assert res.stdout == "", (setting, payload, how)
            assert sorted(p.relative_to(repo) for p in repo.rglob("*")) == before         # nothing created
            assert not (PROJECT_ROOT / "pwned").exists() and not (tmp_path / "pwned").exists()


def test_the_settings_take_their_documented_values_and_nothing_else_is_a_setting(tmp_path):
    repo = _checkout(tmp_path)
    ok = ["VENV=/opt/conda/envs/bgfn", "PYTHON=/usr/bin/python3.11", "NOTEBOOK_SLOTS=1", "CI=true",
          "PIP_FLAGS=--extra-index-url https://download.pytorch.org/whl/cpu",         # the README's
          "PYTEST_ARGS=-x -k walker tests/test_gallery.py::test_a[1]", "PAPERMILL_FLAGS=--log-output"]
    res = _make("-n", "help", *ok, cwd=repo)
    assert res.returncode == 0, res.stderr
    for bad, words in (("NOTEBOOK_SLOTS=0", "is not a count"), ("NOTEBOOK_SLOTS=100", "is not a count"),
                       ("DATA_FETCH=touch pwned", "DATA_FETCH is not a setting"), ("LOCK=x", "LOCK is not a setting")):
        res = _make("-n", "reproduce", "PROFILE=smoke", bad, cwd=repo)
        assert res.returncode != 0 and res.stderr.count(words) == 1 and res.stdout == "", (bad, res.stderr)
    assert not (repo / "pwned").exists()


def test_jobs_and_the_scheduler_reach_python_as_text_never_as_make_code(tmp_path):
    repo = _checkout(tmp_path)
    res = _make("-n", "help", "JOBS=$(shell touch pwned)", "DASK_SCHEDULER=$(shell touch pwned)", cwd=repo)
    assert res.returncode != 0 and not (repo / "pwned").exists()
    assert 'JOBS "$(shell touch pwned)" is not a value of options\' characters' in res.stderr
    # a backquote would reach the notebook recipe's shell through MAKEFLAGS: refused by make itself, nothing run
    res = _make("-n", "help", "DASK_SCHEDULER=`touch pwned`", cwd=repo)
    assert res.returncode != 0 and "DASK_SCHEDULER" in res.stderr and not (repo / "pwned").exists()
    assert _make("-n", "help", "JOBS=2", "DASK_SCHEDULER=tcp://10.0.0.5:8786", cwd=repo).returncode == 0




def _fake_run(tmp_path, papermill="exec sleep 300", keys="exit 0", kernels="exec sleep 300"):
    """A checkout whose venv is a stand-in: its python passes every step (``keys``: the profile's key check), runs
    ``kernels`` as the kernels job (a long sleep) and papermill runs ``papermill``; each writes its PID under
    ``marks/``."""
    import hashlib

    repo = _checkout(tmp_path)
    for folder in ("notebooks", "tools", "data/paper"):
        shutil.copytree(PROJECT_ROOT / folder, repo / folder, ignore=shutil.ignore_patterns("*.ipynb_checkpoints"))
    marks = tmp_path / "marks"
    marks.mkdir()
    bin_ = repo / ".venv" / "bin"
    bin_.mkdir(parents=True)
    (bin_ / "python").write_text(f"""#!/bin/bash
case "$*" in
  *run_group.py*) exec {sys.executable} "$@";;
  *"profile_schema --keys"*) {keys};;
  *"bgfn kernels"*) echo $$ > {marks}/kernels.pid; {kernels};;
  *build_book*) mkdir -p book/_build && echo $$ > {marks}/book.pid; echo "${{BGFN_BOOK_PASS:-every page}}" >> {marks}/book.passes;;
  *execution_count*) exec {sys.executable} "$@";;
esac
exit 0
""")
    (bin_ / "papermill").write_text(f"#!/bin/bash\necho $$ > {marks}/papermill.pid\n{papermill}\n")
    for exe in bin_.iterdir():
        exe.chmod(0o755)
    lock_hash = hashlib.sha256((repo / "requirements.lock").read_bytes()).hexdigest()[:16]
    (repo / ".venv" / f".installed-{lock_hash}").touch()
    config = repo / ".venv" / "etc" / "ipython" / "ipython_kernel_config.py"
    config.parent.mkdir(parents=True)
    shutil.copy(repo / "tools" / "ipython_kernel_config.py", config)
    return repo, marks


def test_the_books_build_keeps_the_code_pages_only_from_this_profiles_build_of_the_same_files(tmp_path):
    import time

    repo, marks = _fake_run(tmp_path)
    (repo / "src" / "bgfn").mkdir(parents=True)
    (repo / "src" / "bgfn" / "nav.py").write_text("")
    for profile in ("smoke", "quick"):
        executed = repo / "results" / profile / "notebooks"
        executed.mkdir(parents=True)
        for nb in (repo / "notebooks").glob("[01][0-9]_*.ipynb"):
            if nb.stem != "11_fleet":
                (executed / nb.name).write_text("{}")

    def build(profile="smoke"):
        time.sleep(0.05)                                # a file changed after a build is newer than its stamp
        res = _make("_book-build", f"PROFILE={profile}", cwd=repo)
        assert res.returncode == 0, res.stderr
        return (marks / "book.passes").read_text().splitlines()[-1]

    assert build() == "every page"                      # book/_build holds no build yet
    assert build() == "pages"                           # this profile's, nothing changed: the code pages kept
    assert build("quick") == "every page" and build() == "every page"   # another profile's build in between
    (repo / "src" / "bgfn" / "nav.py").write_text("# edited")
    assert build() == "every page" and build() == "pages"
    (repo / "src" / "bgfn" / "new.py").write_text("")                     # added: its page is missing
    assert build() == "every page"
    (repo / "src" / "bgfn" / "new.py").unlink()                           # removed: its page would stay
    assert build() == "every page" and build() == "pages"
    (repo / "notebooks" / "01_data_prep.ipynb").touch()                   # a title every page shows may change
    assert build() == "every page"
    assert (repo / "book" / "_build" / ".env-smoke").is_file() and not (repo / "book" / "_build" / ".env-quick").exists()
    assert (repo / "results" / "smoke" / "logs" / ".book-draft").is_file()   # a built book needs no draft


def _gone(pid: int, timeout: float = 10.0) -> None:
    import time

    deadline = time.monotonic() + timeout
    while alive(pid) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert not alive(pid), f"process {pid} outlived its run"


def _wait_for(path, timeout=60.0):
    import time

    deadline = time.monotonic() + timeout
    while not (path.is_file() and path.read_text().strip()):
        assert time.monotonic() < deadline, f"{path.name} never appeared"
        time.sleep(0.1)
    return int(path.read_text())


@pytest.mark.parametrize("sig", ["SIGTERM", "SIGINT"])
def test_a_stopped_run_ends_every_process_it_started_and_releases_its_lock(tmp_path, sig):
    import signal
    import time

    repo, marks = _fake_run(tmp_path)
    # Ctrl-C as a terminal sends it: a make started from a shell's background job (`make test &`, nohup) would
    # inherit SIGINT ignored, and neither make nor bash can catch a signal ignored when they start
    make = subprocess.Popen(["make", "--no-print-directory", "reproduce", "PROFILE=smoke"], cwd=repo,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, start_new_session=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    try:
        pids = [_wait_for(marks / "papermill.pid"), _wait_for(marks / "kernels.pid")]
        lock = repo / "results" / "smoke" / ".lock"
        assert lock.read_text().strip() and all(alive(p) for p in pids)
        # Ctrl-C reaches the terminal's foreground group (make and its recipe shells); `kill` reaches make alone
        os.killpg(make.pid, signal.SIGINT) if sig == "SIGINT" else make.send_signal(signal.SIGTERM)
        make.wait(timeout=30)
        deadline = time.monotonic() + 10
        while any(alive(p) for p in pids) and time.monotonic() < deadline:
            time.sleep(0.1)
        assert not any(alive(p) for p in pids), make.stdout.read()
        with open(lock, "a") as f:                     # the lock is free at once, and names no PID
            fcntl.flock(f, fcntl.LOCK_EX | fcntl.LOCK_NB)
        assert lock.read_text() == ""
    finally:
        if make.poll() is None:
            os.killpg(make.pid, signal.SIGKILL)


def test_a_lock_left_by_a_killed_run_is_taken_over_with_one_line(tmp_path):
    repo, marks = _fake_run(tmp_path, papermill="exit 1")
    lock = repo / "results" / "smoke" / ".lock"
    lock.parent.mkdir(parents=True)
    lock.write_text("999999\n")                       # a run killed with SIGKILL: its PID stays, its lock does not
    res = _make("reproduce", "PROFILE=smoke", cwd=repo)
    assert res.returncode != 0 and "already running" not in res.stderr        # papermill's stand-in failed
    assert res.stdout.count("named PID 999999") == 1 and "taken over" in res.stdout
    assert lock.read_text() == ""
    if (marks / "kernels.pid").exists():                # the run's background job ended with it
        _gone(_wait_for(marks / "kernels.pid"))


def test_a_bad_profile_fails_before_anything_and_leaves_nothing(tmp_path):
    repo, marks = _fake_run(tmp_path, keys="echo 'error: profile smoke: a bad key' >&2; exit 2")
    res = _make("reproduce", "PROFILE=smoke", cwd=repo)
    assert res.returncode != 0 and res.stderr.count("a bad key") == 1
    assert not (repo / "results").exists() and list(marks.iterdir()) == []   # no lock, no log, no job, no data step


def test_clean_debris_never_touches_a_live_run(tmp_path):
    repo = _checkout(tmp_path)
    res_dir = repo / "results" / "smoke"
    live = res_dir / "notebooks" / ".03_bgfn_training.running-4242.ipynb"
    live.parent.mkdir(parents=True)
    live.write_text("the live run's notebook")
    with open(res_dir / ".lock", "w") as held:
        fcntl.flock(held, fcntl.LOCK_EX | fcntl.LOCK_NB)
        held.write("4242\n")
        held.flush()
        res = _make("clean-debris", "PROFILE=smoke", cwd=repo)
        assert res.returncode != 0 and "is live (PID 4242" in res.stderr and live.exists()
        env = {**os.environ, "BGFN_RUN_LOCK": "4242"}                 # the run itself cleans its own debris
        res = subprocess.run(["make", "clean-debris", "PROFILE=smoke"], cwd=repo, capture_output=True, text=True,
                             env=env, timeout=60)
        assert res.returncode == 0 and not live.exists()


def test_the_advice_for_a_corrupt_checkpoint_reruns_the_notebook_that_trains_it_and_what_follows(tmp_path,
                                                                                                 monkeypatch):
    import time

    from bgfn import config
    from bgfn.errors import DataError
    from bgfn.train import checkpoints as ck

    repo, _ = _fake_run(tmp_path)
    monkeypatch.setattr(config, "PROJECT_ROOT", repo)
    monkeypatch.setattr(config, "RESULTS_ROOT", repo / "results")
    res_dir = repo / "results" / "smoke"
    (res_dir / "notebooks").mkdir(parents=True)
    time.sleep(0.05)
    for stamp in (".profile-checked", ".data-fingerprint"):       # a finished run: checked, then every notebook
        (res_dir / stamp).touch()
    for nb in sorted((repo / "notebooks").glob("*.ipynb")):
        time.sleep(0.02)
        (res_dir / "notebooks" / nb.name).write_text("{}")
    args = ["-n", "_notebooks", "PROFILE=smoke", f"-o{res_dir.relative_to(repo)}/.data-fingerprint"]
    assert "papermill" not in _make(*args, cwd=repo).stdout              # nothing to redo
    path = ck.checkpoint_path("smoke", "rtklib-drive0708", "bgfn", 0)
    path.write_bytes(b"truncated")
    with pytest.raises(DataError) as err:
        ck.read_checkpoint(path)
    advice = str(err.value).split("`")[1]
    assert advice.startswith("rm -f results/smoke/models/") and advice.endswith("make reproduce PROFILE=smoke")
    subprocess.run(advice.split(" && ")[0], shell=True, cwd=repo, check=True)
    out = _make(*args, cwd=repo).stdout
    reruns = [nb for nb in sorted(p.stem for p in (repo / "notebooks").glob("*.ipynb")) if f"notebooks/{nb}.ipynb\"" in out]
    assert reruns[0] == "03_bgfn_training" and "04_outage_evaluation" in reruns and not path.exists()


def test_a_notebook_runs_with_sleeping_openmp_threads_unless_the_environment_says_otherwise(tmp_path):
    marks = tmp_path / "marks"
    repo, _ = _fake_run(tmp_path, papermill=f'echo "${{OMP_WAIT_POLICY:-unset}}" >> {marks}/omp; exit 1')
    for value, expected in ((None, "PASSIVE"), ("ACTIVE", "ACTIVE")):
        env = {k: v for k, v in os.environ.items() if k != "OMP_WAIT_POLICY"}
        env |= {"OMP_WAIT_POLICY": value} if value else {}
        res = subprocess.run(["make", "--no-print-directory", "reproduce", "PROFILE=smoke"], cwd=repo, env=env,
                             capture_output=True, text=True, timeout=120)
        assert res.returncode != 0                          # papermill's stand-in failed, after saying what it saw
        assert (marks / "omp").read_text().split()[-1] == expected


@pytest.mark.parametrize("finished", [True, False])
def test_the_kernels_are_started_again_unless_they_finished(tmp_path, finished):
    import time

    repo, marks = _fake_run(tmp_path, papermill="exit 1", kernels="exit 0" if finished else "exec sleep 300")
    stamp = repo / "results" / "smoke" / "logs" / ".kernels-compiled"
    res = _make("reproduce", "PROFILE=smoke", cwd=repo)             # papermill's stand-in fails: the run ends
    _gone(_wait_for(marks / "kernels.pid"))
    time.sleep(0.5)
    assert res.returncode != 0 and stamp.exists() == finished
    dry = _make("-n", "_notebooks", "PROFILE=smoke", cwd=repo).stdout
    assert ("bgfn kernels" in dry) == (not finished)         # a run that ended before they did starts them again


@pytest.mark.parametrize("ran_a_cell", [False, True])
def test_a_kernel_that_never_started_is_started_once_more(tmp_path, ran_a_cell):
    marks = tmp_path / "marks"
    count = 1 if ran_a_cell else "null"
    repo, _ = _fake_run(tmp_path, papermill=f"""echo x >> {marks}/tries
echo '{{"cells": [{{"cell_type": "code", "execution_count": {count}}}]}}' > "$2"; exit 1""")
    res = subprocess.run(["make", "--no-print-directory", "reproduce", "PROFILE=smoke"], cwd=repo,
                         capture_output=True, text=True, timeout=120)
    tries = len((marks / "tries").read_text().split())
    assert res.returncode != 0 and tries == (1 if ran_a_cell else 2)      # once more only when no cell ran
    assert ("its kernel did not start" in res.stdout) == (not ran_a_cell)


def test_the_book_is_built_on_every_core_and_a_failed_build_fails(tmp_path, monkeypatch):
    import runpy

    import jupyter_book.sphinx

    for name in ("_config.yml", "_toc.yml"):
        (tmp_path / "book").mkdir(exist_ok=True)
        shutil.copy(PROJECT_ROOT / "book" / name, tmp_path / "book" / name)
    jobs = []
    monkeypatch.setattr(jupyter_book.sphinx, "build_sphinx", lambda *a, **kw: jobs.append(kw.get("jobs")) or 1)
    monkeypatch.setattr(sys, "argv", ["build_book.py", str(tmp_path / "book"), "--all", "-W", "-n", "--keep-going"])
    with pytest.raises(SystemExit) as ended:
        runpy.run_path(str(PROJECT_ROOT / "tools" / "build_book.py"), run_name="__main__")
    assert ended.value.code == 1 and jobs == [len(os.sched_getaffinity(0))]


def test_two_book_builds_at_once_take_turns(tmp_path):
    import time

    repo, marks = _fake_run(tmp_path)
    (repo / "results" / "smoke" / "notebooks").mkdir(parents=True)
    for nb in (repo / "notebooks").glob("*.ipynb"):
        (repo / "results" / "smoke" / "notebooks" / nb.name).write_text("{}")
    with open(repo / "results" / ".book.lock", "a") as held:        # another profile's book build is running
        fcntl.flock(held, fcntl.LOCK_EX | fcntl.LOCK_NB)
        make = subprocess.Popen(["make", "--no-print-directory", "book", "PROFILE=smoke"], cwd=repo,
                                stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        time.sleep(3)
        assert make.poll() is None and not (marks / "book.pid").exists()    # it waits, touching nothing of book/
    out, _ = make.communicate(timeout=60)
    assert make.returncode == 0, out
    assert out.count("waiting for it") == 1 and (marks / "book.pid").exists()
