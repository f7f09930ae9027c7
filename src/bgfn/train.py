"""One training loop for BGFN and the baselines (paper Sec. 4.1: BPTT, batch 8, 1000 epochs on a GPU).

:func:`train_model` trains one ``(method, seed)`` on a :class:`bgfn.learning.LearningData` and writes

- ``<out_dir>/<method>_seed<k>.pt``: the best checkpoint (lowest validation loss): weights, normalization,
  learning options and model size, enough for :func:`load_trained`;
- ``<out_dir>/<method>_seed<k>.json``: the card (parameters, epochs run, best validation loss, wall time,
  device, per-epoch history, validation RMSE of delta_p_gps and of the zero / last-increment references);
- ``<out_dir>/<method>_seed<k>.last.pt`` while training: the state after the last finished epoch (optimizer,
  scheduler, RNG), from which an interrupted run resumes; removed when the run completes.

Every method gets the same budget: AdamW, the same epochs, batch size, schedule and early stopping on the
validation loss (MSE of the normalized increments). Learning rates can differ per method (``lr`` mapping of
the ``train:`` section); the shipped profiles use the same value for all.

A completed run is not redone: if its card exists with the same configuration hash, :func:`train_model`
returns the card (delete the files to retrain).
"""

from __future__ import annotations

import argparse
import copy
import hashlib
import json
import os
import random
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import torch
from torch import nn

from bgfn import checkpoints
from bgfn.config import results_dir
from bgfn.errors import DataError
from bgfn.io import atomic_path, atomic_write_json
from bgfn.learning import (REFERENCES, VAL_POSITIONS, LearningData, Normalizer, WindowSet, all_windows,
                           build_learning_data, from_target_frame, inner_split, learning_options, motion_in_windows,
                           prediction_windows, reference_columns, reference_rmse, rmse, to_target_frame,
                           val_position_coverage)
from bgfn.models import build_model, count_parameters, is_spiking
from bgfn.nav import outages

#: Defaults of the optimization keys (``train.optimizer`` of a profile).
OPTIMIZER_DEFAULTS: dict[str, Any] = {
    "epochs": 1000,             # paper: 1000
    "batch_size": 8,            # paper: 8
    "lr": 1.0e-3,
    "weight_decay": 1.0e-2,
    "schedule": "plateau",      # 'plateau' (ReduceLROnPlateau on val loss), 'cosine' or 'none'
    "lr_factor": 0.5,
    "lr_patience": 5,
    "min_lr": 1.0e-5,
    "patience": 20,             # early stopping: epochs without a better validation loss
    "min_delta": 1.0e-4,        # relative improvement that counts as better
    "grad_clip": 1.0,           # max global gradient norm (0: off)
    "max_train_windows": None,  # evenly spaced subsample of the training windows (None: all)
    "max_val_windows": None,
    "eval_batch_size": 64,
    "num_threads": None,        # torch CPU threads (None: torch's default)
}


# ----------------------------------------------------------------------------------------------- helpers
def set_seed(seed: int, deterministic: bool = True) -> None:
    """Seed python, numpy and torch; ask torch for deterministic algorithms where they exist."""
    random.seed(seed)
    np.random.seed(seed % 2**32)
    torch.manual_seed(seed)
    if deterministic:
        os.environ.setdefault("CUBLAS_WORKSPACE_CONFIG", ":4096:8")
        torch.use_deterministic_algorithms(True, warn_only=True)
        torch.backends.cudnn.benchmark = False


def pick_device(device: str | None = None) -> torch.device:
    """``device`` if given, else CUDA when available, else CPU."""
    if device:
        return torch.device(device)
    return torch.device("cuda" if torch.cuda.is_available() else "cpu")


def _subsection(train_cfg: dict | None, key: str, defaults: dict) -> dict:
    """``train.<key>`` with ``defaults`` filled in; an unknown key raises DataError naming it."""
    opt = dict((train_cfg or {}).get(key) or {})
    unknown = set(opt) - set(defaults)
    if unknown:
        raise DataError(f"train.{key}", sorted(unknown)[0], f"one of {', '.join(defaults)}")
    return {**defaults, **opt}


def optimizer_options(train_cfg: dict | None) -> dict:
    """``train.optimizer`` keys with defaults filled in (unknown keys raise DataError)."""
    return _subsection(train_cfg, "optimizer", OPTIMIZER_DEFAULTS)


