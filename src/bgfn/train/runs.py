"""A whole profile's training from one call: the main networks of every dataset, then (optionally) the variants.

Kept apart from :mod:`bgfn.train.profile` (what a profile trains on which data) and :mod:`bgfn.train.variants`
(the input and protocol variants), which it joins: ``python -m bgfn train`` calls it, as notebook 03 trains.
"""

from __future__ import annotations

from typing import Any, Callable

from bgfn.parallel import Runner
from bgfn.train.lr_search import tuned_train_config
from bgfn.train.profile import TrainingPlan, prepare_datasets, train_datasets
from bgfn.train.variants import VariantPlan, train_variants


def train_profile(cfg: dict, device: str | None = None, outage_windows=None, echo: Callable[[str], Any] | None = None,
                  variants: bool = False, runner: Runner | None = None) -> list[dict]:
    """Train every ``(dataset, method, seed)`` of a checked profile's ``train:`` section; return the cards.

    The learning rates are those notebook 03 selected (:func:`bgfn.train.lr_search.tuned_train_config`) when its
    search has run. ``runner``: where the runs go (default: the profile's ``parallel:`` section,
    :meth:`bgfn.parallel.Runner.of`). ``variants``: also the profile's input and protocol variants (``variants:`` and
    ``variant_runs:``, :func:`bgfn.train.variants.train_variants`), as notebook 03 trains them.
    """
    plan = TrainingPlan.of(cfg, outage_windows)
    profile = plan.profile
    prepared = prepare_datasets(plan)       # each dataset's own outages unless outage_windows is given
    train_cfgs = {name: tuned_train_config(plan.cfg, profile, name) for name in plan.datasets}
    runner = runner or Runner.of(cfg)
    cards = train_datasets(plan, {name: d.data for name, d in prepared.items()}, train_cfgs, runner, device, echo)
    if variants:
        cards += train_variants(VariantPlan.of(plan), prepared, train_cfgs, device=device, runner=runner, echo=echo)
    return cards
