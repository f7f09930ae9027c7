"""CPU timing helpers: latency per prediction, throughput, and whether a model keeps up with the sensor rates.

BGFN predicts the GNSS position increment from the last ``N`` IMU samples (paper Sec. 3.2). Run on line, a
prediction is due at every GNSS epoch during an outage (1 Hz here) and, if the network is to follow every IMU
sample, at the IMU rate (100 Hz). A model *keeps up* with a rate ``f`` if one prediction (batch 1) takes at
most ``1 / f``: 10 ms for the 100 Hz IMU, 1 s for 1 Hz GNSS.

The figures quoted in the book come from ``make bench`` (``benchmarks/bench_models.py`` for the latency,
``benchmarks/bench_speed.py`` for the throughput and the real-time flags, both into ``results/bench.json``),
never from tests: timings depend on the machine.
"""

from __future__ import annotations

import contextlib
import json
import os
import statistics
import sys
import time
from pathlib import Path
from typing import Callable, Iterator

import torch
from torch import nn

from bgfn.config import RESULTS_ROOT
from bgfn.train.memory import keep_freed_memory

#: IMU rate of the Turin drive, Hz.
IMU_RATE_HZ = 100.0
#: GNSS rate of the low-cost receiver (and of the pseudo-GNSS predictions during an outage), Hz.
GNSS_RATE_HZ = 1.0


def bench_file() -> Path:
    """``results/bench.json``: what ``make bench`` measured on this machine (every benchmark merges into it)."""

    return RESULTS_ROOT / "bench.json"


def read_bench(path: str | Path | None = None) -> dict:
    """The parsed ``bench.json`` (default :func:`bench_file`); ``{}`` when ``make bench`` has not run."""
    p = Path(path) if path is not None else bench_file()
    return json.loads(p.read_text(encoding="utf-8")) if p.is_file() else {}


@contextlib.contextmanager
def torch_threads(n: int | None) -> Iterator[None]:
    """Run the block with ``n`` torch CPU threads (``None``: leave as is); restore the old number after."""
    old = torch.get_num_threads()
    if n:
        torch.set_num_threads(int(n))
    try:
        yield
    finally:
        torch.set_num_threads(old)


def median_time(fn: Callable[[], object], repeats: int, warmup: int = 1) -> float:
    """Median wall time of ``fn()`` over ``repeats`` calls after ``warmup`` untimed calls, s."""
    if repeats < 1:
        raise ValueError(f"repeats must be >= 1, got {repeats}")
    for _ in range(warmup):
        fn()
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def _interleaved(fns: dict[str, Callable[[], object]], repeats: int, warmup: int, measure: Callable) -> dict:
    """``measure(fn)`` of every callable of ``fns`` in turn (A, B, A, B, ...) ``repeats`` times, after ``warmup``
    rounds of plain calls: per name the list of what ``measure`` returned."""
    if repeats < 1:
        raise ValueError(f"repeats must be >= 1, got {repeats}")
    for _ in range(warmup):
        for fn in fns.values():
            fn()
    out: dict[str, list] = {name: [] for name in fns}
    for _ in range(repeats):
        for name, fn in fns.items():
            out[name].append(measure(fn))
    return out


def _wall_time(fn: Callable[[], object]) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def interleaved_times(fns: dict[str, Callable[[], object]], repeats: int, warmup: int = 1) -> dict[str, list[float]]:
    """Wall times of every callable of ``fns``, measured in turn (A, B, A, B, ...) ``repeats`` times after
    ``warmup`` untimed rounds, s.

    Interleaving exposes each callable to the same neighbours: a process that takes one core for a while slows
    the A and the B of the same rounds, so their per-round ratio stays, where timing all A's and then all B's
    would turn the comparison upside down.
    """
    return _interleaved(fns, repeats, warmup, _wall_time)


