"""``python -m bgfn.train``: train the networks of a profile from the shell (what notebook 03 trains, with the
learning rates its search selected once it has run).

Example::

    python -m bgfn.train --profile quick --dataset turin-sim-mpu6000 --method bgfn --seed 0
    python -m bgfn.train --profile quick --variants        # every network of notebook 03, variants included
"""

from __future__ import annotations

import argparse

from bgfn.train.profile import train_profile


def main(argv=None) -> None:
    """Parse ``--profile``, ``--dataset``, ``--method``, ``--seed`` (each repeatable), ``--device`` and
    ``--variants``; train and print one line per run (:func:`bgfn.train.tables.card_line`)."""
    p = argparse.ArgumentParser(prog="python -m bgfn.train", description="Train BGFN and baselines for a profile.")
    p.add_argument("--profile", default="quick")
    p.add_argument("--dataset", action="append")
    p.add_argument("--method", action="append")
    p.add_argument("--seed", action="append", type=int)
    p.add_argument("--device")
    p.add_argument("--variants", action="store_true",
                   help="also train the profile's input and protocol variants (variants:, variant_runs:)")
    a = p.parse_args(argv)
    train_profile(a.profile, a.dataset, a.method, a.seed, a.device, echo=print, variants=a.variants)
