"""Variants of a profile's learning problem, trained beside its main networks.

A profile names them at its top level (:class:`bgfn.settings.Variant`): ``variants:`` maps a name to overrides of
the ``train:`` section (other input channels, a leaky protocol), ``variant_runs:`` which datasets, methods and
seeds train them. A variant is merged over the profile as a ``base:`` chain merges and checked as a whole profile.
Its networks train on the same drives and inputs with the same budget and the learning rates the main search
selected (:mod:`bgfn.train.lr_search`: a variant is compared at its main network's rate), under
``results/<profile>/models/variants/<variant>/`` (:func:`bgfn.train.checkpoints.variant_models_dir`);
:mod:`bgfn.studies.outage_sweep.variant_outages` evaluates them in the outages.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

from bgfn import settings
from bgfn.config import MAIN_VARIANT, merge_sections, variant_config
from bgfn.learning import LEARNING_DEFAULTS, LearningData, build_learning_data, learning_options
from bgfn.parallel import Runner
from bgfn.train import checkpoints
from bgfn.train.options import size_config
from bgfn.train.tables import cards_table
from bgfn.train.tasks import TrainingRun, train_runs

#: Defaults of ``variant_runs`` (null datasets / methods: the ``train:`` section's).
VARIANT_RUN_DEFAULTS: dict[str, Any] = settings.defaults("variant_runs")   # their home: bgfn.settings.VariantRuns


def variant_train_section(train_cfg: dict, overrides: dict | None) -> dict:
    """``train_cfg`` (a ``train:`` section, e.g. with a dataset's selected learning rates) with a variant's
    ``train`` overrides merged over it key by key (:func:`bgfn.config.merge_sections`)."""
    return merge_sections(train_cfg, (overrides or {}).get("train") or {})


def variant_options(train_cfg: dict) -> dict:
    """What a variant changes in the learning problem, in a few words: ``inputs`` (``eq21``: the nine channels
    of Eq. (eq21), ``+<channel>`` per extra channel, ``; yaw <encoding>`` and ``; <frame> frame`` where they are
    not the paper's ``unwrap`` and ``ned``) and ``protocol`` (``honest`` / ``leaky``)."""
    opts = learning_options(train_cfg)
    inputs = "+".join(["eq21", *(opts["extra_channels"] or [])])
    if opts["yaw_encoding"] != LEARNING_DEFAULTS["yaw_encoding"]:
        inputs += f"; yaw {opts['yaw_encoding']}"
    if opts["target_frame"] != LEARNING_DEFAULTS["target_frame"]:
        inputs += f"; {opts['target_frame']} frame"
    return {"inputs": inputs, "protocol": opts["protocol"]}


@dataclass
class VariantPlan:
    """The variant networks of a profile: every ``(variant, dataset, method, seed)``.

    Attributes
    ----------
    profile : str
    cfg : dict
        The profile (:func:`bgfn.config.load_profile`).
    variants : dict
        ``{name: overrides}`` (the profile's ``variants``, in its order).
    datasets, methods : list of str
    seeds : list of int
    outage_windows : list of (start, duration)
        The main plan's outages, s (its ``default`` when each dataset has its own: training and evaluation take
        each dataset's, ``TrainingDataset.windows`` and :func:`bgfn.nav.outages.outage_windows`).
    """

    profile: str
    cfg: dict
    variants: dict
    datasets: list[str]
    methods: list[str]
    seeds: list[int]
    outage_windows: list

    @classmethod
    def of(cls, plan) -> "VariantPlan":
        """The variants of a :class:`bgfn.train.profile.TrainingPlan`'s profile; ``variant_runs``' null datasets
        and methods are the plan's (notebook 03's parameters), its own lists are cut to the plan's."""
        runs = {**VARIANT_RUN_DEFAULTS, **(plan.cfg.get("variant_runs") or {})}
        datasets = [d for d in (runs["datasets"] or plan.datasets) if d in plan.datasets]
        methods = [m for m in (runs["methods"] or plan.methods) if m in plan.methods]
        return cls(plan.profile, plan.cfg, dict(plan.cfg.get("variants") or {}), datasets, methods,
                   [int(s) for s in runs["seeds"]], list(plan.outage_windows or []))

    @property
    def names(self) -> list[str]:
        """The variant names, in the profile's order."""
        return list(self.variants)

    def profile_of(self, name: str) -> dict:
        """The profile with variant ``name`` merged over it (:func:`bgfn.config.variant_config`);
        ``main``: the profile itself."""
        return self.cfg if name == MAIN_VARIANT else variant_config(self.cfg, name)

    def train_section(self, name: str, train_cfg: dict | None = None) -> dict:
        """Variant ``name``'s ``train:`` section over ``train_cfg`` (default the profile's; pass a dataset's
        section with its selected learning rates)."""
        base = self.cfg["train"] if train_cfg is None else train_cfg
        return base if name == MAIN_VARIANT else variant_train_section(base, self.variants[name])

    def models_dir(self, name: str, dataset: str, create: bool = True):
        """Where variant ``name``'s networks of ``dataset`` are (``main``: notebook 03's own folder)."""
        if name == MAIN_VARIANT:
            return checkpoints.models_dir(self.profile, dataset, create=create)
        return checkpoints.variant_models_dir(self.profile, name, dataset, create=create)


def variant_learning_data(train_section: dict, prepared, outage_windows) -> LearningData:
    """The learning data of one variant on one prepared dataset (:class:`bgfn.train.profile.TrainingDataset`):
    its drive and INS attitude, the variant's learning options (inputs, protocol) and the evaluation outages."""
    opts = learning_options(train_section)
    return build_learning_data(prepared.drive.imu, prepared.attitude, prepared.drive.gnss, outage_windows, **opts)


def variant_runs(vplan: VariantPlan, prepared: dict, train_cfgs: dict[str, dict],
                 device: str | None = None) -> list[TrainingRun]:
    """Every ``(variant, dataset, method, seed)`` network of ``vplan`` as a run, into
    ``results/<profile>/models/variants/<variant>/<dataset>/``.

    Parameters
    ----------
    prepared : dict
        ``{dataset: TrainingDataset}`` (:func:`bgfn.train.profile.prepare_datasets`): drives and INS attitude.
    train_cfgs : dict
        ``{dataset: train: section with the selected learning rates}``
        (:func:`bgfn.train.lr_search.selected_train_configs`); the variant's overrides are merged over it.
    """
    runs = []
    for name in vplan.names:
        for dataset in vplan.datasets:
            tc = vplan.train_section(name, train_cfgs[dataset])
            own = prepared[dataset].windows
            data = variant_learning_data(tc, prepared[dataset], vplan.outage_windows if own is None else own)
            out = vplan.models_dir(name, dataset)
            extra = {"variant": name, **variant_options(tc), "dataset": dataset, "profile": vplan.profile,
                     "size": tc.get("size"), "lr_from": "main search"}
            runs += [TrainingRun(f"{name} {dataset} {method} seed {seed}", method, data, size_config(tc, method), tc,
                                 int(seed), out, device, extra) for method in vplan.methods for seed in vplan.seeds]
    return runs


def train_variants(vplan: VariantPlan, prepared: dict, train_cfgs: dict[str, dict], device: str | None = None,
                   runner: Runner | None = None, echo: Callable[[str], Any] | None = None) -> list[dict]:
    """Train every variant network of ``vplan`` (:func:`variant_runs`), spread over ``runner``.

    Returns
    -------
    list of dict
        The cards (:func:`bgfn.train.loop.train_model`) with ``variant``, ``inputs``, ``protocol``, ``dataset``,
        ``profile`` and ``size``; a completed network is not trained again.
    """
    return train_runs(variant_runs(vplan, prepared, train_cfgs, device), runner, desc="variants", echo=echo)


def variant_cards_table(cards: list[dict]):
    """:func:`bgfn.train.tables.cards_table` of variant cards, with ``variant``, ``inputs`` and ``protocol``
    first and the training windows that touch an outage (``n_outage_in_train``: 0 when honest)."""
    table = cards_table(cards)
    for i, col in enumerate(("variant", "inputs", "protocol")):
        table.insert(i, col, [c.get(col) for c in cards])
    table["n_outage_in_train"] = [(c.get("split") or {}).get("n_outage_in_train") for c in cards]
    return table


def wall_time_by_variant(cards: list[dict]) -> dict[str, float]:
    """Variant -> training wall time of its networks, s (rounded to 0.1 s; notebook 03 prints it)."""
    times: dict[str, float] = {}
    for c in cards:
        times[c["variant"]] = times.get(c["variant"], 0.0) + float(c["wall_time_s"])
    return {v: round(t, 1) for v, t in times.items()}
