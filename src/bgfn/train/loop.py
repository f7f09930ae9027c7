"""One training loop for BGFN and the baselines (paper Sec. 4.1: BPTT, batch 8, 1000 epochs on a GPU).

:func:`train_model` trains one ``(method, seed)`` on a :class:`bgfn.learning.LearningData` and writes the best
checkpoint (``<method>_seed<k>.pt``, enough for :func:`bgfn.train.trained.load_trained`), its card (``.json``: the
history from epoch 0, the initial network, so that ``best_epoch >= 1`` says training improved on it) and, while
training, the state to resume from (``.last.pt``). Every method gets the same budget (:mod:`bgfn.train.options`).
A completed run is not redone: a card with the same configuration hash is returned, and the hash covers the
method, seed, sizes, optimizer, learning options, training data and the source of the models and this loop
(:func:`training_fingerprint`), so a network trained under another definition is trained again.
"""

from __future__ import annotations

import copy
import functools
import hashlib
import json
import os
import random
import time
from pathlib import Path
from typing import Any

import numpy as np
import torch
from spikingjelly.activation_based import functional
from torch import nn
from tqdm import tqdm

from bgfn.errors import DataError
from bgfn.io import atomic_path, atomic_write_json, sources_hash
from bgfn.learning import LearningData
from bgfn.models import build_model, count_parameters, definition_fingerprint, is_spiking
from bgfn.train import checkpoints
from bgfn.train.memory import keep_freed_memory
from bgfn.train.objectives import objective_of
from bgfn.train.options import even_subset, method_lr, optimizer_options
from bgfn.train.trained import pick_device, predict_normalized


def set_seed(seed: int, deterministic: bool = True) -> None:
    """Seed python, numpy and torch; ask torch for deterministic algorithms where they exist."""
    random.seed(seed)
    np.random.seed(seed % 2**32)
    torch.manual_seed(seed)
    if deterministic:
        os.environ.setdefault("CUBLAS_WORKSPACE_CONFIG", ":4096:8")
        torch.use_deterministic_algorithms(True, warn_only=True)
        torch.backends.cudnn.benchmark = False


#: Version of the card's layout in the configuration hash: a card of an older layout is trained again
#: (2: epoch 0 is the initial network).
CARD_VERSION = 2


@functools.cache
def training_fingerprint() -> str:
    """Hash of the training code a run's configuration hash covers besides the network's own
    (:func:`bgfn.models.definition_fingerprint`): this loop and the objectives (targets, losses, references). An edit
    of either trains every network again, as an edit of the data code rebuilds the data cache."""
    here = Path(__file__).resolve()
    return sources_hash([here, here.with_name("objectives.py")])[:16]


def _config_hash(obj: Any) -> str:
    return hashlib.sha256(json.dumps(obj, sort_keys=True, default=str).encode()).hexdigest()[:16]


