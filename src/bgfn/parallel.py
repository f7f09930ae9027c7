"""Independent runs side by side: one runner for every loop whose items do not depend on each other.

A training run ``(dataset, method, seed)``, a sweep run, an oracle run are independent. :class:`Runner` hands them to
joblib and gives the results back in the order of the tasks, and each run seeds itself and sets its own torch
thread count, so the tables are the same with 1 job, with 2 and on a cluster. Where they go is the profile's
``parallel:`` section (``JOBS=`` and ``DASK_SCHEDULER=`` on the make command line win): one after the other, a
loky process pool, or a ``dask.distributed`` cluster sharing the checkout's path. :class:`RunProgress` shows a bar
and one line per finished run, to ``BGFN_PROGRESS_LOG`` under ``make reproduce``.
"""

from __future__ import annotations

import importlib
import os
import re
import sys
import tempfile
import threading
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Iterable, Sequence

from joblib import Parallel, delayed, parallel_config
from joblib.externals.loky import process_executor
from tqdm import tqdm

from bgfn import settings
from bgfn.errors import DataError

#: The ``parallel:`` section's keys and defaults (jobs null: the cores of this machine).
PARALLEL_DEFAULTS: dict[str, Any] = settings.defaults("parallel")   # their home: bgfn.settings.Parallel
#: The backends :class:`Runner` knows.
BACKENDS = ("loky", "dask")
#: Environment variables that override the profile (make passes ``JOBS=`` / ``DASK_SCHEDULER=`` as these).
JOBS_ENV, SCHEDULER_ENV, PROGRESS_ENV = "BGFN_JOBS", "DASK_SCHEDULER", "BGFN_PROGRESS_LOG"
#: Runs at a time on this machine at most, per core: more only queue for the cores, each a Python holding torch
#: (hundreds of MB). A larger ``jobs`` is capped to this and says so (:meth:`Runner.describe`).
JOBS_PER_CORE = 4
#: A Dask scheduler's address: ``tcp://host:port`` (or ``tls://``), or ``host:port``.
SCHEDULER_ADDRESS = re.compile(r"^(?:(?:tcp|tls)://)?[A-Za-z0-9._\[\]:-]+:\d{1,5}$")
#: Pools being started in the background (:meth:`Runner.start`); the next :meth:`Runner.map` waits for them.
_STARTING: list[threading.Thread] = []


