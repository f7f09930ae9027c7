"""The learning problem of one drive in one call: windows, outage-free split and normalization
(:class:`LearningData`), with the profile's learning options (a ``train:`` section's keys)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from bgfn import settings
from bgfn.errors import DataError
from bgfn.io import cached, content_hash, sources_hash
from bgfn.learning.normalize import Normalizer
from bgfn.learning.references import reference_columns, reference_rmse
from bgfn.learning.split import block_label, split_windows
from bgfn.learning.targets import TARGET_FRAMES
from bgfn.learning.windows import WindowSet, make_windows

#: Defaults of the learning-problem keys of a profile's ``train:`` section.
LEARNING_DEFAULTS = {k: settings.defaults("train")[k] for k in (   # their home: bgfn.settings.Train
    "window", "alignment", "yaw_encoding", "target_frame", "extra_channels", "epoch_stride", "margin_s", "val_fraction",
    "val_position", "target_screen_sigma", "protocol")}


@dataclass
class LearningData:
    """Training and validation windows of one drive, with the training-set normalization."""

    train: WindowSet
    val: WindowSet
    norm: Normalizer
    info: dict = field(default_factory=dict)
    options: dict = field(default_factory=dict)


def learning_options(cfg: dict | None) -> dict:
    """The learning-problem keys of a ``train:`` section, with defaults filled in."""
    cfg = cfg or {}
    return {k: cfg.get(k, v) for k, v in LEARNING_DEFAULTS.items()}


def all_windows(imu: pd.DataFrame, attitude: pd.DataFrame, gnss: pd.DataFrame, **options) -> WindowSet:
    """Every window of the drive with the learning options ``options`` (split not applied)."""
    opt = learning_options(options)
    return make_windows(imu, attitude, gnss, window=int(opt["window"]), alignment=opt["alignment"],
                        yaw_encoding=opt["yaw_encoding"], extra_channels=tuple(opt["extra_channels"]),
                        epoch_stride=int(opt["epoch_stride"]), target_screen_sigma=opt["target_screen_sigma"])


def build_learning_data(imu: pd.DataFrame, attitude: pd.DataFrame, gnss: pd.DataFrame, outage_windows=(),
                        keep: bool = False, **options) -> LearningData:
    """Windows, split and normalization in one call.

    Parameters
    ----------
    imu, attitude, gnss : DataFrame
        Drive tables (CONTRIBUTING.md schemas; ``attitude`` = INS/KF solution with ``time, roll, pitch, yaw``).
    outage_windows : sequence of (start, duration)
        Evaluation outages (s) excluded from training and validation (``protocol='honest'``; with ``'leaky'``
        only from validation: :func:`bgfn.learning.split_windows`).
    keep : bool
        Keep the result on disk for the next caller with the same inputs (:func:`bgfn.io.cached`): the profile's own
        windows (:func:`bgfn.train.prepare_learning_data`); not a sweep fold's or a variant's, read once.
    **options
        ``window``, ``alignment``, ``yaw_encoding``, ``target_frame``, ``extra_channels``, ``epoch_stride``,
        ``margin_s``, ``val_fraction``, ``val_position``, ``target_screen_sigma``, ``protocol`` (defaults:
        :data:`LEARNING_DEFAULTS`).
    """
    unknown = set(options) - set(LEARNING_DEFAULTS)
    if unknown:
        raise DataError("train", sorted(unknown)[0], f"one of {', '.join(LEARNING_DEFAULTS)}")
    opt = learning_options(options)
    if not keep:
        return _build(imu, attitude, gnss, outage_windows, opt)
    # built once per drive, INS solution, outages and options: notebooks 03, 04, 05 and 06 share the profile's
    return cached("learning_data", lambda: _learning_key(imu, attitude, gnss, outage_windows, opt),
                  lambda: _build(imu, attitude, gnss, outage_windows, opt))


#: Bumped when the windows change in a way the hashed sources do not show (:func:`_learning_key`).
LEARNING_CACHE_VERSION = 1


def _learning_key(imu, attitude, gnss, outage_windows, opt: dict) -> dict:
    """The key of :func:`build_learning_data`'s result: its tables' content, the outages, the options, the code."""
    here = Path(__file__).resolve().parent
    core = here.parent
    code = sources_hash(sorted(here.glob("*.py")) + [core / "nav" / f"{m}.py" for m in ("earth", "transform", "odometer")]
                        + [core / f"{m}.py" for m in ("settings", "schema", "errors", "io")])
    return {"tables": content_hash({"imu": imu, "attitude": attitude, "gnss": gnss}),
            "outage_windows": [list(map(float, o)) for o in outage_windows], "options": opt, "code": code,
            "version": LEARNING_CACHE_VERSION, "libraries": [np.__version__, pd.__version__]}


def _build(imu, attitude, gnss, outage_windows, opt: dict) -> LearningData:
    ws = all_windows(imu, attitude, gnss, **opt)
    tr, va, info = split_windows(ws, outage_windows, margin_s=float(opt["margin_s"]),
                                 val_fraction=float(opt["val_fraction"]), val_position=opt["val_position"],
                                 protocol=opt["protocol"])
    train, val = ws.subset(tr), ws.subset(va)
    info["outage_windows"] = [list(map(float, o)) for o in outage_windows]
    info["n_screened"] = int(ws.n_screened)
    if opt["target_frame"] not in TARGET_FRAMES:
        raise DataError("train", "target_frame", f"one of {TARGET_FRAMES}", repr(opt["target_frame"]))
    return LearningData(train=train, val=val, norm=Normalizer.fit(train, opt["target_frame"]), info=info,
                        options=opt)


def inner_split(data: LearningData, fraction: float = 0.2, position=None) -> LearningData:
    """A tuning split inside the training windows: a ``fraction`` of ``data.train`` (one block of time, at
    ``position``; default: the ``val_position`` of ``data.options``, as the validation block) becomes the
    validation set, training windows overlapping it are dropped, and the normalization is refit.

    Hyper-parameters chosen on it never see ``data.val``, the block every reported validation error comes from.
    """
    if position is None:
        position = data.options["val_position"]
    tr, va, info = split_windows(data.train, (), margin_s=0.0, val_fraction=fraction, val_position=position)
    train, val = data.train.subset(tr), data.train.subset(va)
    frame = data.options["target_frame"]
    return LearningData(train=train, val=val, norm=Normalizer.fit(train, frame),
                        info={**info, "inner_of": data.info.get("val_block")}, options=dict(data.options))


def split_summary(data: LearningData) -> dict:
    """How the windows of ``data`` were split, and the references on its validation block.

    Returns
    -------
    dict
        ``windows`` (all), ``excluded_outages`` (touching an outage +- margin), ``purged_near_val`` (training
        windows overlapping the validation block), ``screened`` (GNSS increments dropped by
        :func:`bgfn.learning.targets.screen_increments`), ``train``, ``val`` (counts), ``val_block_s``
        (``'<lo>..<hi>'``, s) and the :func:`bgfn.learning.references.reference_rmse` columns (m).
    """
    info = data.info
    return {"windows": info["n_windows"], "excluded_outages": info["n_outage_excluded"],
            "purged_near_val": info["n_purged"], "screened": info["n_screened"], "train": info["n_train"],
            "val": info["n_val"], "val_block_s": block_label(info["val_block"]),
            **reference_columns(reference_rmse(data.val))}