def _data_fingerprint(data: LearningData) -> str:
    h = hashlib.sha256()
    for a in (data.train.x, data.train.y, data.val.x, data.val.y):
        h.update(np.ascontiguousarray(a).tobytes())
    return h.hexdigest()[:16]


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
    data : LearningData or SpeedData
        Training/validation windows and normalization (:func:`bgfn.learning.build_learning_data`; a learned
        odometer's :func:`bgfn.learning.odometry.build_speed_data`). Its objective
        (:func:`bgfn.train.objectives.objective_of`) sets the targets, the loss, the error and the references.
    size_cfg : dict
        Model constructor keywords (:func:`bgfn.train.options.size_config`).
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
        ``val_rmse_m`` (``val_rmse_mps`` for a speed), the references of the objective on the same windows
        (``val_rmse_zero_m``, ``val_rmse_last_m``, ``val_rmse_ins_m``), ``wall_time_s``, ``device``, ``history``, ...
    """
    size_cfg = dict(size_cfg or {})
    o = optimizer_options(train_cfg)
    lr = method_lr(train_cfg, method)
    dev = pick_device(device)
    if o["num_threads"]:
        torch.set_num_threads(int(o["num_threads"]))
    keep_freed_memory()                                     # no page faults for every step's fresh tensors

    tr_idx = even_subset(len(data.train), o["max_train_windows"])
    va_idx = even_subset(len(data.val), o["max_val_windows"])
    train_ws, val_ws = data.train.subset(tr_idx), data.val.subset(va_idx)
    if len(train_ws) == 0 or len(val_ws) == 0:
        raise DataError("train", "windows", "at least one training and one validation window",
                        f"{len(train_ws)} and {len(val_ws)}")
    in_channels = train_ws.x.shape[-1]
    obj = objective_of(data)                                # the paper's increments, or an odometer's speed
    # the code is part of what a run is: a changed layer or loss trains again (definition and training fingerprints)
    config = {"method": method, "seed": int(seed), "card": CARD_VERSION, "size_cfg": size_cfg, "optimizer": o, "lr": lr,
              "options": data.options, "data": _data_fingerprint(data), "device": dev.type,
              "code": {"model": definition_fingerprint(), "training": training_fingerprint()}}
    chash = _config_hash(config)

    out = Path(out_dir) if out_dir is not None else None
    best_path = out / checkpoints.checkpoint_name(method, seed) if out else None
    card_path = checkpoints.card_path(best_path) if out else None
    last_path = checkpoints.last_path(best_path) if out else None
    if card_path is not None and card_path.exists() and best_path.exists():
        card = json.loads(card_path.read_text())
        if card.get("complete") and card.get("config_hash") == chash:
            # the references need no training: recomputed, so a card written by older code gains new ones
            refs = obj.references(val_ws)
            if any(json.dumps(card.get(k)) != json.dumps(v) for k, v in refs.items()):   # NaN == NaN here
                card.update(refs)
                atomic_write_json(card_path, card)
            return card

    set_seed(seed)
    model = build_model(method, size_cfg, in_channels=in_channels).to(dev)
    optim = torch.optim.AdamW(model.parameters(), lr=lr, weight_decay=o["weight_decay"])
    sched = _make_scheduler(optim, o)
    gen = torch.Generator().manual_seed(int(seed))

    xtr = torch.as_tensor(data.norm.x(train_ws.x))          # [M, N, C]
    ytr = obj.targets(train_ws)                             # [M, 2] increments, or [M, 1] speeds
    xva = data.norm.x(val_ws.x)
    yva = obj.targets(val_ws)
    spiking = is_spiking(model)
    loss_fn = obj.loss

    history: list[dict] = []
    best = {"val_loss": float("inf"), "epoch": -1}
    start_epoch, bad_epochs, elapsed_before = 0, 0, 0.0
    if last_path is not None and last_path.exists():
        st = checkpoints.read_checkpoint(last_path, dev)
        if st.get("config_hash") == chash:
            model.load_state_dict(st["model"])
            optim.load_state_dict(st["optim"])
            if sched is not None and st["sched"] is not None:
                sched.load_state_dict(st["sched"])
            gen.set_state(st["gen"])
            torch.set_rng_state(st["torch_rng"])
            history, best, bad_epochs = st["history"], st["best"], st["bad_epochs"]
            start_epoch, elapsed_before = st["epoch"] + 1, st["elapsed"]

    def keep_best(epoch):                                   # the weights of the best epoch so far
        if best_path is not None:
            _save_torch({"method": method, "size_cfg": size_cfg, "in_channels": in_channels,
                         "state_dict": model.state_dict(), "norm": data.norm.to_dict(),
                         "options": data.options, "epoch": epoch, "config_hash": chash}, best_path)
        else:
            best["state"] = copy.deepcopy(model.state_dict())

    t0 = time.perf_counter()
    if start_epoch == 0:
        # epoch 0 is the initial network, validated before any step: best_epoch >= 1 then says that training
        # improved on it, and a run that never does reports its initial weights as such (no RNG is drawn here)
        te = time.perf_counter()
        pred = predict_normalized(model, xva, o["eval_batch_size"], dev)
        val_loss = float(loss_fn(torch.as_tensor(pred), yva))
        history.append({"epoch": 0, "train_loss": None, "val_loss": val_loss, obj.metric_key: obj.error(pred, val_ws),
                        "lr": optim.param_groups[0]["lr"], "time_s": time.perf_counter() - te})
        best = {"val_loss": val_loss, "epoch": 0}
        keep_best(0)
        start_epoch = 1
    bar = tqdm(range(start_epoch, int(o["epochs"]) + 1), desc=f"{method} seed {seed}", disable=not progress,
               leave=False)
    for epoch in bar:                                       # training epochs 1 .. epochs
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
        val_rmse = obj.error(pred, val_ws)
        cur_lr = optim.param_groups[0]["lr"]
        if sched is not None:
            sched.step(val_loss) if o["schedule"] == "plateau" else sched.step()
        history.append({"epoch": epoch, "train_loss": total / max(count, 1), "val_loss": val_loss,
                        obj.metric_key: val_rmse, "lr": cur_lr, "time_s": time.perf_counter() - te})
        if val_loss < best["val_loss"] * (1.0 - o["min_delta"]):
            best = {"val_loss": val_loss, "epoch": epoch}
            bad_epochs = 0
            keep_best(epoch)
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
    epochs_run = sum(1 for h in history if h["epoch"] >= 1)    # training epochs (epoch 0: the initial network)

    # best weights -> validation metrics
    if best_path is not None and best_path.exists():
        model.load_state_dict(checkpoints.read_checkpoint(best_path, dev)["state_dict"])
    elif "state" in best:
        model.load_state_dict(best.pop("state"))
    pred = predict_normalized(model, xva, o["eval_batch_size"], dev)
    card = {
        "method": method, "seed": int(seed), "params": count_parameters(model), "size_cfg": size_cfg,
        "lr": lr, "optimizer": o, "options": data.options, "in_channels": in_channels,
        "epochs_run": epochs_run, "best_epoch": best["epoch"], "best_val_loss": best["val_loss"],
        "stopped_early": epochs_run < int(o["epochs"]),
        obj.metric_key: obj.error(pred, val_ws), **obj.references(val_ws),
        "n_train": len(train_ws), "n_val": len(val_ws), "split": data.info,
        "wall_time_s": wall, "train_windows_per_s": (len(train_ws) * epochs_run / wall) if wall > 0 else None,
        "device": dev.type if dev.type == "cpu" else torch.cuda.get_device_name(dev),
        "torch_threads": torch.get_num_threads(), "torch": torch.__version__,
        "history": history, "complete": True, "config_hash": chash, **(extra_card or {}),
    }
    if card_path is not None:
        atomic_write_json(card_path, card)
        if last_path.exists():
            last_path.unlink()
    return card