def quartiles(values) -> dict[str, float]:
    """``{'median', 'q25', 'q75'}`` of ``values`` (inclusive method; one value: all three equal)."""
    v = sorted(float(x) for x in values)
    if not v:
        raise ValueError("quartiles of no values")
    if len(v) == 1:
        return {"median": v[0], "q25": v[0], "q75": v[0]}
    q25, q50, q75 = statistics.quantiles(v, n=4, method="inclusive")
    return {"median": q50, "q25": q25, "q75": q75}


def paired_ratio(numerator: list[float], denominator: list[float], reference: float = 1.0) -> dict:
    """The ratio of two interleaved series, round by round (:func:`interleaved_times`): median and interquartile
    range of ``numerator[i] / denominator[i]``.

    ``unreliable`` is True when the interquartile range is wider than the difference the ratio reports, i.e. than
    ``|median - reference|`` (``reference`` 1: "the two are equally fast"): then the measurement cannot tell
    which one is faster, or by how much.
    """
    if len(numerator) != len(denominator) or not numerator:
        raise ValueError("paired_ratio needs two series of the same, non-zero length")
    q = quartiles([a / b for a, b in zip(numerator, denominator)])
    return {**q, "iqr": q["q75"] - q["q25"], "rounds": len(numerator),
            "unreliable": bool(q["q75"] - q["q25"] > abs(q["median"] - reference))}


def _infer(model: nn.Module, x: torch.Tensor) -> Callable[[], object]:
    model.eval()

    def run():
        with torch.no_grad():
            return model(x)            # BGFN resets its membranes at the start of every forward pass
    return run


def latency_ms(model: nn.Module, window: int, in_channels: int = 9, repeats: int = 20, threads: int | None = 1,
               seed: int = 0) -> float:
    """Median time of one prediction (batch 1, eval mode, no autograd), ms."""
    x = torch.randn(1, window, in_channels, generator=torch.Generator().manual_seed(seed))
    with torch_threads(threads):
        return 1e3 * median_time(_infer(model, x), repeats)


def throughput(model: nn.Module, window: int, batch: int = 64, in_channels: int = 9, repeats: int = 5,
               threads: int | None = 1, seed: int = 0) -> float:
    """Windows predicted per second in batches of ``batch`` (eval mode, no autograd; median batch time)."""
    x = torch.randn(batch, window, in_channels, generator=torch.Generator().manual_seed(seed))
    with torch_threads(threads):
        return batch / median_time(_infer(model, x), repeats)


def _training_step(model: nn.Module, window: int, batch: int, in_channels: int, seed: int) -> Callable[[], None]:
    """One training step on a fixed random batch: forward, BPTT backward and an AdamW step (with the memory
    setting of the training loop, :func:`bgfn.train.memory.keep_freed_memory`)."""
    keep_freed_memory()
    g = torch.Generator().manual_seed(seed)
    x, y = torch.randn(batch, window, in_channels, generator=g), torch.randn(batch, 2, generator=g)
    opt = torch.optim.AdamW(model.parameters(), lr=1e-3)

    def step():
        model.train()
        opt.zero_grad(set_to_none=True)
        torch.nn.functional.mse_loss(model(x), y).backward()
        opt.step()

    return step


def training_step(model: nn.Module, window: int, batch: int, in_channels: int = 9,
                  seed: int = 0) -> Callable[[], None]:
    """One training step (forward, BPTT backward, AdamW step) on a fixed random batch, to time it."""
    return _training_step(model, window, batch, in_channels, seed)


def training_throughput(model: nn.Module, window: int, batch: int, in_channels: int = 9, repeats: int = 3,
                        seed: int = 0) -> float:
    """Training windows per second: forward, BPTT backward and an AdamW step on random inputs (median of
    ``repeats`` steps after one warm-up), torch's current CPU threads."""
    return batch / median_time(_training_step(model, window, batch, in_channels, seed), repeats)


#: torch operators whose self time is dense matrix arithmetic (Linear, attention products, convolution).
MATMUL_OPS = ("aten::mm", "aten::addmm", "aten::bmm", "aten::baddbmm", "aten::matmul",
              "aten::_scaled_dot_product_flash_attention_for_cpu",
              "aten::_scaled_dot_product_flash_attention_for_cpu_backward", "aten::mkldnn_convolution",
              "aten::convolution_backward")