def method_lr(train_cfg: dict | None, method: str) -> float:
    """Learning rate of ``method``: ``train.lr[method]`` if set, else ``train.optimizer.lr``."""
    per = (train_cfg or {}).get("lr") or {}
    return float(per.get(method, optimizer_options(train_cfg)["lr"]))


#: ``train.lr_search``: learning rates tried for every method on :func:`bgfn.learning.inner_split` (null: none).
#: ``extend``: when a method's best rate is the grid's smallest or largest, up to this many further rates are
#: tried beyond it, one grid step (the ratio of the two rates at that end) at a time, so no method's choice
#: is cut off by the grid's ends.
LR_SEARCH_DEFAULTS: dict[str, Any] = {"grid": None, "fraction": 0.2, "seed": 0, "extend": 0}
LR_SEARCH_FILE = "lr_search.csv"


def lr_search_options(train_cfg: dict | None) -> dict:
    """``train.lr_search`` with defaults filled in (unknown keys raise DataError)."""
    return _subsection(train_cfg, "lr_search", LR_SEARCH_DEFAULTS)


def search_learning_rates(data: LearningData, methods, train_cfg: dict, out_dir: str | Path | None = None,
                          progress: bool = False) -> pd.DataFrame:
    """Train every method once per learning rate of ``train.lr_search.grid`` on a tuning split inside the
    training windows (:func:`bgfn.learning.inner_split`) and mark the rate with the lowest tuning loss.

    Every method gets the same grid, budget (the profile's optimizer) and seed, so none is tuned more than
    another; the validation block of ``data`` is never used.

    Returns
    -------
    DataFrame
        ``method, lr, tuning_rmse_m, tuning_loss, epochs_run, selected`` (one row per method and rate).
    """
    ls = lr_search_options(train_cfg)
    grid = [float(v) for v in (ls["grid"] or [])]
    if not grid:
        raise DataError("train.lr_search", "grid", "a non-empty list of learning rates", repr(ls["grid"]))
    grid = sorted(set(grid))
    inner = inner_split(data, float(ls["fraction"]))
    rows = []
    for method in methods:
        def tune(lr: float) -> dict:
            cfg = {**train_cfg, "lr": {**(train_cfg.get("lr") or {}), method: lr}}
            sub = Path(out_dir) / f"lr{lr:g}" if out_dir is not None else None
            card = train_model(method, inner, size_config(train_cfg, method), cfg, seed=int(ls["seed"]),
                               out_dir=sub, progress=progress)
            return {"method": method, "lr": lr, "tuning_rmse_m": card["val_rmse_m"],
                    "tuning_loss": card["best_val_loss"], "epochs_run": card["epochs_run"]}

        tried = [tune(lr) for lr in grid]
        for _ in range(int(ls["extend"])):
            nxt = next_learning_rate([r["lr"] for r in tried], min(tried, key=lambda r: r["tuning_loss"])["lr"])
            if nxt is None:
                break
            tried.append(tune(nxt))
        rows += sorted(tried, key=lambda r: r["lr"])
    table = pd.DataFrame(rows)
    best = table.groupby("method", sort=False)["tuning_loss"].idxmin()
    table["selected"] = table.index.isin(best.to_numpy())
    return table


def next_learning_rate(tried, best: float) -> float | None:
    """The rate one grid step beyond ``best`` when ``best`` is the smallest or largest of ``tried``
    (geometric step: the ratio of the two rates at that end); None when ``best`` is inside, or the step is
    undefined (fewer than two positive rates at that end)."""
    rates = sorted(set(float(r) for r in tried))
    if len(rates) < 2:
        return None
    if best == rates[-1] and rates[-2] > 0:
        return rates[-1] * rates[-1] / rates[-2]
    if best == rates[0] and rates[0] > 0:
        return rates[0] * rates[0] / rates[1]
    return None


def with_selected_lr(train_cfg: dict, search: pd.DataFrame | None) -> dict:
    """``train_cfg`` with ``lr`` set to the selected rate of each method in ``search`` (unchanged if None)."""
    if search is None or len(search) == 0:
        return train_cfg
    chosen = search[search["selected"].astype(bool)]
    return {**train_cfg, "lr": {**(train_cfg.get("lr") or {}),
                                **{str(m): float(v) for m, v in zip(chosen["method"], chosen["lr"])}}}


