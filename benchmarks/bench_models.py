"""Training throughput and inference latency of BGFN and the baselines at the quick and paper sizes.

Adds to ``results/bench.json``:

- ``train_windows_per_s.<model>.<size>``: training windows per second (forward + BPTT backward + AdamW step),
  batch = the profile's batch size, window N = the profile's window, torch's default CPU threads;
- ``infer_ms.<model>.<size>``: latency of one window (batch 1, eval mode, 1 CPU thread), ms;
- ``train_ratio_bgfn_over_twin.<size>``: BGFN's training throughput divided by its ANN twin's (Transformer),
  measured interleaved (twin step, BGFN step, twin, BGFN, ... in one process, a warm-up round discarded) and
  taken round by round, so a busy neighbour slows both alike; ``train_ratio_spread.<size>``: that ratio's median,
  quartiles, rounds and ``unreliable`` (the interquartile range wider than the ratio's distance from 1);
- ``train_step_profile.<model>.<size>``: training steps of BGFN and its twin under ``torch.profiler``, interleaved
  (:data:`PROFILE_ROUNDS` rounds, :func:`bgfn.train.speed.interleaved_profiles`): the medians of all operators and
  of the dense matrix products alone, s; ``train_ratio_ceiling.<size>``: the median over the rounds of the twin's
  profiled step over BGFN's matrix products alone, the ratio BGFN would reach if everything but its matrix
  arithmetic (LIF, BatchNorm, copies) cost nothing; ``train_ceiling_spread.<size>``: its quartiles and those of
  BGFN's matrix products over its own profiled step (``matmul_share``, :func:`bgfn.train.speed.ceiling_spread`);
- ``train_ceiling_replay.<size>``: the same two figures without the profiler (which slows the step: its own thread
  shares the cores): BGFN's matrix products recorded once (:func:`bgfn.train.speed.matmul_calls`) and replayed alone
  on operands of the same shapes (:func:`bgfn.train.speed.matmul_replay`), timed in the same interleaved rounds as
  the two steps, so each round gives the twin's step over those products and the products over BGFN's step
  (``ceiling``, ``matmul_share``: quartiles; ``matmul_ms``, ``step_ms``: medians of the two, ms);
- ``models_bench``: what ran (threads, device, batch, window, parameter counts, repeats).

Sizes come from ``train.sizes`` of ``params/<size>.yaml`` (the same blocks in every profile). Median of a
few repeats after a warm-up (the pair BGFN/twin: :data:`PAIR_ROUNDS` interleaved rounds); the paper size gets
fewer repeats so that the whole script runs in minutes.
"""

from __future__ import annotations

import sys

import torch

from bgfn.profile_schema import load_profile
from bgfn.io import update_json
from bgfn.models import METHODS, build_model, count_parameters
from bgfn.report.training_words import ratio_text
from bgfn.train.speed import (bench_file, ceiling_spread, interleaved_profiles, interleaved_times, matmul_calls,
                              matmul_replay, median_profile, median_time, paired_ratio, quartiles,
                              training_step, training_throughput, twin_ratios)

SIZES = ("quick", "paper")
#: (training steps, inference calls) measured per size, after one warm-up each.
REPEATS = {"quick": (5, 30), "paper": (2, 5)}
#: Interleaved rounds of the BGFN / twin training steps per size (after one warm-up round).
PAIR_ROUNDS = {"quick": 21, "paper": 9}
#: Interleaved rounds of the profiled BGFN / twin training steps per size (after one warm-up round): one profile of
#: each varied the ceiling by a quarter from run to run (0.41-0.53 at the paper size on one machine).
PROFILE_ROUNDS = {"quick": 7, "paper": 5}
PAIR = ("bgfn", "transformer")


def bench(model_name: str, size: str) -> tuple[float, float, int, dict]:
    cfg = load_profile(size)["train"]
    size_cfg = dict(cfg["sizes"][model_name][size])
    batch, window = int(cfg["optimizer"]["batch_size"]), int(cfg["window"])
    n_train, n_infer = REPEATS[size]
    torch.manual_seed(0)
    model = build_model(model_name, size_cfg)
    threads = torch.get_num_threads()
    rate = training_throughput(model, window, batch, repeats=n_train)
    x1 = torch.randn(1, window, 9)
    model.eval()
    torch.set_num_threads(1)
    try:
        with torch.no_grad():
            infer_s = median_time(lambda: model(x1), n_infer)
    finally:
        torch.set_num_threads(threads)
    return rate, 1e3 * infer_s, count_parameters(model), {"batch": batch, "window": window,
                                                                      "repeats": [n_train, n_infer]}


def pair_steps(size: str) -> dict:
    """One training step (:func:`bgfn.train.speed.training_step`) of BGFN and of its twin at ``size``."""
    cfg = load_profile(size)["train"]
    batch, window = int(cfg["optimizer"]["batch_size"]), int(cfg["window"])
    steps = {}
    for m in PAIR:
        torch.manual_seed(0)
        steps[m] = training_step(build_model(m, dict(cfg["sizes"][m][size])), window, batch)
    return steps


