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


def speed_lines(bench: dict | None, paper_cfg: dict | None = None) -> list[str]:
    """Plain lines for notebook 03: BGFN's training throughput over its ANN twin's (``make bench``'s
    ``train_ratio_bgfn_over_twin``) at each measured size, and at the paper size the ceiling that the
    twin's profiled step over BGFN's matrix products alone sets (``train_ratio_ceiling``; with ``paper_cfg``, the
    ``paper`` profile, its T_s is named), and the same without the profiler (``train_ceiling_replay``). Empty
    without them."""
    time_steps = (((paper_cfg or {}).get("train") or {}).get("sizes") or {}).get("bgfn", {}).get("paper", {}).get(
        "time_steps")
    ratio = (bench or {}).get("train_ratio_bgfn_over_twin") or {}
    if not ratio:
        return []
    sizes = ", ".join(f"{r:.2f} at the {size} size" for size, r in ratio.items())
    lines = [f"BGFN's training throughput over its ANN twin's (windows/s, both measured in one run): {sizes}"]
    ceiling = ((bench or {}).get("train_ratio_ceiling") or {}).get("paper")
    prof = ((bench or {}).get("train_step_profile") or {})
    if ceiling is not None and "paper" in ratio:
        b, t = prof["bgfn"]["paper"], prof["transformer"]["paper"]
        steps = f"with T_s = {time_steps} SNN steps " if time_steps else ""
        lines.append(f"paper size, one profiled training step: BGFN's matrix products alone take {b['matmul_s']:.2f} s "
                     f"of its {b['step_s']:.2f} s, the twin's whole step {t['step_s']:.2f} s; even if its LIF, "
                     f"BatchNorm and copies cost nothing BGFN would reach at most {ceiling:.2f} of the twin's "
                     f"throughput: {steps}every spiking layer multiplies T_s times as many rows as the twin's")
    replay = ((bench or {}).get("train_ceiling_replay") or {}).get("paper")
    if replay and "paper" in ratio:
        lines.append(f"paper size, without the profiler (it slows a step; its own thread shares the cores): BGFN's "
                     f"matrix products, replayed alone, take {replay['matmul_ms']:.0f} ms of its {replay['step_ms']:.0f} "
                     f"ms step ({100 * replay['matmul_share']['median']:.0f} %); the ceiling they set is "
                     f"{replay['ceiling']['median']:.2f}, of which BGFN reaches "
                     f"{100 * ratio['paper'] / replay['ceiling']['median']:.0f} %")
    return lines


def estimate_lines(table: pd.DataFrame | None) -> list[str]:
    """Plain lines for notebook 03: the estimate, or how to get one."""
    if table is None:
        return ["paper profile: not run here; no paper-size training step measured yet -- run `make bench` "
                "(benchmarks/bench_models.py), then this notebook prints the estimated training time"]
    total = float(table["hours"].sum())
    per = ", ".join(f"{r.method} {r.hours:.1f} h ({r.windows_per_s:.1f} windows/s)" for r in table.itertuples())
    return [f"paper profile: not run here; its training would take at most {total:.1f} h on this machine, from "
            f"the measurement ({int(table['epochs'].iloc[0])} epochs x {int(table['runs'].iloc[0])} runs per "
            f"method, without early stopping): {per}"]