def tuned_train_config(cfg: dict, profile: str, dataset: str) -> dict:
    """The profile's ``train:`` section with the learning rates notebook 03 selected for ``dataset``
    (``tables/lr_search.csv``); unchanged when the profile has no search or it has not run."""
    tc = cfg["train"]
    if not lr_search_options(tc)["grid"]:
        return tc
    path = results_dir(profile, create=False) / "tables" / LR_SEARCH_FILE
    if not path.exists():
        return tc
    table = pd.read_csv(path)
    return with_selected_lr(tc, table[table["dataset"] == dataset])


def size_config(train_cfg: dict, method: str, size: str | None = None) -> dict:
    """Constructor keywords of ``method`` for the named ``size`` (default ``train.size``) from ``train.sizes``."""
    size = size or train_cfg.get("size")
    try:
        return dict(train_cfg["sizes"][method][size] or {})
    except (KeyError, TypeError):
        raise DataError("train.sizes", f"{method}.{size}", "a size block for this method and size") from None


def even_subset(n: int, k: int | None) -> np.ndarray:
    """Indices of ``k`` evenly spaced items of ``n`` (all when ``k`` is None or >= n), sorted and unique."""
    if k is None or k >= n:
        return np.arange(n)
    return np.unique(np.linspace(0, n - 1, int(k)).round().astype(int))


def _config_hash(obj: Any) -> str:
    return hashlib.sha256(json.dumps(obj, sort_keys=True, default=str).encode()).hexdigest()[:16]


def _data_fingerprint(data: LearningData) -> str:
    h = hashlib.sha256()
    for a in (data.train.x, data.train.y, data.val.x, data.val.y):
        h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()[:16]


@torch.no_grad()
def predict_normalized(model: nn.Module, x: np.ndarray | torch.Tensor, batch_size: int = 64,
                       device: torch.device | str = "cpu") -> np.ndarray:
    """Model outputs [M, 2] (normalized units) for normalized inputs ``x`` [M, N, C]; eval mode."""
    from spikingjelly.activation_based import functional

    model.eval()
    xt = torch.as_tensor(x, dtype=torch.float32)
    out = []
    for i in range(0, len(xt), batch_size):
        out.append(model(xt[i:i + batch_size].to(device)).cpu())
        if is_spiking(model):
            functional.reset_net(model)
    return torch.cat(out).numpy() if out else np.zeros((0, 2), np.float32)


# ----------------------------------------------------------------------------------------------- trained model
@dataclass
class TrainedModel:
    """A trained model with what it needs to predict delta_p_gps in metres from raw drive tables."""

    method: str
    model: nn.Module
    norm: Normalizer
    options: dict
    size_cfg: dict
    device: torch.device = torch.device("cpu")

    def predict_windows(self, ws: WindowSet, batch_size: int = 64) -> np.ndarray:
        """delta_p_gps (north, east), m, [M, 2], for the (raw) windows ``ws``."""
        z = self.norm.y_inverse(predict_normalized(self.model, self.norm.x(ws.x), batch_size, self.device))
        return from_target_frame(z, ws.yaw_ref, self.options.get("target_frame", "ned"))

    def predict_increments(self, imu, attitude, epochs) -> np.ndarray:
        """delta_p_gps [K, 2] (m) for the increments ``epochs[i] -> epochs[i+1]`` (pseudo-GNSS epochs of an
        outage, Eq. pred-gps); see :func:`bgfn.learning.prediction_windows`."""
        ws = prediction_windows(imu, attitude, epochs, window=int(self.options["window"]),
                                alignment=self.options["alignment"], yaw_encoding=self.options["yaw_encoding"],
                                extra_channels=tuple(self.options["extra_channels"]))
        return self.predict_windows(ws)

    def increment_table(self, imu, attitude, epochs):
        """:meth:`predict_increments` as the table :class:`bgfn.nav.outages.IncrementPseudoGps` reads:
        ``time`` (end of each increment, s), ``delta_p_n``, ``delta_p_e`` (m)."""
        d = self.predict_increments(imu, attitude, epochs)
        return pd.DataFrame({"time": np.asarray(epochs, float)[1:], "delta_p_n": d[:, 0], "delta_p_e": d[:, 1]})


