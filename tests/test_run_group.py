"""tools/run_group.py: the run's group reaps its orphans (their CPU time counts with the run's) and ends with it."""

import os
import subprocess
import sys
import time

from bgfn.config import PROJECT_ROOT

RUN_GROUP = str(PROJECT_ROOT / "tools" / "run_group.py")
BURN = "import time\nt = time.process_time()\nwhile time.process_time() - t < 0.6: pass\n"


def _run(script: str, tmp_path) -> tuple[int, float, float]:
    """Run ``bash -c script`` under run_group.py; (exit status, its children's CPU seconds, wall seconds)."""
    t0 = time.monotonic()
    proc = subprocess.Popen([sys.executable, RUN_GROUP, "bash", "-c", script], cwd=tmp_path)
    _, status, usage = os.wait4(proc.pid, 0)
    proc.returncode = os.waitstatus_to_exitcode(status)
    return proc.returncode, usage.ru_utime + usage.ru_stime, time.monotonic() - t0


def test_a_background_job_that_outlives_its_shell_is_counted_with_the_run(tmp_path):
    # the subshell exits at once; its background job (orphaned, like the numba kernels' job) burns 0.6 CPU s and
    # ends while the command still runs: reaped by the run, not by init
    (tmp_path / "burn.py").write_text(BURN)
    rc, cpu, _ = _run(f"( {sys.executable} burn.py & ); sleep 2", tmp_path)
    assert rc == 0
    assert cpu >= 0.5, f"the orphan's CPU time was not counted: {cpu:.2f} s"


def test_what_is_left_of_the_group_ends_with_the_command_and_its_status_is_kept(tmp_path):
    # a sleeper and one that ignores SIGTERM (killed after the grace period), both orphaned; the command fails
    script = (f"( sleep 300 & echo $! > sleeper.pid ); "
              f"( {sys.executable} -c 'import signal, time; signal.signal(signal.SIGTERM, signal.SIG_IGN); "
              f"open(\"stubborn.pid\", \"w\").write(str(__import__(\"os\").getpid())); time.sleep(300)' & ); "
              f"while [ ! -s stubborn.pid ]; do sleep 0.05; done; exit 3")
    rc, _, wall = _run(script, tmp_path)
    assert rc == 3
    assert wall < 30
    for name in ("sleeper.pid", "stubborn.pid"):
        pid = int((tmp_path / name).read_text())
        assert not os.path.exists(f"/proc/{pid}"), f"{name[:-4]} outlived the run"
