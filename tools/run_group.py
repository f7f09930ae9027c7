"""Run a command as a session and process group of its own, and reap every process of it (standard library only).

``make reproduce`` runs its inner make under this. A process a recipe leaves in the background (the numba kernels)
or a pool worker whose parent has ended is handed to this process, not to the system's init (Linux: a child
subreaper). So its CPU time is counted with the run's (``/usr/bin/time``), and none outlives the run: when the
command has ended, what is left of the group gets SIGTERM (then SIGKILL, after ``GRACE_S``) and is reaped.

    python tools/run_group.py make -j2 _reproduce     # exit status: the command's (128 + n: ended by signal n)
"""
from __future__ import annotations

import ctypes
import os
import signal
import sys
import time

PR_SET_CHILD_SUBREAPER = 36     # linux/prctl.h
GRACE_S = 10.0                  # what is left of the group after SIGTERM gets SIGKILL after this long (s)


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


def _end_group() -> None:
    """SIGTERM to every other process of this group, SIGKILL to those alive ``GRACE_S`` later; all reaped."""
    signal.signal(signal.SIGTERM, signal.SIG_IGN)
    os.killpg(0, signal.SIGTERM)
    deadline, killed = time.monotonic() + GRACE_S, False
    while True:
        try:
            pid, _ = os.waitpid(-1, os.WNOHANG)
        except ChildProcessError:       # none left
            return
        if pid:
            continue
        if not killed and time.monotonic() > deadline:
            for other in _group_members():
                try:
                    os.kill(other, signal.SIGKILL)
                except ProcessLookupError:
                    pass
            killed = True
        time.sleep(0.05)


def _group_members() -> list[int]:
    """The other processes of this process group (from /proc)."""
    me, members = os.getpid(), []
    for entry in os.listdir("/proc"):
        if entry.isdigit() and int(entry) != me:
            try:
                with open(f"/proc/{entry}/stat") as f:
                    fields = f.read().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if int(fields[2]) == me:        # pgrp: this group's id is this process's PID (setsid)
                members.append(int(entry))
    return members


def main(argv: list[str]) -> int:
    if not argv:
        print("usage: run_group.py COMMAND [ARG...]", file=sys.stderr)
        return 2
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

    for s in (signal.SIGTERM, signal.SIGINT, signal.SIGHUP):
        signal.signal(s, stop)
    child = os.fork()
    if child == 0:
        for s in (signal.SIGTERM, signal.SIGINT, signal.SIGHUP):
            signal.signal(s, signal.SIG_DFL)
        try:
            os.execvp(argv[0], argv)
        finally:
            os._exit(127)
    status = None
    while status is None:
        for pid, st in _wait_any():
            if pid == child:
                status = st
    _end_group()
    if stopping:
        return 128 + stopping[0]
    return os.waitstatus_to_exitcode(status) if os.WIFEXITED(status) else 128 + os.WTERMSIG(status)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