def load_trained(path: str | Path, device: str | None = None) -> TrainedModel:
    """Load a best checkpoint ``<method>_seed<k>.pt`` written by :func:`train_model`."""
    dev = pick_device(device)
    ck = torch.load(Path(path), map_location=dev, weights_only=False)
    model = build_model(ck["method"], ck["size_cfg"], in_channels=ck["in_channels"]).to(dev)
    model.load_state_dict(ck["state_dict"])
    model.eval()
    return TrainedModel(ck["method"], model, Normalizer.from_dict(ck["norm"]), ck["options"], ck["size_cfg"], dev)


# ----------------------------------------------------------------------------------------------- training
def _save_torch(obj: Any, path: Path) -> None:
    with atomic_path(path) as tmp:
        torch.save(obj, tmp)


def _make_scheduler(opt: torch.optim.Optimizer, o: dict):
    if o["schedule"] == "plateau":
        return torch.optim.lr_scheduler.ReduceLROnPlateau(opt, mode="min", factor=o["lr_factor"],
                                                          patience=o["lr_patience"], min_lr=o["min_lr"])
    if o["schedule"] == "cosine":
        return torch.optim.lr_scheduler.CosineAnnealingLR(opt, T_max=max(1, int(o["epochs"])), eta_min=o["min_lr"])
    if o["schedule"] == "none":
        return None
    raise DataError("train.optimizer", "schedule", "'plateau', 'cosine' or 'none'", repr(o["schedule"]))


