"""How long reproducing takes: each notebook's wall time, and how it scales with the number of jobs.

The executed notebooks' wall times (papermill's ``metadata.papermill.duration``, :func:`notebook_wall_times`) and the
measured runs of ``make reproduce`` with ``JOBS=1`` and ``JOBS=2`` (:data:`MEASURED_FILE`; ``python -m bgfn
walltimes --record`` adds a finished run) side by side (:func:`scaling_table`), with more jobs projected by Amdahl's
law per notebook: the share that did not get faster with 2 jobs is taken as serial. The page names its assumption
(the rest divides evenly over the jobs); it is an upper bound on the speed-up. The book's build writes the page's
section with ``python -m bgfn.report.walltimes`` (:func:`main`), which imports no torch and no study.
"""

from __future__ import annotations

import argparse
import datetime
import json
import math
import sys
from pathlib import Path

import pandas as pd

from bgfn.config import PROJECT_ROOT, git_commit, results_dir
from bgfn.errors import DataError
from bgfn.io import atomic_write_csv, atomic_write_text

#: The measured runs (one row per profile, jobs and notebook; ``notebook`` ``total`` = the whole make run).
MEASURED_FILE = PROJECT_ROOT / "data" / "measured" / "reproduce_wall_times.csv"
MEASURED_COLUMNS = ("profile", "jobs", "notebook", "wall_s", "date", "commit", "note")
#: Job counts the page projects to.
PROJECTED_JOBS = (4, 8, 16)


def notebook_wall_times(profile: str) -> pd.DataFrame:
    """``notebook, wall_s, end, cpu_s`` of every executed notebook of ``profile`` (papermill's metadata; the CPU
    seconds from :func:`notebook_cpu_seconds`), in order."""
    rows = []
    for path in sorted((results_dir(profile, create=False) / "notebooks").glob("[0-9]*.ipynb")):
        try:
            meta = json.loads(path.read_text(encoding="utf-8"))["metadata"]["papermill"]
        except (KeyError, ValueError) as exc:
            raise DataError(str(path), "metadata.papermill", "an executed notebook (papermill's metadata)",
                            type(exc).__name__) from None
        rows.append({"notebook": path.stem, "wall_s": float(meta.get("duration") or float("nan")),
                     "end": meta.get("end_time"), "cpu_s": notebook_cpu_seconds(profile, path.stem)})
    return pd.DataFrame(rows, columns=["notebook", "wall_s", "end", "cpu_s"])


def notebook_cpu_seconds(profile: str, notebook: str) -> float:
    """User + system seconds of ``notebook``'s last run (papermill, its kernel and the pool workers it reaped), from
    ``logs/<notebook>.cpu`` (``wall_user_sys``, written by the Makefile's ``/usr/bin/time``); NaN when absent."""
    path = results_dir(profile, create=False) / "logs" / f"{notebook}.cpu"
    try:
        _, user, system = (float(v) for v in path.read_text(encoding="utf-8").strip().split("_"))
    except (OSError, ValueError):
        return float("nan")
    return user + system


def read_measured(path: str | Path = MEASURED_FILE) -> pd.DataFrame:
    """The measured runs (:data:`MEASURED_COLUMNS`); empty when none is recorded."""
    p = Path(path)
    if not p.is_file():
        return pd.DataFrame(columns=list(MEASURED_COLUMNS))
    table = pd.read_csv(p)
    missing = [c for c in MEASURED_COLUMNS if c not in table.columns]
    if missing:
        raise DataError(str(p), missing[0], f"the columns {', '.join(MEASURED_COLUMNS)}", "missing")
    return table[list(MEASURED_COLUMNS)]


def record_run(profile: str, jobs: int, total_s: float | None = None, note: str = "",
               path: str | Path = MEASURED_FILE) -> pd.DataFrame:
    """Add the notebooks of ``profile``'s last run (and the whole make run, ``total_s``, when given) to the
    measured runs as made with ``jobs`` jobs; a row of the same profile, jobs and notebook is replaced."""
    times = notebook_wall_times(profile)
    if times.empty:
        raise DataError(str(results_dir(profile, create=False) / "notebooks"), "executed notebooks",
                        f"a finished make reproduce PROFILE={profile}", "none")
    today, commit = datetime.date.today().isoformat(), git_commit() or "unknown"
    new = [{"profile": profile, "jobs": int(jobs), "notebook": r.notebook, "wall_s": round(r.wall_s, 1),
            "date": today, "commit": commit, "note": note} for r in times.itertuples()]
    if total_s is not None:
        new.append({"profile": profile, "jobs": int(jobs), "notebook": "total", "wall_s": round(float(total_s), 1),
                    "date": today, "commit": commit, "note": note})
    old = read_measured(path)
    keep = ~old.set_index(["profile", "jobs", "notebook"]).index.isin(
        [(r["profile"], r["jobs"], r["notebook"]) for r in new])
    table = pd.concat([old[keep], pd.DataFrame(new)], ignore_index=True)
    atomic_write_csv(Path(path), table)
    return table


def amdahl(t1: float, t2: float, jobs: int) -> float:
    """Projected wall time with ``jobs`` jobs from the times with 1 and 2 (module docstring), s."""
    serial = min(1.0, max(0.0, 2.0 * t2 / t1 - 1.0))
    return t1 * (serial + (1.0 - serial) / jobs)


