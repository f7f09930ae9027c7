"""tools/run_group.py: the run's group reaps its orphans (their CPU time counts with the run's) and ends with it."""

import os
import signal
import subprocess
import sys
import time

import pytest

from bgfn.config import PROJECT_ROOT

RUN_GROUP = str(PROJECT_ROOT / "tools" / "run_group.py")
BURN = ("import time\nt = time.process_time()\nwhile time.process_time() - t < 0.6: pass\n"
        "open('burnt', 'w').write('done')\n")
# a shell loop that waits for a file, at most a minute (a failed start fails the test instead of hanging it)
WAIT_FOR = "for i in $(seq 1200); do [ -s {0} ] && break; sleep 0.05; done; "


def _run(script: str, tmp_path) -> tuple[int, float, float]:
    """Run ``bash -c script`` under run_group.py (1 s from SIGTERM to SIGKILL); (exit status, its children's CPU
    seconds, wall seconds)."""
    t0 = time.monotonic()
    proc = subprocess.Popen([sys.executable, RUN_GROUP, "--grace-s", "1", "bash", "-c", script], cwd=tmp_path)
    while True:                     # at most two minutes: a run_group that never ends fails the test, not the suite
        pid, status, usage = os.wait4(proc.pid, os.WNOHANG)
        if pid:
            break
        if time.monotonic() - t0 > 120:
            _kill_group(proc.pid)
            pytest.fail("run_group.py did not end")
        time.sleep(0.05)
    proc.returncode = os.waitstatus_to_exitcode(status)
    return proc.returncode, usage.ru_utime + usage.ru_stime, time.monotonic() - t0


def _kill_group(pgid: int) -> None:
    try:
        os.killpg(pgid, signal.SIGKILL)     # run_group.py's group is its PID (setsid)
    except ProcessLookupError:
        pass


def test_a_background_job_that_outlives_its_shell_is_counted_with_the_run(tmp_path):
    # the subshell exits at once; its background job (orphaned, like the numba kernels' job) burns 0.6 CPU s and
    # ends while the command still runs: reaped by the run, not by init
    (tmp_path / "burn.py").write_text(BURN)
    rc, cpu, _ = _run(f"( {sys.executable} burn.py & ); " + WAIT_FOR.format("burnt") + "sleep 0.2", tmp_path)
    assert rc == 0
    assert cpu >= 0.5, f"the orphan's CPU time was not counted: {cpu:.2f} s"


def test_what_is_left_of_the_group_ends_with_the_command_and_its_status_is_kept(tmp_path):
    # orphans: a sleeper, one in a session of its own (as a notebook's kernel is) and one that ignores SIGTERM (both
    # killed after the grace period); the command fails
    script = (f"( sleep 300 & echo $! > sleeper.pid ); ( setsid sleep 300 & echo $! > session.pid ); "
              f"( {sys.executable} -c 'import signal, time; signal.signal(signal.SIGTERM, signal.SIG_IGN); "
              f"open(\"stubborn.pid\", \"w\").write(str(__import__(\"os\").getpid())); time.sleep(300)' & ); "
              + WAIT_FOR.format("stubborn.pid") + "exit 3")
    rc, _, wall = _run(script, tmp_path)
    assert rc == 3
    assert wall < 60
    for name in ("sleeper.pid", "session.pid", "stubborn.pid"):
        pid = int((tmp_path / name).read_text())
        assert not os.path.exists(f"/proc/{pid}"), f"{name[:-4]} outlived the run"


def test_a_stopped_run_ends_its_command_and_says_so(tmp_path):
    proc = subprocess.Popen([sys.executable, RUN_GROUP, "--grace-s", "1", "bash", "-c",
                             "echo $$ > shell.pid; sleep 300"], cwd=tmp_path)
    deadline = time.monotonic() + 60
    try:
        while not (tmp_path / "shell.pid").is_file() or not (tmp_path / "shell.pid").read_text().strip():
            assert time.monotonic() < deadline and proc.poll() is None
            time.sleep(0.05)
        os.kill(proc.pid, signal.SIGTERM)       # make's recipe stops the run so
        assert proc.wait(timeout=30) == 128 + signal.SIGTERM
        assert not os.path.exists(f"/proc/{int((tmp_path / 'shell.pid').read_text())}")
    finally:
        if proc.poll() is None:
            _kill_group(proc.pid)
            proc.wait()
