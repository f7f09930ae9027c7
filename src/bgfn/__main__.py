"""``python -m bgfn train``: train the networks of a profile from the shell (what notebook 03 trains, with the
learning rates its search selected once it has run). A command line is an edge of the package: it checks the
profile and its options (:func:`bgfn.profile_schema.with_overrides`) before anything runs.

Example::

    python -m bgfn train --profile quick --dataset turin-sim-mpu6000 --method bgfn --seed 0
    python -m bgfn train --profile quick --variants        # every network of notebook 03, variants included
    python -m bgfn train --profile paper --jobs 8           # 8 runs at a time (default: the profile's parallel:)
"""

from __future__ import annotations

import argparse
import sys

from bgfn.errors import DataError
from bgfn.parallel import Runner
from bgfn.profile_schema import load_profile, with_overrides
from bgfn.train.runs import train_profile


def main(argv=None) -> int:
    """Parse ``--profile``, ``--dataset``, ``--method``, ``--seed`` (each repeatable), ``--device``, ``--jobs`` and
    ``--variants``; train and print one line per finished run (:class:`bgfn.parallel.RunProgress`)."""
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
        cfg = with_overrides(load_profile(a.profile), {"train.datasets": a.dataset, "train.methods": a.method,
                                                       "train.seeds": a.seed, "parallel.jobs": a.jobs}, "command line")
        runner = Runner.of(cfg) if a.jobs is None else Runner.of(cfg, environ={})
    except DataError as exc:
        print(f"error: profile {a.profile!r}: {exc}", file=sys.stderr)
        return 2
    print(f"profile {a.profile!r}: runs {runner.describe()}")
    train_profile(cfg, a.device, echo=print, variants=a.variants, runner=runner)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
