"""Helpers of the tests that stop runs and look for what outlived them."""

from __future__ import annotations


def alive(pid: int) -> bool:
    """The process runs (a zombie waiting for its parent to reap it has ended)."""
    try:
        with open(f"/proc/{pid}/status") as f:
            return not any(line.startswith("State:") and "Z" in line.split()[1] for line in f)
    except OSError:
        return False
