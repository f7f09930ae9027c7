"""The package's command line, an edge: each command checks the profile and its options
(:func:`bgfn.profile_schema.with_overrides`) before anything runs.

- ``python -m bgfn train``: a profile's networks (what notebook 03 trains, with the learning rates its search chose);
- ``python -m bgfn kernels``: the navigation's numba kernels compiled into numba's cache (:mod:`bgfn.evaluate.kernels`);
- ``python -m bgfn odometers``: the odometer bars alone (:func:`bgfn.studies.odometer.section.run_odometer_section`);
  ``--record`` keeps their summary in ``data/measured/`` (:mod:`bgfn.studies.odometer.sizes`: a run on a GPU);
- ``python -m bgfn walltimes``: the wall times of the book's "Reproduce it" page (:func:`bgfn.report.walltimes.main`,
  which the book's build runs as ``python -m bgfn.report.walltimes``: it imports pandas and bgfn's core modules, no
  torch and no study).

Example::

    python -m bgfn train --profile quick --dataset turin-sim-mpu6000 --method bgfn --seed 0
    python -m bgfn train --profile paper --jobs 8           # 8 runs at a time (default: the profile's parallel:)
"""

from __future__ import annotations

import argparse
import sys
import time

from bgfn.config import results_dir, set_keys
from bgfn.errors import DataError
from bgfn.evaluate import evaluation_setup
from bgfn.studies.odometer import sizes as odometer_sizes
from bgfn.studies.odometer.section import run_odometer_section
from bgfn.evaluate.kernels import compile_kernels
from bgfn.parallel import Runner
from bgfn.profile_schema import load_profile, with_overrides
from bgfn.report import walltimes as walltimes_module
from bgfn.report.odometer_words import odometer_markdown
from bgfn.report.run_words import runner_words
from bgfn.train.runs import train_profile


def kernels(argv) -> int:
    """``kernels [--profile P]``: the notebooks' navigation paths once on a synthetic drive, with the profile's
    ``nav:`` section; prints the wall time."""
    p = argparse.ArgumentParser(prog="python -m bgfn kernels", description="Compile the numba kernels into the cache.")
    p.add_argument("--profile", default="quick")
    a = p.parse_args(argv)
    try:
        # without the run plan: make starts this beside the check that writes it, and the kernels' types do not
        # depend on what the plan scales
        cfg = load_profile(a.profile, planned=False)
    except DataError as exc:
        print(f"error: profile {a.profile!r}: {exc}", file=sys.stderr)
        return 2
    print(f"numba kernels compiled or loaded from the cache in {compile_kernels(cfg['nav']):.1f} s")
    return 0


def odometers(argv) -> int:
    """``odometers --profile P [--method M ...] [--seed S ...] [--jobs N]``: the odometer bars of the profile's
    ``evaluate.odometer.datasets`` (one line per finished run), their tables and ``odometer_run.json`` under
    ``results/P/``; ``odometers --profile P --record [--note TEXT]``: keep that run's summary in ``data/measured/``
    with the date, the commit and the device (:mod:`bgfn.studies.odometer.sizes`)."""
    p = argparse.ArgumentParser(prog="python -m bgfn odometers", description="The learned odometers' bars alone.")
    p.add_argument("--profile", default="paper-odometer")
    p.add_argument("--method", action="append", help="network odometers (evaluate.odometer.methods)")
    p.add_argument("--seed", action="append", type=int, help="their seeds (evaluate.odometer.network_seeds)")
    p.add_argument("--jobs", type=int, help="runs at a time (default: the profile's parallel.jobs, BGFN_JOBS)")
    p.add_argument("--record", action="store_true", help="keep the last run's summary in data/measured/ (no run)")
    p.add_argument("--note", default="", help="how it was measured (with --record)")
    a = p.parse_args(argv)
    try:
        if a.record:
            print("recorded in", ", ".join(map(str, odometer_sizes.record(a.profile, a.note))))
            return 0
        cfg = with_overrides(load_profile(a.profile), {"evaluate.odometer.methods": a.method,
                                                       "evaluate.odometer.network_seeds": a.seed,
                                                       "parallel.jobs": a.jobs}, "command line")
        setup = evaluation_setup(cfg)
    except DataError as exc:
        print(f"error: profile {a.profile!r}: {exc}", file=sys.stderr)
        return 2
    t0 = time.perf_counter()
    runner = setup.runner if a.jobs is None else Runner.of(cfg, environ={})
    print(f"profile {a.profile!r}: runs {runner_words(runner)}", flush=True)
    section = run_odometer_section(cfg, a.profile, setup, results_dir(a.profile), runner, report=print)
    print(odometer_markdown(section))
    print("wrote", odometer_sizes.write_run_facts(a.profile, cfg, t0, runner_words(runner)))
    return 0