def train_model(method: str, data: LearningData, size_cfg: dict | None = None, train_cfg: dict | None = None,
                seed: int = 0, out_dir: str | Path | None = None, device: str | None = None,
                progress: bool = True, extra_card: dict | None = None) -> dict:
    """Train ``method`` on ``data`` with early stopping; return its card (and write it under ``out_dir``).

    Parameters
    ----------
    method : str
        ``bgfn``, ``transformer``, ``at_lstm`` or ``mlp``.
    data : LearningData
        Training/validation windows and normalization (:func:`bgfn.learning.build_learning_data`).
    size_cfg : dict
        Model constructor keywords (:func:`size_config`).
    train_cfg : dict
        A profile's ``train:`` section (uses ``optimizer`` and ``lr``).
    seed : int
        Seed of weights, shuffling and dropout.
    out_dir : path, optional
        Where ``<method>_seed<seed>.{pt,json}`` go; without it nothing is written (and nothing resumed).
    device : str, optional
        ``'cpu'``/``'cuda'``; default CUDA if available.
    progress : bool
        tqdm bar over epochs.
    extra_card : dict, optional
        Added to the card (e.g. dataset, profile).

    Returns
    -------
    dict
        The card: ``method``, ``seed``, ``params``, ``epochs_run``, ``best_epoch``, ``best_val_loss``,
        ``val_rmse_m``, the references of :func:`bgfn.learning.reference_rmse` on the same windows
        (``val_rmse_zero_m``, ``val_rmse_last_m``, ``val_rmse_ins_m``), ``wall_time_s``, ``device``, ``history``, ...
    """
    from spikingjelly.activation_based import functional
    from tqdm import tqdm

    size_cfg = dict(size_cfg or {})
    o = optimizer_options(train_cfg)
    lr = method_lr(train_cfg, method)
    dev = pick_device(device)
    if o["num_threads"]:
        torch.set_num_threads(int(o["num_threads"]))

    tr_idx = even_subset(len(data.train), o["max_train_windows"])
    va_idx = even_subset(len(data.val), o["max_val_windows"])
    train_ws, val_ws = data.train.subset(tr_idx), data.val.subset(va_idx)
    if len(train_ws) == 0 or len(val_ws) == 0:
        raise DataError("train", "windows", "at least one training and one validation window",
                        f"{len(train_ws)} and {len(val_ws)}")
    in_channels = train_ws.x.shape[-1]
    config = {"method": method, "seed": int(seed), "size_cfg": size_cfg, "optimizer": o, "lr": lr,
              "options": data.options, "data": _data_fingerprint(data), "device": dev.type}
    chash = _config_hash(config)

    out = Path(out_dir) if out_dir is not None else None
    best_path = out / checkpoints.checkpoint_name(method, seed) if out else None
    card_path = checkpoints.card_path(best_path) if out else None
    last_path = checkpoints.last_path(best_path) if out else None
    if card_path is not None and card_path.exists() and best_path.exists():
        card = json.loads(card_path.read_text())
        if card.get("complete") and card.get("config_hash") == chash:
            # the references need no training: recomputed, so a card written by older code gains new ones
            refs = reference_columns(reference_rmse(val_ws))
            if any(json.dumps(card.get(k)) != json.dumps(v) for k, v in refs.items()):   # NaN == NaN here
                card.update(refs)
                atomic_write_json(card_path, card)
            return card

    set_seed(seed)
    model = build_model(method, size_cfg, in_channels=in_channels).to(dev)
    optim = torch.optim.AdamW(model.parameters(), lr=lr, weight_decay=o["weight_decay"])
    sched = _make_scheduler(optim, o)
    gen = torch.Generator().manual_seed(int(seed))

    frame = data.options.get("target_frame", "ned")
    xtr = torch.as_tensor(data.norm.x(train_ws.x))          # [M, N, C]
    ytr = torch.as_tensor(data.norm.y(to_target_frame(train_ws.y, train_ws.yaw_ref, frame)))   # [M, 2]
    xva = data.norm.x(val_ws.x)
    yva = torch.as_tensor(data.norm.y(to_target_frame(val_ws.y, val_ws.yaw_ref, frame)))

    def to_metres(pred_normalized):                         # model outputs -> (dN, dE), m
        return from_target_frame(data.norm.y_inverse(pred_normalized), val_ws.yaw_ref, frame)
    spiking = is_spiking(model)
    loss_fn = nn.MSELoss()

    history: list[dict] = []
    best = {"val_loss": float("inf"), "epoch": -1}
    start_epoch, bad_epochs, elapsed_before = 0, 0, 0.0
    if last_path is not None and last_path.exists():
        st = torch.load(last_path, map_location=dev, weights_only=False)
        if st.get("config_hash") == chash:
            model.load_state_dict(st["model"])
            optim.load_state_dict(st["optim"])
            if sched is not None and st["sched"] is not None:
                sched.load_state_dict(st["sched"])
            gen.set_state(st["gen"])
            torch.set_rng_state(st["torch_rng"])
            history, best, bad_epochs = st["history"], st["best"], st["bad_epochs"]
            start_epoch, elapsed_before = st["epoch"] + 1, st["elapsed"]

    t0 = time.perf_counter()
    bar = tqdm(range(start_epoch, int(o["epochs"])), desc=f"{method} seed {seed}", disable=not progress, leave=False)
    for epoch in bar:
        if bad_epochs >= o["patience"]:
            break
        te = time.perf_counter()
        model.train()
        perm = torch.randperm(len(xtr), generator=gen)
        total, count = 0.0, 0
        for i in range(0, len(perm), o["batch_size"]):
            b = perm[i:i + o["batch_size"]]
            if len(b) < 2 and len(perm) > 1:      # BatchNorm needs 2 samples; drop a last singleton batch
                continue
            xb, yb = xtr[b].to(dev), ytr[b].to(dev)
            optim.zero_grad(set_to_none=True)
            loss = loss_fn(model(xb), yb)
            loss.backward()                        # BPTT through the T_s steps for BGFN
            if o["grad_clip"]:
                nn.utils.clip_grad_norm_(model.parameters(), o["grad_clip"])
            optim.step()
            if spiking:
                functional.reset_net(model)        # no membrane state carried to the next batch
            total += float(loss.detach()) * len(b)
            count += len(b)
        pred = predict_normalized(model, xva, o["eval_batch_size"], dev)
        val_loss = float(loss_fn(torch.as_tensor(pred), yva))
        val_rmse = rmse(to_metres(pred), val_ws.y)
        cur_lr = optim.param_groups[0]["lr"]
        if sched is not None:
            sched.step(val_loss) if o["schedule"] == "plateau" else sched.step()
        history.append({"epoch": epoch, "train_loss": total / max(count, 1), "val_loss": val_loss,
                        "val_rmse_m": val_rmse, "lr": cur_lr, "time_s": time.perf_counter() - te})
        if val_loss < best["val_loss"] * (1.0 - o["min_delta"]):
            best = {"val_loss": val_loss, "epoch": epoch}
            bad_epochs = 0
            if best_path is not None:
                _save_torch({"method": method, "size_cfg": size_cfg, "in_channels": in_channels,
                             "state_dict": model.state_dict(), "norm": data.norm.to_dict(),
                             "options": data.options, "epoch": epoch, "config_hash": chash}, best_path)
            else:
                best["state"] = copy.deepcopy(model.state_dict())
        else:
            bad_epochs += 1
        bar.set_postfix(train=f"{history[-1]['train_loss']:.3f}", val=f"{val_loss:.3f}", rmse=f"{val_rmse:.2f}")
        if last_path is not None:
            _save_torch({"model": model.state_dict(), "optim": optim.state_dict(),
                         "sched": sched.state_dict() if sched is not None else None, "gen": gen.get_state(),
                         "torch_rng": torch.get_rng_state(), "history": history,
                         "best": {k: v for k, v in best.items() if k != "state"}, "bad_epochs": bad_epochs,
                         "epoch": epoch, "elapsed": elapsed_before + time.perf_counter() - t0,
                         "config_hash": chash}, last_path)
    wall = elapsed_before + time.perf_counter() - t0

    # best weights -> validation metrics
    if best_path is not None and best_path.exists():
        model.load_state_dict(torch.load(best_path, map_location=dev, weights_only=False)["state_dict"])
    elif "state" in best:
        model.load_state_dict(best.pop("state"))
    pred_m = to_metres(predict_normalized(model, xva, o["eval_batch_size"], dev))
    refs = reference_rmse(val_ws)
    card = {
        "method": method, "seed": int(seed), "params": count_parameters(model), "size_cfg": size_cfg,
        "lr": lr, "optimizer": o, "options": data.options, "in_channels": in_channels,
        "epochs_run": len(history), "best_epoch": best["epoch"], "best_val_loss": best["val_loss"],
        "stopped_early": len(history) < int(o["epochs"]),
        "val_rmse_m": rmse(pred_m, val_ws.y), **reference_columns(refs),
        "n_train": len(train_ws), "n_val": len(val_ws), "split": data.info,
        "wall_time_s": wall, "train_windows_per_s": (len(train_ws) * len(history) / wall) if wall > 0 else None,
        "device": dev.type if dev.type == "cpu" else torch.cuda.get_device_name(dev),
        "torch_threads": torch.get_num_threads(), "torch": torch.__version__,
        "history": history, "complete": True, "config_hash": chash, **(extra_card or {}),
    }
    if card_path is not None:
        atomic_write_json(card_path, card)
        if last_path.exists():
            last_path.unlink()
    return card


