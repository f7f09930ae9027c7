"""How long the paper profile would train on this machine, from a measured training step (``make bench``).

The paper trains for 1000 epochs with batch 8 on an RTX A6000 (Sec. 4.1). Before anyone spends hours on the
``paper`` profile, notebook 03 prints what it would cost here: ``make bench`` (``benchmarks/bench_models.py``)
measures the training throughput of every method at the paper size (``train_windows_per_s.<method>.paper``
in ``results/bench.json``, windows per second, forward + BPTT backward + optimizer step); the estimate
multiplies one epoch over this profile's training windows by the paper's epochs, seeds and datasets. It is an
upper bound (early stopping may end a run sooner) without the learning-rate search and the validation passes.
"""

from __future__ import annotations

import pandas as pd
import torch

from bgfn.models import build_model
from bgfn.train.speed import training_step_profile, training_throughput, twin_ratios


def paper_training_estimate(n_train: dict[str, int], paper_cfg: dict, bench: dict | None) -> pd.DataFrame | None:
    """Hours the paper profile's training would take on the machine that ran ``make bench``.

    Parameters
    ----------
    n_train : dict
        Dataset -> training windows (all of them, as the paper profile trains on: ``max_train_windows: null``).
    paper_cfg : dict
        The ``paper`` profile (:func:`bgfn.config.load_profile`): its methods, seeds and epochs.
    bench : dict or None
        ``results/bench.json`` (:func:`bgfn.train.speed.read_bench`); without a paper-size rate the result is None.

    Returns
    -------
    DataFrame or None
        One row per method: ``windows_per_s`` (measured), ``epoch_s`` (all datasets), ``runs``
        (datasets x seeds), ``epochs``, ``hours`` (upper bound); None when no paper-size rate was measured.
    """
    rates = ((bench or {}).get("train_windows_per_s") or {})
    tc = paper_cfg["train"]
    epochs = int(tc["optimizer"]["epochs"])
    rows = []
    for method in tc["methods"]:
        rate = (rates.get(method) or {}).get("paper")
        if not rate:
            return None
        epoch_s = sum(n / float(rate) for n in n_train.values())          # one epoch of every dataset
        runs = len(n_train) * len(tc["seeds"])
        rows.append({"method": method, "windows_per_s": float(rate), "epoch_s": epoch_s,
                     "runs": runs, "epochs": epochs, "hours": epoch_s * len(tc["seeds"]) * epochs / 3600.0})
    return pd.DataFrame(rows)


def measure_paper_step(paper_cfg: dict, repeats: int = 2) -> dict:
    """The paper-size training throughput of every method, measured now (a few seconds per method), in the
    form of ``results/bench.json`` (``{"train_windows_per_s": {method: {"paper": windows/s}}}``), for when
    ``make bench`` has not run on this machine."""
    tc = paper_cfg["train"]
    window, batch = int(tc["window"]), int(tc["optimizer"]["batch_size"])
    rates, profiles = {}, {}
    for method in dict.fromkeys([*tc["methods"], "transformer"]):         # the twin too, for the speed ratio
        torch.manual_seed(0)
        model = build_model(method, dict(tc["sizes"][method]["paper"]))
        rates[method] = {"paper": training_throughput(model, window, batch, repeats=repeats)}
        if method in ("bgfn", "transformer"):
            profiles[method] = {"paper": training_step_profile(model, window, batch)}
    return {"train_windows_per_s": rates, "measured_by": "bgfn.train.estimate.measure_paper_step",
            "train_step_profile": profiles, **twin_ratios(rates, profiles)}