def train_config(profile: str, datasets=None, methods=None, seeds=None, jobs=None, variants: bool = False) -> dict:
    """The profile with this command's choice of networks (``--dataset``, ``--method``, ``--seed``; None: the
    profile's) over it, checked as a profile (errors name the command line).

    The choice narrows what this command trains, not the profile: the keys that name some of the profile's networks
    for other notebooks follow it (``energy.dataset`` / ``energy.seed``, notebook 05's network, back to their null
    rule when not chosen; ``variant_runs``, the variants trained with ``--variants``, narrowed to the choice; no
    variants without ``--variants``), so that a command the error messages suggest for one network passes.
    """
    cfg = load_profile(profile)
    choice = {"train.datasets": datasets, "train.methods": methods, "train.seeds": seeds, "parallel.jobs": jobs}
    cfg = set_keys(cfg, choice)
    for key, chosen in (("dataset", datasets), ("seed", seeds)):
        if chosen and cfg["energy"].get(key) not in chosen:
            cfg["energy"][key] = None
    runs = cfg.get("variant_runs") or {}
    for key, chosen in (("datasets", datasets), ("methods", methods)):
        if chosen and runs.get(key) is not None:
            runs[key] = [x for x in runs[key] if x in chosen] or None
    if not variants:
        cfg["variants"] = {}
    return with_overrides(cfg, {}, "command line")


def main(argv=None) -> int:
    """Parse ``--profile``, ``--dataset``, ``--method``, ``--seed`` (each repeatable), ``--device``, ``--jobs`` and
    ``--variants``; train and print one line per finished run (:class:`bgfn.parallel.RunProgress`)."""
    argv = sys.argv[1:] if argv is None else list(argv)
    if argv[:1] == ["walltimes"]:
        return walltimes_module.main(argv[1:], prog="python -m bgfn walltimes")
    if argv[:1] == ["kernels"]:
        return kernels(argv[1:])
    if argv[:1] == ["odometers"]:
        return odometers(argv[1:])
    p = argparse.ArgumentParser(prog="python -m bgfn", description="Train BGFN and baselines for a profile.")
    p.add_argument("command", choices=["train"])
    p.add_argument("--profile", default="quick")
    p.add_argument("--dataset", action="append")
    p.add_argument("--method", action="append")
    p.add_argument("--seed", action="append", type=int)
    p.add_argument("--device")
    p.add_argument("--jobs", type=int, help="runs at a time (default: the profile's parallel.jobs, BGFN_JOBS)")
    p.add_argument("--variants", action="store_true",
                   help="also train the profile's input and protocol variants (variants:, variant_runs:)")
    a = p.parse_args(argv)
    try:
        cfg = train_config(a.profile, a.dataset, a.method, a.seed, a.jobs, a.variants)
        runner = Runner.of(cfg) if a.jobs is None else Runner.of(cfg, environ={})
    except DataError as exc:
        print(f"error: profile {a.profile!r}: {exc}", file=sys.stderr)
        return 2
    print(f"profile {a.profile!r}: runs {runner_words(runner)}")
    train_profile(cfg, a.device, echo=print, variants=a.variants, runner=runner)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
