"""Notebook 03 in words: what a plan trains, whether every run learned, the recheck of those that did not, how
long the paper profile would train here and how BGFN's training speed compares with its ANN twin's."""

from __future__ import annotations

import pandas as pd

from bgfn.config import MAIN_VARIANT
from bgfn.learning import learning_options
from bgfn.nav import outages
from bgfn.train.options import optimizer_options
from bgfn.train.profile import DESCRIBED_OPTIONS, TrainingPlan
from bgfn.train.recheck import enabled
from bgfn.train.tables import lowest_train_loss
from bgfn.train.variants import VariantPlan, variant_options


def plan_text(plan: TrainingPlan) -> str:
    """What a :class:`~bgfn.train.profile.TrainingPlan` trains, on which data, with which budget (a few lines for
    notebook 03)."""
    tc = plan.train_cfg
    opts = learning_options(tc)
    return "\n".join([
        f"profile {plan.cfg['profile']!r}: {plan.cfg['description']}",
        f"datasets {plan.datasets}, methods {plan.methods}, seeds {plan.seeds}, size {tc.get('size')!r}",
        (f"evaluation outages excluded from training (start, duration) s: {_windows_text(plan)} "
         f"+- {opts['margin_s']} s" if opts["protocol"] == "honest" else
         f"protocol {opts['protocol']!r}: the evaluation outages (start, duration) s {_windows_text(plan)} "
         "are training windows too"),
        f"optimizer: {optimizer_options(tc)}",
        f"learning problem: { {k: opts[k] for k in DESCRIBED_OPTIONS} }",
    ])


def _windows_text(plan: TrainingPlan) -> str:
    """The outages per dataset where the profile gives them per dataset, else the one list."""
    if not plan.per_dataset:
        return str(plan.outage_windows)
    parts = []
    for name in plan.datasets:
        entry = outages.outage_entry(plan.cfg, name)
        parts.append(f"{name}: " + (f"rule {entry['rule']} (picked from the drive)" if outages.is_rule(entry)
                                    else str(outages.outage_windows(plan.cfg, dataset=name))))
    return "; ".join(parts)


def variants_text(vplan: VariantPlan) -> str:
    """One line per variant of a :class:`~bgfn.train.variants.VariantPlan` (its inputs and protocol) and the
    networks each trains."""
    lines = [f"variants {vplan.names or 'none'}: datasets {vplan.datasets}, methods {vplan.methods}, "
             f"seeds {vplan.seeds}, each with the learning rate the main search chose for its dataset and method"]
    for name in [MAIN_VARIANT] + vplan.names:
        tc = vplan.train_section(name)
        what = variant_options(tc)
        lines.append(f"  {name}: inputs {what['inputs']}, protocol {what['protocol']}")
    return "\n".join(lines)


def learning_check(cards: list[dict]) -> list[str]:
    """Did every run learn? Lines for notebook 03: how many runs improved on their initial network
    (``best_epoch >= 1``; epoch 0 is the initial network), which did not and whether they fitted their training
    windows all the same (:func:`lowest_train_loss`), and how many kept their first training epoch (their
    validation loss only grew after one pass over the data)."""
    done = [c for c in cards if c.get("best_epoch") is not None]
    untrained = [c for c in done if int(c["best_epoch"]) < 1]
    first = [c for c in done if int(c["best_epoch"]) == 1]
    lines = [f"{len(done) - len(untrained)} of {len(done)} runs improved on their initial network (best epoch >= 1)"]
    for c in untrained:
        fit = lowest_train_loss(c)
        fitted = "" if fit is None else f"; its training loss fell to {fit:.2f} (predicting the training mean: about 1)"
        lines.append(f"  not improved: {c.get('dataset', '')} {c['method']} seed {c['seed']}: the initial network "
                     f"is kept{fitted}")
    if first:
        lines.append(f"{len(first)} runs kept their first training epoch (validation loss grew after it): "
                     + ", ".join(f"{c.get('dataset', '')} {c['method']} seed {c['seed']}" for c in first))
    return lines


def card_line(card: dict) -> str:
    """One line per run: dataset, method, seed, epochs, wall time, validation RMSE and the references (m)."""
    return (f"{card.get('dataset', ''):>18} {card['method']:>12} seed {card['seed']}: {card['epochs_run']:4d} epochs, "
            f"{card['wall_time_s']:7.1f} s, val RMSE {card['val_rmse_m']:.3f} m "
            f"(zero {card['val_rmse_zero_m']:.3f}, last increment {card['val_rmse_last_m']:.3f}, "
            f"INS increment {card['val_rmse_ins_m']:.3f})")


def recheck_lines(table: pd.DataFrame, train_cfg: dict) -> list[str]:
    """Plain lines for notebook 03: how many of the rechecked runs improved on their initial network once
    they had every training window (``train_cfg``: the ``train:`` section, whether the recheck is on)."""
    if not enabled(train_cfg):
        return ["not rechecked (train.recheck_all_windows is false)"]
    if not len(table):
        return ["no run to recheck: every run improved on its initial network, or trained on all its windows"]
    improved = int((table["best_epoch_all"] >= 1).sum())
    fit = float(table["train_loss_min_all"].median())
    which = (" (the first of each dataset and method, train.recheck_runs: first)"
             if train_cfg["recheck_runs"] == "first" else "")
    lines = [f"trained again on all their training windows, {improved} of {len(table)} runs that never improved on "
             f"their initial network{which} then did (median lowest training loss {fit:.2f}; predicting the "
             f"training mean: about 1):"]
    lines += [f"  {r.dataset} {r.method} seed {r.seed}: {r.n_train} -> {r.n_train_all} windows, best epoch "
              f"{r.best_epoch} -> {r.best_epoch_all}" for r in table.itertuples()]
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


def ratio_text(r: dict) -> str:
    """``0.52 [IQR 0.50-0.55, 15 rounds]`` and ``unreliable`` where :func:`paired_ratio` says so."""
    return (f"{r['median']:.2f} [IQR {r['q25']:.2f}-{r['q75']:.2f}, {r['rounds']} rounds]"
            + (" -- unreliable: the spread is wider than the difference" if r["unreliable"] else ""))