def scaling_table(measured: pd.DataFrame, profile: str, projected=PROJECTED_JOBS) -> pd.DataFrame:
    """Per notebook of ``profile``: the measured wall times with 1 and 2 jobs (s), the speed-up, the serial share
    and the projection to ``projected`` jobs (:func:`amdahl`); empty unless both runs are recorded."""
    m = measured[measured["profile"] == profile]
    wide = m.pivot_table(index="notebook", columns="jobs", values="wall_s", aggfunc="last")
    if 1 not in wide.columns or 2 not in wide.columns:
        return pd.DataFrame()
    order = [n for n in m["notebook"].drop_duplicates() if n != "total"] + (["total"] if "total" in wide.index
                                                                              else [])
    wide = wide.reindex(order).dropna(subset=[1, 2])
    out = pd.DataFrame({"1 job (s)": wide[1], "2 jobs (s)": wide[2], "speed-up": wide[1] / wide[2],
                        "serial share": (2.0 * wide[2] / wide[1] - 1.0).clip(0.0, 1.0)})
    for n in projected:
        out[f"{n} jobs (s), projected"] = [amdahl(a, b, n) for a, b in zip(wide[1], wide[2])]
    return out


def wall_time_markdown(profile: str, measured: pd.DataFrame | None = None) -> str:
    """The wall-time section of the book's "Reproduce it" page: this build's notebooks, then the measured
    scaling with its projection and assumption."""
    measured = read_measured() if measured is None else measured
    lines = [f"### This build (`{profile}`)", ""]
    times = notebook_wall_times(profile)
    if times.empty:
        lines.append("No executed notebook of this profile yet.")
    else:
        # CPU share: CPU seconds over wall seconds; 2 cores busy read 200 %, a neighbour notebook's share not counted
        lines += ["| notebook | wall time | CPU time | CPU share |", "|---|---|---|---|"]
        lines += [f"| {r.notebook} | {_minutes(r.wall_s)} | {_minutes(r.cpu_s)} | {_share(r.cpu_s, r.wall_s)} |"
                  for r in times.itertuples()]
        cpu_all = times["cpu_s"].sum(min_count=len(times))
        lines.append(f"| all notebooks | {_minutes(times['wall_s'].sum())} | {_minutes(cpu_all)} | |")
    lines += ["", f"### With 1 and 2 jobs (`{profile}`, measured from a fresh clone)", ""]
    table = scaling_table(measured, profile)
    if table.empty:
        lines.append(f"No run of `{profile}` with both `JOBS=1` and `JOBS=2` is recorded in "
                     f"`{MEASURED_FILE.relative_to(PROJECT_ROOT)}`.")
        return "\n".join(lines) + "\n"
    cols = list(table.columns)
    lines += ["| notebook | " + " | ".join(cols) + " |", "|---" * (len(cols) + 1) + "|"]
    for name, r in table.iterrows():
        cells = [f"{r[c]:.2f}" if c in ("speed-up", "serial share") else f"{r[c]:.0f}" for c in cols]
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    runs = measured[measured["profile"] == profile][["jobs", "date", "commit", "note"]].drop_duplicates()
    lines += ["", "Measured: " + "; ".join(f"{r.jobs} job{'s' if r.jobs > 1 else ''} on {r.date} at commit "
                                           f"`{r.commit}`" + (f" ({r.note})" if isinstance(r.note, str) and r.note
                                                             else "") for r in runs.itertuples()) + ".",
              *_other_notebooks(table, times),
              "", "The projection is Amdahl's law per notebook: the share that did not get faster from 1 to 2 jobs "
              "stays serial, the rest divides evenly over the jobs. That assumes at least as many runs of about "
              "equal length as jobs and nothing else shared (memory bandwidth, disk, a GPU), so it is an upper "
              "bound on the speed-up: with fewer runs than jobs the longest run sets the time."]
    return "\n".join(lines) + "\n"


def _other_notebooks(table: pd.DataFrame, times: pd.DataFrame) -> list[str]:
    """A paragraph when the measured runs' notebooks are not this build's (renamed, split or merged since)."""
    measured = [n for n in table.index if n != "total"]
    absent = [n for n in measured if n not in set(times["notebook"])]
    if times.empty or not absent:
        return []
    return ["", f"The measured runs' notebooks are those of their commits, not this build's: "
                f"{', '.join(absent)} {'is' if len(absent) == 1 else 'are'} not among this build's notebooks. "
                "The table shows how the runs of a notebook scale with the jobs, not how long this build's "
                "notebooks take."]


def _share(cpu_s: float, wall_s: float) -> str:
    """``163 %``: CPU over wall seconds (``-`` when either is unknown)."""
    return "-" if math.isnan(cpu_s) or math.isnan(wall_s) or wall_s <= 0 else f"{100 * cpu_s / wall_s:.0f} %"


def _minutes(seconds: float) -> str:
    """``12.3 min`` from seconds (``-`` when unknown)."""
    return "-" if math.isnan(seconds) else f"{seconds / 60:.1f} min ({seconds:.0f} s)"


def main(argv=None, prog: str = "python -m bgfn.report.walltimes") -> int:
    """``walltimes --profile P [--markdown FILE] [--record JOBS [--total-s S] [--note TEXT]]``."""
    p = argparse.ArgumentParser(prog=prog, description="Wall times of a profile's notebooks.")
    p.add_argument("--profile", default="quick")
    p.add_argument("--markdown", help="write the book's wall-time section here (default: print it)")
    p.add_argument("--record", type=int, metavar="JOBS", help="add the last run, made with JOBS jobs, to "
                   "data/measured/reproduce_wall_times.csv")
    p.add_argument("--total-s", type=float, help="the whole make reproduce's wall time, s (with --record)")
    p.add_argument("--note", default="", help="how it was measured (with --record)")
    a = p.parse_args(sys.argv[1:] if argv is None else argv)
    try:
        if a.record is not None:
            record_run(a.profile, a.record, a.total_s, a.note)
        text = wall_time_markdown(a.profile)
    except DataError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    if a.markdown:
        atomic_write_text(a.markdown, text)
    else:
        print(text)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
