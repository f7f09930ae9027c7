"""A profile's training: what notebook 03 and ``python -m bgfn train`` train, and the data they train it on.

:class:`TrainingPlan` names the ``(dataset, method, seed)`` runs of a profile's ``train:`` section and the
evaluation outages kept out of training; :func:`prepare_datasets` loads each drive, runs the GPS/INS filter for
the attitude input of Eq. (eq21) (:func:`ins_attitude`) and builds its windows; :func:`train_dataset` trains
every method and seed of one dataset into ``results/<profile>/models/<dataset>/`` and
:func:`train_datasets` every run of the plan, spread over a :class:`bgfn.parallel.Runner`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

import pandas as pd

from bgfn.data import load_drive
from bgfn.errors import DataError
from bgfn.learning import (VAL_POSITIONS, LearningData, all_windows, build_learning_data, learning_options,
                           motion_in_windows, val_position_coverage)
from bgfn.nav import outages
from bgfn.nav.baseline import run_drive
from bgfn.parallel import Runner
from bgfn.train import checkpoints
from bgfn.train.options import size_config
from bgfn.train.tasks import TrainingRun, train_runs

#: Learning options :func:`bgfn.report.training_words.plan_text` shows (the rest of
#: :data:`bgfn.learning.LEARNING_DEFAULTS` is in the profile).
DESCRIBED_OPTIONS = ("window", "alignment", "yaw_encoding", "target_frame", "extra_channels", "val_position",
                     "target_screen_sigma", "protocol")


@dataclass
class TrainingPlan:
    """The runs of a profile: every ``(dataset, method, seed)``, with the profile and its evaluation outages.

    Attributes
    ----------
    profile : str
        Profile name (``params/<profile>.yaml``).
    cfg : dict
        The profile (:func:`bgfn.config.load_profile`); ``cfg['train']`` is :attr:`train_cfg`.
    datasets, methods : list of str
    seeds : list of int
    outage_windows : list of (start, duration) or None
        Evaluation outages, s, kept (widened by ``train.margin_s``) out of training and validation: with
        ``per_dataset`` False the windows of every dataset; with ``per_dataset`` True the profile's ``default``
        list (None when the profile has no such list), and each dataset's own are :meth:`windows_of`.
    per_dataset : bool
        Whether each dataset takes its own entry of the profile's ``outage_windows`` (:meth:`of` without
        windows) rather than ``outage_windows``.
    """

    profile: str
    cfg: dict
    datasets: list[str]
    methods: list[str]
    seeds: list[int]
    outage_windows: list | None
    per_dataset: bool = False

    @classmethod
    def of(cls, cfg: dict, outage_windows=None) -> "TrainingPlan":
        """The plan of a checked profile ``cfg`` (:func:`bgfn.profile_schema.load_profile`, with a notebook's
        ``train.datasets`` / ``train.methods`` / ``train.seeds`` set through
        :func:`bgfn.profile_schema.with_overrides`); ``outage_windows`` given: the outages of every dataset,
        else each dataset's own from the top-level ``outage_windows`` (:meth:`windows_of`)."""
        tc = cfg["train"]
        if outage_windows is not None:
            windows, per_dataset = [(float(s), float(d)) for s, d in outage_windows], False
        else:
            windows, per_dataset = outages.default_windows(cfg), True
        return cls(cfg["profile"], cfg, list(tc["datasets"]), list(tc["methods"]), [int(s) for s in tc["seeds"]],
                   windows, per_dataset)

    def windows_of(self, dataset: str, drive=None) -> list:
        """The evaluation outages of ``dataset`` kept out of its training, s: :attr:`outage_windows`, or with
        :attr:`per_dataset` its entry in the profile (:func:`bgfn.nav.outages.outage_windows`; a rule needs the
        ``drive``)."""
        if not self.per_dataset:
            return list(self.outage_windows)
        return outages.outage_windows(self.cfg, drive, dataset)

    @property
    def train_cfg(self) -> dict:
        """The profile's ``train:`` section."""
        return self.cfg["train"]


    def dataset_windows(self, name: str, prepared: "TrainingDataset") -> list:
        """The evaluation outages kept out of a prepared dataset: its own (``prepared.windows``), else the plan's."""
        return prepared.windows if prepared.windows is not None else self.windows_of(name, prepared.drive)


@dataclass
class TrainingDataset:
    """One dataset of a plan: its drive, the INS attitude its windows were built from, its learning data, and
    the evaluation outages kept out of them (``windows``, s; None: the plan's, :meth:`TrainingPlan.windows_of`)."""

    name: str
    drive: Any
    attitude: pd.DataFrame
    data: LearningData
    windows: list | None = None


def prepare_datasets(plan: TrainingPlan) -> dict[str, TrainingDataset]:
    """``{dataset: TrainingDataset}`` for every dataset of ``plan``, in its order (:func:`prepare_learning_data`
    with the :func:`ins_attitude` of each drive)."""
    prepared = {}
    for name in plan.datasets:
        drive = load_drive(name, profile=plan.profile)
        attitude = ins_attitude(drive, plan.cfg)
        windows = plan.windows_of(name, drive)
        data = prepare_learning_data(plan.cfg, name, attitude=attitude, drive=drive, outage_windows=windows)
        prepared[name] = TrainingDataset(name, drive, attitude, data, windows)
    return prepared