# ----------------------------------------------------------------------------------------------- profiles
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
        Evaluation outages; default: the profile's (:func:`bgfn.nav.outages.outage_windows`).
    """
    from bgfn.data import load_drive

    if drive is None:
        drive = load_drive(dataset, profile=cfg["profile"])
    attitude, outage_windows, opts = _learning_inputs(cfg, drive, attitude, outage_windows)
    return build_learning_data(drive.imu, attitude, drive.gnss, outage_windows, **opts)


def _learning_inputs(cfg: dict, drive, attitude=None, outage_windows=None) -> tuple:
    """``(attitude, outage_windows, learning options)`` of the profile, defaults filled in."""
    attitude = attitude if attitude is not None else ins_attitude(drive, cfg)
    if outage_windows is None:
        outage_windows = outages.outage_windows(cfg)
    return attitude, outage_windows, learning_options(cfg.get("train"))


def val_position_table(cfg: dict, drive, attitude=None, outage_windows=None, positions=None):
    """:func:`bgfn.learning.val_position_coverage` of ``drive`` with the profile's learning options: what each
    place of the validation block would leave to training (notebook 03)."""
    attitude, outage_windows, opts = _learning_inputs(cfg, drive, attitude, outage_windows)
    ws = all_windows(drive.imu, attitude, drive.gnss, **opts)
    return val_position_coverage(ws, motion_in_windows(drive.reference, outage_windows), outage_windows,
                                 margin_s=float(opts["margin_s"]), val_fraction=float(opts["val_fraction"]),
                                 positions=positions or VAL_POSITIONS)


def ins_attitude(drive, cfg: dict):
    """INS/KF solution at IMU rate (reference schema): ``roll, pitch, yaw`` are the attitude input of Eq. (eq21).

    The other columns (``v_n``, ``v_e``, ...) are there for ``train.extra_channels`` (not the paper's input).

    ``train.attitude_source``: ``'kf'`` (default, the paper's online-training mode) runs the 15-state loosely
    coupled filter with the GNSS fixes and the profile's ``nav:`` section (:func:`bgfn.nav.baseline.run_drive`);
    ``'reference'`` takes the truth attitude
    (debugging only: the outage evaluation feeds the INS attitude).
    """

    src = (cfg.get("train") or {}).get("attitude_source", "kf")
    if src == "reference":
        return drive.reference.copy()
    if src != "kf":
        raise DataError("train", "attitude_source", "'kf' or 'reference'", repr(src))
    from bgfn.nav import run_drive

    traj = run_drive(drive, cfg.get("nav") or {}).trajectory
    return pd.DataFrame(traj).reset_index(drop=True)


def train_profile(profile: str, datasets=None, methods=None, seeds=None, device: str | None = None,
                  progress: bool = True, outage_windows=None) -> list[dict]:
    """Train every ``(dataset, method, seed)`` of a profile's ``train:`` section; return the cards.

    The learning rates are those notebook 03 selected (:func:`tuned_train_config`) when its search has run.
    """
    from bgfn.config import load_profile

    cfg = load_profile(profile)
    cards = []
    for dataset in datasets or cfg["train"]["datasets"]:
        tc = tuned_train_config(cfg, profile, dataset)
        data = prepare_learning_data(cfg, dataset, outage_windows=outage_windows)
        out = checkpoints.models_dir(profile, dataset)
        for method in methods or tc["methods"]:
            for seed in seeds if seeds is not None else tc["seeds"]:
                cards.append(train_model(method, data, size_config(tc, method), tc, seed=seed, out_dir=out,
                                         device=device, progress=progress,
                                         extra_card={"dataset": dataset, "profile": profile,
                                                     "size": tc.get("size")}))
    return cards


# ----------------------------------------------------------------------------------------------- reporting
def cards_table(cards: list[dict]):
    """One row per run: dataset, method, seed, params, learning rate, epochs, wall time, validation RMSE and
    references (m)."""
    cols = ["dataset", "method", "seed", "params", "lr", "epochs_run", "best_epoch", "wall_time_s", "n_train", "n_val",
            "val_rmse_m", *REFERENCES.values(), "device"]
    return pd.DataFrame([{c: card.get(c) for c in cols} for card in cards], columns=cols)


#: Wall-clock columns of :func:`cards_table` / :func:`summary_table`: they vary from run to run, so the result
#: tables are saved without them (:func:`without_timing`) and the times go to a table of their own.
TIMING_COLUMNS = ("wall_time_s", "train_time_s_mean", "train_time_s_total")


def without_timing(table):
    """``table`` without :data:`TIMING_COLUMNS`: the same profile run twice gives byte-identical tables."""
    return table.drop(columns=[c for c in TIMING_COLUMNS if c in table.columns])


def timing_table(table):
    """The key columns of ``table`` and its :data:`TIMING_COLUMNS` (wall-clock seconds)."""
    keys = [c for c in ("dataset", "method", "seed") if c in table.columns]
    return table[keys + [c for c in TIMING_COLUMNS if c in table.columns]]


def summary_table(cards: list[dict]):
    """Per dataset and method: parameters, epochs, training time and validation RMSE over seeds (mean, std)."""
    runs = cards_table(cards)
    g = runs.groupby(["dataset", "method"], sort=False)
    out = g.agg(params=("params", "first"), lr=("lr", "first"), seeds=("seed", "count"),
                epochs_mean=("epochs_run", "mean"),
                train_time_s_mean=("wall_time_s", "mean"), train_time_s_total=("wall_time_s", "sum"),
                val_rmse_m_mean=("val_rmse_m", "mean"), val_rmse_m_std=("val_rmse_m", "std"),
                **{col: (col, "first") for col in REFERENCES.values()})
    return out.reset_index()


def plot_training_curves(cards: list[dict], title: str = ""):
    """Training (dashed) and validation (solid) loss per epoch, one panel per method, one line per seed."""
    import matplotlib.pyplot as plt

    methods = list(dict.fromkeys(c["method"] for c in cards))
    fig, axes = plt.subplots(1, len(methods), figsize=(3.6 * len(methods), 3.2), squeeze=False, sharey=True)
    for ax, m in zip(axes[0], methods):
        for i, c in enumerate(c for c in cards if c["method"] == m):
            ep = [h["epoch"] for h in c["history"]]
            color = f"C{i}"
            ax.plot(ep, [h["train_loss"] for h in c["history"]], "--", color=color, lw=1)
            ax.plot(ep, [h["val_loss"] for h in c["history"]], "-", color=color, lw=1.5,
                    label=f"seed {c['seed']}")
            ax.plot(c["best_epoch"], c["best_val_loss"], "o", color=color, ms=4)
        ax.set_yscale("log")
        ax.set_title(m)
        ax.set_xlabel("epoch")
        ax.grid(alpha=0.3)
    axes[0, 0].set_ylabel("MSE (normalized): -- train, - validation")
    axes[0, -1].legend(fontsize=8)
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def plot_val_predictions(data: LearningData, predictions: dict, title: str = "", segment_s: float = 120.0):
    """Predicted against true delta_p_gps on the validation windows: a time segment and scatter plots.

    Parameters
    ----------
    data : LearningData
    predictions : dict
        ``{method: [M, 2] array}`` (north, east, m) for ``data.val``.
    """
    import matplotlib.pyplot as plt

    val = data.val
    t = val.t_to
    seg = np.flatnonzero(t <= t[0] + segment_s)
    # break the lines where windows are missing (excluded outages, GNSS gaps)
    step = np.median(np.diff(t)) if len(t) > 1 else 1.0
    gap = np.concatenate([[False], np.diff(t[seg]) > 1.5 * step])

    def broken(a):
        a = np.asarray(a, dtype=float)[seg]
        return np.insert(a, np.flatnonzero(gap), np.nan)
    fig, axes = plt.subplots(2, 2, figsize=(12, 6.5), gridspec_kw={"width_ratios": [2.2, 1]})
    for row, (k, name) in enumerate(((0, "north"), (1, "east"))):
        ax = axes[row, 0]
        ax.plot(broken(t - t[0]), broken(val.y[:, k]), "k-", lw=2, label="GNSS (true)")
        for i, (m, p) in enumerate(predictions.items()):
            ax.plot(broken(t - t[0]), broken(p[:, k]), "-", color=f"C{i}", lw=1, label=m)
        ax.set_ylabel(f"delta_p_gps {name}, m")
        ax.grid(alpha=0.3)
        sc = axes[row, 1]
        lim = np.nanmax(np.abs(val.y[:, k])) * 1.1
        sc.plot([-lim, lim], [-lim, lim], "k-", lw=0.8)
        for i, (m, p) in enumerate(predictions.items()):
            sc.plot(val.y[:, k], p[:, k], ".", color=f"C{i}", ms=2, alpha=0.5, label=m)
        sc.set_xlabel(f"true {name}, m")
        sc.set_ylabel(f"predicted {name}, m")
        sc.set_aspect("equal")
        sc.grid(alpha=0.3)
    axes[1, 0].set_xlabel(f"time since {t[0]:.1f} s (validation block), s")
    axes[0, 0].legend(fontsize=8, ncol=3)
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def plot_motion_coverage(sets: dict, title: str = ""):
    """Heading and speed histograms of the windows a network trains on, is validated on and meets in the
    outages. ``sets``: ``{label: DataFrame with heading_deg, speed_mps}`` (:func:`bgfn.learning.motion_of_windows`,
    :func:`bgfn.learning.motion_in_windows`)."""
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(11, 3.4))
    for i, (label, df) in enumerate(sets.items()):
        axes[0].hist(df["heading_deg"], bins=np.arange(0, 361, 15), density=True, histtype="step", lw=1.5,
                     color=f"C{i}", label=f"{label} ({len(df)})")
        axes[1].hist(df["speed_mps"], bins=np.arange(0, max(25.0, float(df["speed_mps"].max()) + 1), 1.0),
                     density=True, histtype="step", lw=1.5, color=f"C{i}", label=label)
    axes[0].set_xlabel("heading (INS yaw), deg")
    axes[1].set_xlabel("speed over the increment, m/s")
    for ax in axes:
        ax.set_ylabel("density")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def main(argv=None) -> None:
    p = argparse.ArgumentParser(description="Train BGFN and baselines for a profile.")
    p.add_argument("--profile", default="quick")
    p.add_argument("--dataset", action="append")
    p.add_argument("--method", action="append")
    p.add_argument("--seed", action="append", type=int)
    p.add_argument("--device")
    a = p.parse_args(argv)
    for c in train_profile(a.profile, a.dataset, a.method, a.seed, a.device):
        print(f"{c['dataset']:>16} {c['method']:>12} seed {c['seed']}: val RMSE {c['val_rmse_m']:.3f} m "
              f"(zero {c['val_rmse_zero_m']:.3f}, last {c['val_rmse_last_m']:.3f}, INS {c['val_rmse_ins_m']:.3f}), "
              f"{c['epochs_run']} epochs, {c['wall_time_s']:.1f} s")


if __name__ == "__main__":
    main()
