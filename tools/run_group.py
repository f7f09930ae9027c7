"""Run a command as a session and process group of its own, and reap every process of it (standard library only).

``make reproduce`` runs its inner make under this. A process a recipe leaves in the background (the numba kernels)
or a pool worker whose parent has ended is handed to this process, not to the system's init (Linux: a child
subreaper). So its CPU time is counted with the run's (``/usr/bin/time``), and none outlives the run: when the
command has ended, what is left of the group gets SIGTERM; what is still alive ``--grace-s`` later (a child in a
session of its own too, such as a notebook's kernel whose papermill was killed) gets SIGKILL; all are reaped.

    python tools/run_group.py [--grace-s 10] make -j2 _reproduce     # exit status: the command's (128 + n: signal n)

SIGTERM, SIGINT or SIGHUP to this process or its group ends the whole group, the command included.
"""
from __future__ import annotations

import ctypes
import os
import signal
import sys
import time

PR_SET_CHILD_SUBREAPER = 36     # linux/prctl.h
GRACE_S = 10.0                  # default of --grace-s: from SIGTERM to SIGKILL for what is left (s)
STOPS = (signal.SIGTERM, signal.SIGINT, signal.SIGHUP)


def _become_subreaper() -> bool:
    """Orphaned descendants are reparented to this process (Linux 3.4+); False elsewhere (they go to init)."""
    try:
        return ctypes.CDLL(None, use_errno=True).prctl(PR_SET_CHILD_SUBREAPER, 1, 0, 0, 0) == 0
    except (OSError, AttributeError):
        return False


def _wait_any() -> list[tuple[int, int]]:
    """``[(pid, wait status)]`` of the children that have ended, waiting for one first."""
    ended, flags = [], 0
    while True:
        try:
            pid, status = os.waitpid(-1, flags)
        except ChildProcessError:       # no child left
            return ended
        if pid == 0:
            return ended
        ended.append((pid, status))
        flags = os.WNOHANG


def _end_group(grace_s: float) -> None:
    """SIGTERM to every other process of this group; from ``grace_s`` on, SIGKILL twice a second to what is left of
    it and to every child of this process (reparented orphans in sessions of their own included); all reaped."""
    for s in STOPS:
        signal.signal(s, signal.SIG_IGN)
    os.killpg(0, signal.SIGTERM)
    deadline, next_kill = time.monotonic() + grace_s, 0.0
    while True:
        try:
            pid, _ = os.waitpid(-1, os.WNOHANG)
        except ChildProcessError:       # none left
            return
        if pid:
            continue
        now = time.monotonic()
        if now > deadline and now > next_kill:
            for other in _left_behind():
                try:
                    os.kill(other, signal.SIGKILL)
                except ProcessLookupError:
                    pass
            next_kill = now + 0.5
        time.sleep(0.05)


def _left_behind() -> list[int]:
    """The other processes of this process group and this process's children (from /proc)."""
    me, found = os.getpid(), []
    for entry in os.listdir("/proc"):
        if entry.isdigit() and int(entry) != me:
            try:
                with open(f"/proc/{entry}/stat") as f:
                    fields = f.read().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if int(fields[1]) == me or int(fields[2]) == me:    # ppid; pgrp (this group's id is this PID: setsid)
                found.append(int(entry))
    return found


def main(argv: list[str]) -> int:
    grace_s = GRACE_S
    if argv[:1] == ["--grace-s"] and len(argv) > 1:
        grace_s, argv = float(argv[1]), argv[2:]
    if not argv:
        print("usage: run_group.py [--grace-s SECONDS] COMMAND [ARG...]", file=sys.stderr)
        return 2
    # A stop that comes before the command is started waits (blocked) until it is, then ends it like any other.
    signal.pthread_sigmask(signal.SIG_BLOCK, STOPS)
    try:
        os.setsid()
    except PermissionError:
        print("run_group.py: already a process group leader; start it in the background (`cmd &`) or with setsid",
              file=sys.stderr)
        return 2
    _become_subreaper()
    stopping = []

    def stop(signum, _frame):       # the run stopped from outside: the whole group ends (the command included)
        if not stopping:
            stopping.append(signum)
            signal.signal(signal.SIGTERM, signal.SIG_IGN)
            os.killpg(0, signal.SIGTERM)

    for s in STOPS:
        signal.signal(s, stop)
    child = os.fork()
    if child == 0:
        # the command starts as from a shell: default dispositions (Python ignores SIGPIPE and SIGXFSZ), no signal
        # blocked (a stop sent before now was this process's, not the child's: the parent acts on it)
        for s in (*STOPS, signal.SIGPIPE, signal.SIGXFSZ):
            signal.signal(s, signal.SIG_DFL)
        signal.pthread_sigmask(signal.SIG_UNBLOCK, STOPS)
        try:
            os.execvp(argv[0], argv)
        except OSError as err:
            print(f"run_group.py: cannot run {argv[0]!r}: {err.strerror}", file=sys.stderr)
        os._exit(127)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, STOPS)
    status = None
    while status is None:
        for pid, st in _wait_any():
            if pid == child:
                status = st
    _end_group(grace_s)
    if stopping:
        return 128 + stopping[0]
    return os.waitstatus_to_exitcode(status) if os.WIFEXITED(status) else 128 + os.WTERMSIG(status)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
