"""How a run is spread over processes or a cluster, in words (notebooks 03, 04 and the command line)."""

from __future__ import annotations

from bgfn.parallel import JOBS_PER_CORE, Runner, machine_cores


def runner_words(runner: Runner) -> str:
    """How the runs of a :class:`bgfn.parallel.Runner` are spread, in a few words."""
    if runner.backend == "dask":
        return f"on the Dask cluster at {runner.scheduler}"
    capped = (f" ({runner.asked} asked: at most {JOBS_PER_CORE} per core of the {machine_cores()} here)"
              if runner.asked else "")
    return ("one after the other (1 job)" if runner.jobs == 1 else
            f"{runner.jobs} processes on this machine (loky)") + capped
