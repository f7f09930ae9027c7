"""Notebook 05 in words: which networks and windows were measured, where BGFN's energy goes, the break-even firing
rate, SpikingJelly's counts beside ours, the CPU speed's notes and the result in one paragraph."""

from __future__ import annotations

from bgfn.energy.checkpoint import EvaluationWindows, MeasuredModels
from bgfn.energy.crosscheck import Crosscheck
from bgfn.energy.tables import SPEED_KEYS, EnergyTotals
from bgfn.report.sample_words import sample_clause, sample_note


def measured_lines(measured: MeasuredModels) -> list[str]:
    """The networks measured (:class:`~bgfn.energy.checkpoint.MeasuredModels`), one line each: checkpoint, size,
    best epoch, validation RMSE."""
    rel = measured.relative_paths()
    return [f"{m:>12}: {rel[m]} | size {measured.trained[m].size_cfg} | best epoch {c.get('best_epoch')}, "
            f"val RMSE {c.get('val_rmse_m', float('nan')):.3f} m" for m, c in measured.cards.items()]


def windows_line(windows: EvaluationWindows, dataset: str, time_steps: int) -> str:
    """The windows measured (:class:`~bgfn.energy.checkpoint.EvaluationWindows`): how many, of what shape, from
    when."""
    ws = windows.windows
    return (f"{dataset}: {len(ws)} of {windows.n_validation} validation windows, {ws.x.shape[1]} IMU samples x "
            f"{ws.x.shape[2]} channels, t = {ws.t_end.min():.0f} .. {ws.t_end.max():.0f} s (GPS time of "
            f"week); T_s = {time_steps}")


def totals_lines(totals: EnergyTotals, n_windows: int, n_seeds: int = 1) -> list[str]:
    """Where BGFN's energy goes, and how much of the gap the attention products make
    (:class:`~bgfn.energy.tables.EnergyTotals`), each line saying that it rests on ``n_seeds`` trained networks
    (one: the checkpoint measured) and ``n_windows`` windows when too few for statistics."""
    sample = sample_note(n_seeds, n_windows)
    return [f"BGFN: {totals.macs:,.0f} MACs + {totals.sops:,.0f} SOPs; "
            f"the MAC layers (encoder, readout) take {100 * totals.mac_share:.1f} % of its energy{sample}",
            f"attention products: {100 * totals.attention_uj['transformer'] / totals.twin_uj:.1f} % of the twin's "
            f"energy, {100 * totals.attention_uj['bgfn'] / totals.bgfn_uj:.1f} % of BGFN's; reduction without "
            f"them in both models: {totals.reduction_without_attention_pct:.1f} %{sample}"]


def break_even_note(rate: float) -> str:
    """One sentence on the break-even mean firing rate of :func:`reduction_vs_rate`."""
    return (f"break-even mean firing rate: {rate:.3f} "
            + ("(above 1: BGFN stays cheaper at any firing rate)" if rate > 1
               else "(BGFN costs more than the twin above it)"))


def crosscheck_lines(cross: Crosscheck, tolerance_pct: float, snn: str = "bgfn",
                     ann: str = "transformer") -> list[str]:
    """SpikingJelly's counts beside ours (:class:`~bgfn.energy.crosscheck.Crosscheck`): the agreement against the
    tolerance, and the result under SpikingJelly's default rules."""
    return [f"agreement within {cross.worst_pct:.2f} % (tolerance {tolerance_pct} %)",
            f"SpikingJelly default rules (non-binary inputs -> MACs): BGFN {cross.strict_uj[snn]:.4g} µJ, "
            f"twin {cross.strict_uj[ann]:.4g} µJ, reduction {cross.strict_reduction_pct:.1f} %"]


def speed_notes(bench: dict, path: str = "results/bench.json") -> list[str]:
    """What the table cannot say: no figures yet, the settings they were recorded with, missing keys."""
    if not any(k in bench for k in SPEED_KEYS):
        return [f"{path} has no speed figures yet: `make bench` produces them."]
    info = bench.get("speed_bench") or bench.get("models_bench") or {}
    settings = {k: info.get(k) for k in ("threads", "threads_infer", "batch", "device", "torch") if k in info}
    notes = [f"recorded with: {settings}"]
    missing = [k for k in SPEED_KEYS if k not in bench]
    if missing:
        notes.append(f"missing in {path}: {', '.join(missing)} -- run `make bench`")
    return notes


def result_markdown(summary: dict) -> str:
    """The result of notebook 05 in one paragraph (Markdown), from :func:`energy_summary`'s dict; its lead says
    that it rests on one trained network (and too few windows, when so)."""
    s = summary
    e, attn = s["energy_uj_per_prediction"], s["attention_energy_uj"]
    n_windows = (s.get("windows") or {}).get("n_windows")
    clause = sample_clause(1, int(n_windows)) if n_windows else ""          # one network measured
    lead = f"**Result ({s['profile']} profile, {s['dataset']}, seed {s['seed']}{'; ' + clause if clause else ''}):**"
    if not (s.get("improved") or {}).get("bgfn", True):
        return (f"{lead} BGFN did not train (its best "
                f"epoch is 0: training never improved on its initial network), so its firing rates are an untrained "
                f"network's and no energy saving against the Transformer twin is claimed (BGFN {e['bgfn']:.4g} µJ, "
                f"twin {e['transformer']:.4g} µJ per prediction; paper: {s['paper_reduction_pct']} % less).")
    return (
        f"{lead} BGFN {e['bgfn']:.4g} µJ vs "
        f"Transformer twin {e['transformer']:.4g} µJ per prediction: **{s['reduction_pct']:.1f} % less energy** "
        f"(paper: {s['paper_reduction_pct']} %), at a mean input firing rate of {s['mean_input_firing_rate']:.3f} "
        f"(break-even {s['break_even_firing_rate']:.3f}). The twin's softmax attention (2N²D MACs per block) "
        f"takes {100 * attn['transformer'] / e['transformer']:.0f} % of its energy; without the attention "
        f"products in both models the reduction is {s['reduction_pct_without_attention']:.1f} %. Under "
        f"SpikingJelly's stricter default rules (integer residual inputs counted as MACs) it is "
        f"{s['crosscheck_spikingjelly']['default_rules_reduction_pct']:.1f} %.")