def machine_cores() -> int:
    """The CPU cores this process may use (its affinity set where the OS says, else ``os.cpu_count()``)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:            # not on Linux
        return max(1, os.cpu_count() or 1)


@dataclass(frozen=True)
class Runner:
    """Where independent runs go: ``jobs`` processes of ``backend`` (``scheduler``: a Dask scheduler's address).

    Build it from a profile with :meth:`of`; :meth:`map` runs the tasks.
    """

    jobs: int = 1
    backend: str = "loky"
    scheduler: str | None = None
    asked: int | None = None        # the jobs asked for, when more than this machine takes (capped to ``jobs``)

    @classmethod
    def of(cls, cfg: dict | None = None, environ: dict | None = None) -> "Runner":
        """The runner of a profile's ``parallel:`` section, with ``BGFN_JOBS`` / ``DASK_SCHEDULER`` of
        ``environ`` (default ``os.environ``) over it. A Dask scheduler address selects the Dask backend."""
        env = os.environ if environ is None else environ
        sec = {**PARALLEL_DEFAULTS, **((cfg or {}).get("parallel") or {})}
        jobs, backend, scheduler = sec["jobs"], sec["backend"], sec["scheduler"]
        if env.get(JOBS_ENV, "").strip():
            jobs = _env_jobs(env[JOBS_ENV])
        if env.get(SCHEDULER_ENV, "").strip():
            backend, scheduler = "dask", env[SCHEDULER_ENV].strip()
        if backend not in BACKENDS:
            raise DataError("parallel", "backend", f"one of {', '.join(BACKENDS)}", repr(backend))
        if backend == "dask" and not scheduler:
            raise DataError("parallel", "scheduler", "a Dask scheduler address (tcp://host:port) with backend dask "
                            f"(or {SCHEDULER_ENV}=...)", repr(scheduler))
        if backend == "dask" and not SCHEDULER_ADDRESS.match(str(scheduler)):
            raise DataError(*((SCHEDULER_ENV, "address") if env.get(SCHEDULER_ENV, "").strip() else
                              ("parallel", "scheduler")), "a Dask scheduler address tcp://host:port or host:port "
                            "(e.g. tcp://10.0.0.5:8786)", repr(scheduler))
        jobs = int(jobs) if jobs is not None else machine_cores()
        most = JOBS_PER_CORE * machine_cores()
        return cls(min(jobs, most), backend, scheduler, jobs if jobs > most and backend == "loky" else None)

    def start(self, *modules: str) -> "Runner":
        """Start the pool's worker processes now, in the background, each importing ``modules`` (those whose
        functions the runs call, e.g. ``"bgfn.train"``); returns the runner.

        A worker is a fresh Python that imports torch and the package before its first run: about 10 s on the
        2-core machine, in every notebook. Started here, at the top of a notebook, that overlaps the notebook's
        serial work (loading drives, the GPS-aided filter) instead of delaying its first :meth:`map`, which waits
        for the start to finish and then uses the same workers. Nothing else changes (the runs, their seeds and
        results). With one job or on a Dask cluster (its workers are already running) it does nothing.
        """
        if self.backend == "loky" and self.jobs > 1:
            thread = threading.Thread(target=_start_workers, args=(self.jobs, modules), daemon=True,
                                      name="bgfn-runner-start")
            thread.start()
            _STARTING.append(thread)
        return self

    def map(self, fn: Callable, tasks: Sequence[tuple], labels: Sequence[str] | None = None,
            summary: Callable[[Any], str] | None = None, desc: str = "runs", echo: Callable[[str], Any] | None = None,
            bar: bool = True, cost: Sequence[float] | None = None) -> list:
        """``[fn(*task) for task in tasks]``, the tasks spread over the runner's jobs; results in task order.

        Parameters
        ----------
        fn : callable
            A module-level function (the pool pickles it by name).
        tasks : sequence of tuple
            The positional arguments of each run.
        labels : sequence of str, optional
            What each run is, for its progress line (default ``<desc> <i>``).
        summary : callable, optional
            ``summary(result)`` -> what a finished run reports in its line (epochs, best loss, ...).
        desc : str
            The bar's and the lines' name of the loop.
        echo : callable, optional
            Where the lines go without ``BGFN_PROGRESS_LOG`` (default: printed above the bar).
        bar : bool
            Show a tqdm bar over the runs.
        cost : sequence of float, optional
            Each task's expected cost, in any unit: with more than one job the pool gets the costliest first
            (:func:`dispatch_order`), so that no long run starts last while the other jobs idle. Only the order
            in which the runs start changes; their results, and their order here, do not.
        """
        tasks = list(tasks)
        labels = list(labels) if labels is not None else [f"{desc} {i + 1}" for i in range(len(tasks))]
        progress = RunProgress(len(tasks), desc, echo=echo, bar=bar)
        results: list = [None] * len(tasks)
        try:
            for i, result, seconds in self._unordered(fn, tasks, cost):
                results[i] = result
                progress.done(labels[i], seconds, summary(result) if summary is not None else "")
        finally:
            progress.close()
        return results

    def _unordered(self, fn: Callable, tasks: list[tuple], cost: Sequence[float] | None = None
                   ) -> Iterable[tuple[int, Any, float]]:
        """``(index, result, seconds)`` of every task as it finishes."""
        if not tasks:
            return
        if self.backend == "loky" and (self.jobs == 1 or len(tasks) == 1):
            for i, task in enumerate(tasks):        # in this process: nothing to pickle, the same numbers
                yield _timed(i, fn, task)
            return
        order = dispatch_order(cost, len(tasks))
        jobs = min(self.jobs, len(tasks)) if self.backend == "loky" else -1
        config = ({"backend": "dask", "scheduler_host": self.scheduler} if self.backend == "dask"
                  else LOKY_CONFIG)
        while _STARTING:                            # workers that start() is starting: wait, then reuse them
            _STARTING.pop().join()
        owner = os.getpid() if self.backend == "loky" else None      # a Dask worker is no child of ours
        with parallel_config(**config):
            yield from Parallel(n_jobs=jobs, return_as="generator_unordered")(
                delayed(_timed)(i, fn, tasks[i], owner) for i in order)


#: joblib's settings of the local pool (one thread per worker: each run sets its own torch threads). The same in
#: :meth:`Runner.start` and :meth:`Runner.map`, so that the pool started by the one is reused by the other.
LOKY_CONFIG: dict[str, Any] = {"backend": "loky", "inner_max_num_threads": 1}


def _start_workers(jobs: int, modules: Sequence[str]) -> None:
    """Start ``jobs`` loky workers, each importing ``modules`` (:meth:`Runner.start`, in a background thread).
    A failure is left to the first :meth:`Runner.map`, which meets it again and raises it there."""
    try:
        with tempfile.TemporaryDirectory(prefix="bgfn-start-") as rendezvous, parallel_config(**LOKY_CONFIG):
            Parallel(n_jobs=jobs)(delayed(_import_modules)(modules, rendezvous, jobs, os.getpid())
                                  for _ in range(jobs))
    except Exception:       # noqa: BLE001 -- only a head start: the map raises whatever went wrong, in its place
        pass


#: How long a start task waits for the pool's other workers to take theirs, at most, s.
START_WAIT_S = 60.0


def _import_modules(modules: Sequence[str], rendezvous: str, jobs: int, owner: int | None = None) -> int:
    """Import ``modules`` in a worker (what its runs will need), then wait until ``jobs`` workers have checked in
    to the folder ``rendezvous`` (at most :data:`START_WAIT_S`), so that no worker takes two of the start tasks
    while another is still starting; its process id comes back."""
    watch_owner(owner)
    for name in modules:
        importlib.import_module(name)
    # loky takes a worker's memory after its first task as its reference and replaces the worker once it has grown
    # by 300 MB (a guard against leaking tasks). After this start task the reference is the bare imports, and the
    # drive, filter context and networks that a run holds on purpose would pass the mark: the worker would be
    # replaced in the middle of a map (a warning in the notebook and a new worker's start). So the guard is off in
    # the workers started here; a worker loky starts later takes its reference after a real run, as before.
    process_executor._USE_PSUTIL = False
    pid = os.getpid()
    Path(rendezvous, str(pid)).touch()
    deadline = time.monotonic() + START_WAIT_S
    while len(os.listdir(rendezvous)) < jobs and time.monotonic() < deadline:
        time.sleep(0.05)
    return pid


def dispatch_order(cost: Sequence[float] | None, n: int) -> list[int]:
    """The order in which a pool starts ``n`` tasks: the costliest first (longest-processing-time first, ties in
    task order), or the task order without ``cost``. A pool that takes the next task whenever a job frees up then
    ends its last runs close together instead of waiting for one long run that started last."""
    if cost is None:
        return list(range(n))
    cost = list(cost)
    if len(cost) != n:
        raise ValueError(f"cost has {len(cost)} entries for {n} tasks")
    return sorted(range(n), key=lambda i: -float(cost[i]))


def _timed(i: int, fn: Callable, task: tuple, owner: int | None = None) -> tuple[int, Any, float]:
    """Run one task where the pool put it; its index and wall time come back with its result. In a worker of a
    local pool, the first task starts :func:`watch_owner` (``owner``: the process that runs the map)."""
    watch_owner(owner)
    t0 = time.perf_counter()
    result = fn(*task)
    return i, result, time.perf_counter() - t0


#: How often a pool worker checks that the process that started it is still there, s.
OWNER_POLL_S = 0.5
_WATCHING: list[int] = []


def watch_owner(owner: int | None) -> None:
    """In a local pool's worker: a daemon thread that ends this process once its parent is no longer ``owner`` (the
    notebook's kernel or the command that runs the map), so that a kernel killed with SIGKILL, or a make stopped
    with SIGTERM, leaves no worker behind (the kernel's children are reparented; loky's workers would wait for
    tasks for minutes, each holding torch). Once per process; nothing in ``owner`` itself or without one.

    Not ``prctl(PR_SET_PDEATHSIG)``: its signal comes when the *thread* that started the worker ends, and
    :meth:`Runner.start` starts the pool from a thread that ends at once.
    """
    if owner is None or owner == os.getpid() or _WATCHING:
        return
    _WATCHING.append(owner)

    def watch() -> None:
        while os.getppid() == owner:
            time.sleep(OWNER_POLL_S)
        os._exit(1)         # the owner is gone: nothing waits for this worker's results

    threading.Thread(target=watch, daemon=True, name="bgfn-owner-watch").start()


def _env_jobs(text: str) -> int:
    """``BGFN_JOBS`` as a job count (a positive integer)."""
    try:
        jobs = int(text)
    except ValueError:
        jobs = 0
    if jobs < 1:
        raise DataError(JOBS_ENV, "jobs", "a positive integer (JOBS=2 on the make command line)", repr(text))
    return jobs


class RunProgress:
    """A bar over ``total`` runs and one line per finished run (which run, what it reports, seconds, runs left
    and an ETA from the mean pace so far); the lines go to ``BGFN_PROGRESS_LOG`` when it is set, else to
    ``echo`` (default: printed above the bar)."""

    def __init__(self, total: int, desc: str, echo: Callable[[str], Any] | None = None, bar: bool = True):
        self.total, self.desc, self.left = int(total), desc, int(total)
        self.t0 = time.perf_counter()
        self.log_path = os.environ.get(PROGRESS_ENV) or None
        # Under make the terminal has the lines, and every refresh of the bar would be kept in the executed notebook
        # (the book shows each as a line): then the bar is redrawn once a minute at most, else every second.
        self.bar = tqdm(total=self.total, desc=desc, disable=not bar or self.total == 0, file=sys.stderr,
                        mininterval=60.0 if self.log_path else 1.0, dynamic_ncols=False, ncols=100)
        self.echo = echo if echo is not None else (lambda line: tqdm.write(line, file=sys.stdout))

    def line(self, label: str, seconds: float, what: str) -> str:
        """The progress line of one finished run."""
        elapsed = time.perf_counter() - self.t0
        done = self.total - self.left
        eta = elapsed / done * self.left if done else float("nan")
        parts = [f"[{self.desc}] {label}", what, f"{seconds:.1f} s", f"{self.left} left",
                 f"ETA {_clock(eta)}" if self.left else f"all {self.total} in {_clock(elapsed)}"]
        return " | ".join(p for p in parts if p)

    def done(self, label: str, seconds: float, what: str = "") -> None:
        """Count one finished run and report it."""
        self.left -= 1
        text = self.line(label, seconds, what)
        if self.log_path:
            with open(self.log_path, "a", encoding="utf-8") as f:
                f.write(text + "\n")
        else:
            self.echo(text)
        self.bar.update(1)

    def close(self) -> None:
        """Close the bar."""
        self.bar.close()


def _clock(seconds: float) -> str:
    """``m:ss`` (``h:mm:ss`` from an hour), ``?`` when unknown."""
    if seconds != seconds:
        return "?"
    s = int(round(seconds))
    h, m = divmod(s // 60, 60)
    return f"{h}:{m:02d}:{s % 60:02d}" if h else f"{m}:{s % 60:02d}"