def matmul_seconds(events) -> tuple[float, float]:
    """(Seconds in :data:`MATMUL_OPS`, seconds in all operators) of ``torch.profiler`` key averages (self CPU
    time, so nested operators are not counted twice)."""
    total = sum(e.self_cpu_time_total for e in events) / 1e6
    dense = sum(e.self_cpu_time_total for e in events if e.key in MATMUL_OPS) / 1e6
    return dense, total


@contextlib.contextmanager
def _without_native_stderr() -> Iterator[None]:
    """Discard what native code writes to file descriptor 2 inside the block: torch's profiler (Kineto) prints
    a line from C++ when it starts and stops, which a notebook would show (Python's ``sys.stderr`` is kept)."""
    sys.stderr.flush()
    saved, null = os.dup(2), os.open(os.devnull, os.O_WRONLY)
    os.dup2(null, 2)
    try:
        yield
    finally:
        os.dup2(saved, 2)
        os.close(saved)
        os.close(null)


def _profiled(step: Callable[[], object], record_shapes: bool = False):
    """``step()`` once under ``torch.profiler`` (CPU activity, its native lines on stderr discarded): the profile."""
    # here, not at the top: the profiler loads its own native library, needed by `make bench` alone
    from torch.profiler import ProfilerActivity, profile

    with _without_native_stderr(), profile(activities=[ProfilerActivity.CPU], record_shapes=record_shapes) as prof:
        step()
    return prof


def profile_step(step: Callable[[], object]) -> dict[str, float]:
    """``step()`` once under ``torch.profiler``: ``{'step_s', 'matmul_s'}``, profiled time of all operators and of the
    dense matrix products alone (:data:`MATMUL_OPS`), s."""
    dense, total = matmul_seconds(_profiled(step).key_averages())
    return {"step_s": total, "matmul_s": dense}


def training_step_profile(model: nn.Module, window: int, batch: int, in_channels: int = 9,
                          seed: int = 0) -> dict[str, float]:
    """One training step (as :func:`training_throughput`) under ``torch.profiler``, after a warm-up step.

    Returns ``{'step_s', 'matmul_s'}``: profiled time of all operators and of the dense matrix products alone,
    s. Their ratio says how much of a step is arithmetic that no change of the other layers can remove.
    """
    step = _training_step(model, window, batch, in_channels, seed)
    step()
    return profile_step(step)


#: the dense products :func:`matmul_calls` records and :func:`matmul_replay` runs again: torch's function and how
#: many of the operator's inputs are its operands (``addmm``: the added matrix, then the two factors). The encoder's
#: convolution (a few hundredths of BGFN's products) is left out.
REPLAYED_OPS = {"aten::mm": (torch.mm, 2), "aten::bmm": (torch.bmm, 2), "aten::addmm": (torch.addmm, 3)}


def matmul_calls(step: Callable[[], object]) -> list[tuple[str, tuple[tuple[int, ...], ...]]]:
    """The dense matrix products of one ``step()`` (:data:`REPLAYED_OPS`), in the order they ran: (operator, shapes of
    its operands), recorded by ``torch.profiler`` with shapes."""
    return [(e.name, tuple(tuple(int(n) for n in shape) for shape in e.input_shapes[:REPLAYED_OPS[e.name][1]]))
            for e in _profiled(step, record_shapes=True).events() if e.name in REPLAYED_OPS]


def matmul_replay(calls: list[tuple[str, tuple[tuple[int, ...], ...]]], seed: int = 0) -> Callable[[], None]:
    """A callable that runs the products of :func:`matmul_calls` again, unprofiled, on random float32 operands of the
    same shapes: BGFN's matrix products alone, timed as any step is.

    Every call gets operands of its own, so that they come from memory, not from the cache, as in the step (at the
    paper's size they take most of a gigabyte). The operands are C-contiguous, where a step may hand the library
    a transposed one; either way the library reads it in place.
    """
    g = torch.Generator().manual_seed(seed)
    ops = [(REPLAYED_OPS[name][0], [torch.randn(shape, generator=g) for shape in shapes]) for name, shapes in calls]

    def replay():
        for fn, operands in ops:
            fn(*operands)

    return replay