def main(sizes=SIZES, methods=METHODS) -> dict:
    train_rate: dict = {m: {} for m in methods}
    infer_ms: dict = {m: {} for m in methods}
    info: dict = {"threads_train": torch.get_num_threads(), "threads_infer": 1, "device": "cpu",
                  "torch": torch.__version__, "params": {m: {} for m in methods}, "problem": {}}
    for size in sizes:
        for m in methods:
            rate, ms, n_params, prob = bench(m, size)
            train_rate[m][size] = rate
            infer_ms[m][size] = ms
            info["params"][m][size] = n_params
            info["problem"][size] = prob
            print(f"{m:>12} {size:>6}: {rate:9.1f} train windows/s, {ms:8.2f} ms/window inference, "
                  f"{n_params} parameters", flush=True)
    # BGFN's training throughput over its ANN twin's, interleaved round by round, and the ceiling its matrix
    # products set (the twin's profiled step over BGFN's matrix products alone)
    spread, ceilings, profiles, replayed = {}, {}, {}, {}
    if all(m in methods for m in PAIR):
        for size in sizes:
            steps = pair_steps(size)
            # BGFN's matrix products alone, unprofiled, in the same rounds as the two steps
            matmuls = matmul_replay(matmul_calls(steps["bgfn"]))
            times = interleaved_times({**steps, "bgfn_matmuls": matmuls}, PAIR_ROUNDS[size])
            replayed[size] = ceiling_spread([{"step_s": t} for t in times["transformer"]],
                                            [{"step_s": b, "matmul_s": mm}
                                             for b, mm in zip(times["bgfn"], times["bgfn_matmuls"])])
            replayed[size]["matmul_ms"] = 1e3 * quartiles(times["bgfn_matmuls"])["median"]
            replayed[size]["step_ms"] = 1e3 * quartiles(times["bgfn"])["median"]
            spread[size] = paired_ratio(times["transformer"], times["bgfn"])    # BGFN's throughput / the twin's
            for m in PAIR:
                q = quartiles(times[m])
                train_rate[m][size] = info["problem"][size]["batch"] / q["median"]
                info.setdefault("pair_step_s", {}).setdefault(m, {})[size] = q
            prof = interleaved_profiles(steps, PROFILE_ROUNDS[size])
            ceilings[size] = ceiling_spread(prof["transformer"], prof["bgfn"])
            for m in PAIR:
                profiles.setdefault(m, {})[size] = median_profile(prof[m])
    ratios = twin_ratios(train_rate, profiles)
    ratios["train_ratio_bgfn_over_twin"].update({size: r["median"] for size, r in spread.items()})
    # the ceiling as the median of its per-round values (twin_ratios divides the median profiles), so that it is the
    # middle of the interquartile range printed beside it
    ratios["train_ratio_ceiling"].update({size: c["ceiling"]["median"] for size, c in ceilings.items()})
    ratio, ceiling = ratios["train_ratio_bgfn_over_twin"], ratios["train_ratio_ceiling"]
    for size, r in ratio.items():
        c = ceiling.get(size, float("nan"))
        text = (f"BGFN / Transformer training throughput, {size}: "
                + (ratio_text(spread[size]) if size in spread else f"{r:.2f}")
                + f"; ceiling (twin's step / BGFN's matrix products alone) {c:.2f}")
        if size in ceilings:
            cq, sq = ceilings[size]["ceiling"], ceilings[size]["matmul_share"]
            text += (f" [IQR {cq['q25']:.2f}-{cq['q75']:.2f}, {cq['rounds']} profiled rounds]: {100 * r / c:.0f} % of "
                     f"it; BGFN's matrix products {100 * sq['median']:.0f} % [IQR {100 * sq['q25']:.0f}-"
                     f"{100 * sq['q75']:.0f} %] of its own profiled step")
        else:
            text += f": {100 * r / c:.0f} % of it"
        if size in replayed:
            cq, sq = replayed[size]["ceiling"], replayed[size]["matmul_share"]
            text += (f"\n    without the profiler: BGFN's matrix products replayed alone {replayed[size]['matmul_ms']:.0f} ms "
                     f"of its {replayed[size]['step_ms']:.0f} ms step, {100 * sq['median']:.0f} % [IQR {100 * sq['q25']:.0f}-"
                     f"{100 * sq['q75']:.0f} %]; ceiling {cq['median']:.2f} [IQR {cq['q25']:.2f}-{cq['q75']:.2f}]: "
                     f"{100 * r / cq['median']:.0f} % of it")
        print(text, flush=True)
    update_json(bench_file(),
                {"train_windows_per_s": train_rate, "infer_ms": infer_ms, "models_bench": info,
                 "train_step_profile": profiles, "train_ratio_spread": spread, "train_ceiling_spread": ceilings,
                 "train_ceiling_replay": replayed,
                 **ratios})
    return {"train_windows_per_s": train_rate, "infer_ms": infer_ms, "train_ratio_bgfn_over_twin": ratio}


if __name__ == "__main__":
    main(sizes=tuple(sys.argv[1:]) or SIZES)
