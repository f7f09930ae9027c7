"""How a run is spread over processes or a cluster, in words (notebooks 03, 04 and the command line)."""

from __future__ import annotations

from bgfn.parallel import Runner


def runner_words(runner: Runner) -> str:
    """How the runs of a :class:`bgfn.parallel.Runner` are spread, in a few words."""
    if runner.backend == "dask":
        return f"on the Dask cluster at {runner.scheduler}"
    return "one after the other (1 job)" if runner.jobs == 1 else f"{runner.jobs} processes on this machine (loky)"