def prepare_learning_data(cfg: dict, dataset: str, attitude=None, drive=None, outage_windows=None) -> LearningData:
    """Windows of drive ``dataset`` for the profile ``cfg`` (:func:`bgfn.config.load_profile`).

    Parameters
    ----------
    cfg : dict
        The profile.
    dataset : str
        Name for :func:`bgfn.data.load_drive`.
    attitude : DataFrame, optional
        INS/KF attitude (``time, roll, pitch, yaw``) at IMU rate; default :func:`ins_attitude`.
    drive : Drive, optional
        Already loaded drive.
    outage_windows : sequence of (start, duration), optional
        Evaluation outages; default: the profile's for ``dataset`` (:func:`bgfn.nav.outages.outage_windows`).
    """
    if drive is None:
        drive = load_drive(dataset, profile=cfg["profile"])
    attitude, outage_windows, opts = _learning_inputs(cfg, drive, attitude, outage_windows, dataset)
    return build_learning_data(drive.imu, attitude, drive.gnss, outage_windows, keep=True, **opts)


def _learning_inputs(cfg: dict, drive, attitude=None, outage_windows=None, dataset: str | None = None) -> tuple:
    """``(attitude, outage_windows, learning options)`` of the profile, defaults filled in (the outages of
    ``dataset``, default ``drive.name``)."""
    attitude = attitude if attitude is not None else ins_attitude(drive, cfg)
    if outage_windows is None:
        outage_windows = outages.outage_windows(cfg, drive, dataset)
    return attitude, outage_windows, learning_options(cfg.get("train"))


def ins_attitude(drive, cfg: dict):
    """INS/KF solution at IMU rate (reference schema): ``roll, pitch, yaw`` are the attitude input of Eq. (eq21).

    The other columns (``v_n``, ``v_e``, ...) are there for ``train.extra_channels`` (not the paper's input).

    ``train.attitude_source``: ``'kf'`` (default, the paper's online-training mode) runs the 15-state loosely
    coupled filter with the GNSS fixes and the profile's ``nav:`` section (:func:`bgfn.nav.baseline.run_drive`);
    ``'reference'`` takes the truth attitude
    (debugging only: the outage evaluation feeds the INS attitude).
    """
    src = cfg["train"]["attitude_source"]
    if src == "reference":
        return drive.reference.copy()
    if src != "kf":
        raise DataError("train", "attitude_source", "'kf' or 'reference'", repr(src))
    traj = run_drive(drive, cfg.get("nav") or {}).trajectory
    return pd.DataFrame(traj).reset_index(drop=True)


def val_position_table(cfg: dict, drive, attitude=None, outage_windows=None, positions=None,
                       dataset: str | None = None):
    """:func:`bgfn.learning.val_position_coverage` of ``drive`` with the profile's learning options: what each
    place of the validation block would leave to training (notebook 03)."""
    attitude, outage_windows, opts = _learning_inputs(cfg, drive, attitude, outage_windows, dataset)
    ws = all_windows(drive.imu, attitude, drive.gnss, **opts)
    return val_position_coverage(ws, motion_in_windows(drive.reference, outage_windows), outage_windows,
                                 margin_s=float(opts["margin_s"]), val_fraction=float(opts["val_fraction"]),
                                 positions=positions or VAL_POSITIONS)


def val_position_tables(plan: TrainingPlan, prepared: dict[str, TrainingDataset]) -> pd.DataFrame:
    """:func:`val_position_table` of every prepared dataset in one table, ``dataset`` first."""
    positions = pd.concat([val_position_table(plan.cfg, d.drive, attitude=d.attitude,
                                              outage_windows=plan.dataset_windows(name, d),
                                              dataset=name).assign(dataset=name)
                           for name, d in prepared.items()], ignore_index=True)
    return positions[["dataset"] + [col for col in positions.columns if col != "dataset"]]


def training_runs(plan: TrainingPlan, dataset: str, data: LearningData, train_cfg: dict | None = None,
                  device: str | None = None) -> list[TrainingRun]:
    """The ``(method, seed)`` runs of ``plan`` on one dataset's ``data``, into ``results/<profile>/models/<dataset>/``.

    ``train_cfg``: the ``train:`` section with this dataset's learning rates (:mod:`bgfn.train.lr_search`);
    default :attr:`TrainingPlan.train_cfg`.
    """
    tc = plan.train_cfg if train_cfg is None else train_cfg
    out = checkpoints.models_dir(plan.profile, dataset)
    return [TrainingRun(f"{dataset} {method} seed {seed}", method, data, size_config(tc, method), tc, int(seed), out,
                        device, {"dataset": dataset, "profile": plan.profile, "size": tc.get("size")})
            for method in plan.methods for seed in plan.seeds]


def train_datasets(plan: TrainingPlan, learning_data: dict[str, LearningData], train_cfgs: dict[str, dict],
                   runner: Runner | None = None, device: str | None = None,
                   echo: Callable[[str], Any] | None = None) -> list[dict]:
    """Train every ``(dataset, method, seed)`` of ``plan`` (:func:`training_runs` of each dataset of
    ``learning_data`` with its ``train_cfgs`` entry), spread over ``runner``; the cards in that order.

    Returns
    -------
    list of dict
        The cards (:func:`bgfn.train.loop.train_model`), with ``dataset``, ``profile`` and ``size``.
    """
    runs = [run for name, data in learning_data.items()
            for run in training_runs(plan, name, data, train_cfgs.get(name), device)]
    return train_runs(runs, runner, desc=f"training {plan.profile}", echo=echo)


def train_dataset(plan: TrainingPlan, dataset: str, data: LearningData, train_cfg: dict | None = None,
                  device: str | None = None, runner: Runner | None = None,
                  echo: Callable[[str], Any] | None = None) -> list[dict]:
    """Train every ``(method, seed)`` of ``plan`` on one dataset (:func:`training_runs`); return the cards."""
    return train_runs(training_runs(plan, dataset, data, train_cfg, device), runner, desc=f"training {dataset}",
                      echo=echo)