def interleaved_profiles(steps: dict[str, Callable[[], object]], repeats: int,
                         warmup: int = 1) -> dict[str, list[dict[str, float]]]:
    """:func:`profile_step` of every step of ``steps`` in turn (A, B, A, B, ...) ``repeats`` times after ``warmup``
    unprofiled rounds: per name a list of ``{'step_s', 'matmul_s'}``. As :func:`interleaved_times`, a busy
    neighbour slows the A and the B of the same round alike, so a per-round ratio of the two keeps."""
    return _interleaved(steps, repeats, warmup, profile_step)


def ceiling_spread(twin: list[dict[str, float]], bgfn: list[dict[str, float]]) -> dict[str, dict]:
    """Per-round figures of :func:`interleaved_profiles` of BGFN and its twin.

    Returns
    -------
    dict
        ``ceiling``: quartiles (:func:`quartiles`, plus ``rounds``) of the twin's profiled step over BGFN's matrix
        products alone, round by round (the throughput ratio BGFN would reach if nothing but its matrix arithmetic
        cost time); ``matmul_share``: quartiles of BGFN's matrix products over its own profiled step (the share of
        its step that no change of its other layers can remove: the ratio over the ceiling it reaches, measured
        within one step).
    """
    if len(twin) != len(bgfn) or not twin:
        raise ValueError("ceiling_spread needs two series of the same, non-zero length")
    ceiling = [t["step_s"] / b["matmul_s"] for t, b in zip(twin, bgfn)]
    share = [b["matmul_s"] / b["step_s"] for b in bgfn]
    return {"ceiling": {**quartiles(ceiling), "rounds": len(ceiling)},
            "matmul_share": {**quartiles(share), "rounds": len(share)}}


def median_profile(profiles: list[dict[str, float]]) -> dict[str, float]:
    """The median of each figure of a list of :func:`profile_step` results."""
    return {k: statistics.median(p[k] for p in profiles) for k in ("step_s", "matmul_s")}


def twin_ratios(rates: dict, profiles: dict) -> dict[str, dict[str, float]]:
    """BGFN against its ANN twin per size, as ``make bench`` records them.

    Parameters
    ----------
    rates : dict
        ``train_windows_per_s``: method -> size -> training windows per second.
    profiles : dict
        ``train_step_profile``: method -> size -> :func:`training_step_profile`.

    Returns
    -------
    dict
        ``train_ratio_bgfn_over_twin``: size -> BGFN's throughput over the twin's; ``train_ratio_ceiling``: size ->
        the twin's profiled step over BGFN's matrix products alone (the ratio if nothing else cost time). A size
        is left out where a measurement is missing.
    """
    b, t = rates.get("bgfn") or {}, rates.get("transformer") or {}
    pb, pt = profiles.get("bgfn") or {}, profiles.get("transformer") or {}
    return {"train_ratio_bgfn_over_twin": {size: b[size] / t[size] for size in b if size in t},
            "train_ratio_ceiling": {size: pt[size]["step_s"] / pb[size]["matmul_s"] for size in pb if size in pt}}


def realtime_flags(latency_ms_value: float, imu_rate_hz: float = IMU_RATE_HZ,
                   gnss_rate_hz: float = GNSS_RATE_HZ) -> dict[str, bool]:
    """Whether a batch-1 latency (ms) keeps up with the IMU and the GNSS rates.

    Returns ``{'imu': latency <= 1000 / imu_rate_hz, 'gnss': latency <= 1000 / gnss_rate_hz}``.
    """
    lat = float(latency_ms_value)
    if not lat >= 0:
        raise ValueError(f"latency must be a non-negative number of ms, got {latency_ms_value!r}")
    return {"imu": lat <= 1e3 / imu_rate_hz, "gnss": lat <= 1e3 / gnss_rate_hz}
