"""Energy tables and the record of notebook 05: energy per layer and per prediction, the totals, the reduction
against the twin, and the measured CPU speed beside them (``make bench``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd
from torch import nn

from bgfn.energy.counts import LayerCount, layer_counts, mean_rate
from bgfn.energy.rules import E_AC_PJ, E_MAC_PJ, energy_uj
from bgfn.models import MODELS

# ---------------------------------------------------------------------------------------------------
# Energy tables: energy per layer and per prediction, the totals, and the reduction against the twin.
# ---------------------------------------------------------------------------------------------------
#: Columns of :func:`energy_table` (and of ``results/<profile>/tables/energy.csv``).
COLUMNS = ("model", "layer", "firing_rate", "macs", "sops", "energy_uj")


#: Suffixes of the attention-product rows: BGFN's spiking (``qkv_matmul``) and the twin's softmax attention.
ATTENTION_ROWS = (".attention", ".qkv_matmul")


def table_from_counts(counts: list[LayerCount], model_name: str, e_mac: float = E_MAC_PJ,
                      e_ac: float = E_AC_PJ) -> pd.DataFrame:
    """The per-layer energy table of ``counts`` with a ``total`` row (columns :data:`COLUMNS`).

    ``energy_uj = (e_mac * macs + e_ac * sops) * 1e-6`` (pJ -> µJ). The ``total`` row's ``firing_rate`` is
    the effective mean input rate of the spike-driven layers, ``sum(sops) / sum(trains * dense)`` (1.0 for
    an ANN).
    """
    rows = [{"model": model_name, "layer": c.name, "firing_rate": float(c.rate), "macs": float(c.macs),
             "sops": float(c.sops), "energy_uj": energy_uj(c.macs, c.sops, e_mac, e_ac)} for c in counts]
    dense_spk = sum(c.trains * c.dense for c in counts if c.spiking)
    sops = sum(c.sops for c in counts)
    macs = sum(c.macs for c in counts)
    rows.append({"model": model_name, "layer": "total",
                 "firing_rate": float(sops / dense_spk) if dense_spk else 1.0,
                 "macs": float(macs), "sops": float(sops), "energy_uj": energy_uj(macs, sops, e_mac, e_ac)})
    return pd.DataFrame(rows, columns=list(COLUMNS))


def model_name(model: nn.Module) -> str:
    """Method id of ``model`` (``bgfn``, ``transformer``, ...) from :data:`bgfn.models.MODELS`."""
    for key, cls in MODELS.items():
        if type(model) is cls:
            return key
    return type(model).__name__.lower()


def energy_table(model: nn.Module, windows, e_mac: float = E_MAC_PJ, e_ac: float = E_AC_PJ,
                 batch_size: int = 32, name: str | None = None) -> pd.DataFrame:
    """Per-layer firing rate, MACs, SOPs and energy (µJ per prediction) of ``model`` on ``windows``.

    Parameters
    ----------
    model : nn.Module
        BGFN (spike-driven layers -> SOPs) or an ANN such as the Transformer twin (all MACs).
    windows : array [M, N, C] or WindowSet-like
        Normalized evaluation windows.
    e_mac, e_ac : float
        Energy per MAC and per accumulate, pJ (Horowitz 2014, 45 nm float32: 4.6 and 0.9).
    batch_size : int
        Windows per forward pass.
    name : str, optional
        Value of the ``model`` column (default: the method id, :func:`model_name`).

    Returns
    -------
    DataFrame
        Columns ``model, layer, firing_rate, macs, sops, energy_uj``; one row per counted layer in execution
        order and a final ``total`` row.
    """
    return table_from_counts(layer_counts(model, windows, batch_size), name or model_name(model), e_mac, e_ac)


def stack_tables(tables: dict[str, pd.DataFrame]) -> pd.DataFrame:
    """The tables of several models one under the other (``energy.csv``), after checking them.

    Raises
    ------
    ValueError
        A table's columns are not :data:`COLUMNS`, or a ``firing_rate`` lies outside [0, 1] (a rate per merged
        spike train cannot).
    """
    table = pd.concat(tables.values(), ignore_index=True)
    if list(table.columns) != list(COLUMNS):
        raise ValueError(f"energy table columns {list(table.columns)}, expected {list(COLUMNS)}")
    bad = table[~table["firing_rate"].between(0.0, 1.0)]
    if len(bad):
        raise ValueError(f"firing rates outside [0, 1]:\n{bad}")
    return table


def with_input_trains(table: pd.DataFrame, snn_counts: list[LayerCount], snn: str = "bgfn") -> pd.DataFrame:
    """``table`` with a column ``input_trains``: the spike trains merged into each layer's input (model ``snn``
    from ``snn_counts``; 1 for every other row)."""
    trains = {c.name: c.trains for c in snn_counts}
    return table.assign(input_trains=[trains.get(layer, 1) if m == snn else 1
                                      for m, layer in zip(table["model"], table["layer"])])


def total_energy_uj(table: pd.DataFrame) -> float:
    """Energy per prediction (µJ) of the ``total`` row of an :func:`energy_table`."""
    tot = table.loc[table["layer"] == "total", "energy_uj"]
    if len(tot) != 1:
        raise ValueError("table has no (or several) 'total' rows")
    return float(tot.iloc[0])


def reduction_pct(snn, ann) -> float:
    """Energy saved by the SNN relative to the ANN, %: ``100 * (1 - E_snn / E_ann)``.

    ``snn`` and ``ann`` are :func:`energy_table` frames (their ``total`` rows) or energies (µJ).
    """
    e_snn = total_energy_uj(snn) if isinstance(snn, pd.DataFrame) else float(snn)
    e_ann = total_energy_uj(ann) if isinstance(ann, pd.DataFrame) else float(ann)
    if not e_ann > 0:
        raise ValueError(f"ANN energy must be positive, got {e_ann}")
    return 100.0 * (1.0 - e_snn / e_ann)


def attention_energy_uj(table: pd.DataFrame) -> float:
    """Energy (µJ per prediction) of the attention-product rows of a table (:data:`ATTENTION_ROWS`)."""
    return float(table.loc[table["layer"].str.endswith(ATTENTION_ROWS), "energy_uj"].sum())


@dataclass
class EnergyTotals:
    """Energy per prediction of BGFN and of its twin, and what the reduction is made of.

    Attributes
    ----------
    bgfn_uj, twin_uj : float
        Energy per prediction, µJ.
    reduction_pct : float
        ``100 * (1 - bgfn_uj / twin_uj)``.
    mean_rate : float
        BGFN's effective mean input firing rate (:func:`bgfn.energy.counts.mean_rate`).
    macs, sops : float
        BGFN's MACs and SOPs per prediction.
    mac_share : float
        Fraction of BGFN's energy spent in its MAC layers (spike encoder, readout).
    attention_uj : dict
        Energy of the attention products, µJ, per model (``bgfn``, ``transformer``).
    reduction_without_attention_pct : float
        The reduction with the attention products removed from both models.
    """

    bgfn_uj: float
    twin_uj: float
    reduction_pct: float
    mean_rate: float
    macs: float
    sops: float
    mac_share: float
    attention_uj: dict
    reduction_without_attention_pct: float

    def frame(self, paper_reduction_pct: float) -> pd.DataFrame:
        """This reproduction beside the paper (which gives only the reduction)."""
        return pd.DataFrame(
            {"this reproduction": [self.bgfn_uj, self.twin_uj, self.reduction_pct, self.mean_rate],
             "paper": [np.nan, np.nan, paper_reduction_pct, np.nan]},
            index=["BGFN energy per prediction (µJ)", "Transformer twin energy per prediction (µJ)",
                   "energy reduction vs Transformer (%)", "BGFN mean input firing rate"])


def energy_totals(tables: dict[str, pd.DataFrame], bgfn_counts: list[LayerCount],
                  e_mac: float = E_MAC_PJ) -> EnergyTotals:
    """The totals of :func:`table_from_counts` tables ``{'bgfn': ..., 'transformer': ...}``.

    The twin's softmax attention costs ``2 N^2 D`` MACs per block while BGFN's (no softmax) is evaluated as
    ``Q (K^T V)``, linear in ``N``: the reduction without the attention products in both models tells how much
    of it comes from the attention alone.

    Parameters
    ----------
    tables : dict
        Method -> per-layer energy table with a ``total`` row.
    bgfn_counts : list of LayerCount
        BGFN's counts (its mean input rate).
    e_mac : float
        Energy per MAC, pJ (BGFN's MAC share).
    """
    e_bgfn, e_twin = total_energy_uj(tables["bgfn"]), total_energy_uj(tables["transformer"])
    tb = tables["bgfn"].set_index("layer")
    attn = {m: attention_energy_uj(t) for m, t in tables.items()}
    return EnergyTotals(
        bgfn_uj=e_bgfn, twin_uj=e_twin, reduction_pct=reduction_pct(tables["bgfn"], tables["transformer"]),
        mean_rate=mean_rate(bgfn_counts), macs=float(tb.loc["total", "macs"]), sops=float(tb.loc["total", "sops"]),
        mac_share=e_mac * tb.loc["total", "macs"] * 1e-6 / e_bgfn, attention_uj=attn,
        reduction_without_attention_pct=reduction_pct(e_bgfn - attn["bgfn"], e_twin - attn["transformer"]))


# ---------------------------------------------------------------------------------------------------
# Measured CPU speed beside the energy estimate: the figures of ``results/bench.json`` (``make bench``).
# ---------------------------------------------------------------------------------------------------
#: Keys of ``bench.json`` (method -> size -> value) shown in the table.
SPEED_KEYS = ("infer_ms", "throughput_windows_per_s", "realtime_imu_100hz", "realtime_gnss_1hz")


#: Columns of :func:`speed_table` after ``model`` and ``size``, by ``bench.json`` key.
SPEED_COLUMNS = {"throughput_windows_per_s": "throughput (windows/s, batch 64)",
                 "realtime_imu_100hz": "keeps up with 100 Hz IMU",
                 "realtime_gnss_1hz": "keeps up with 1 Hz GNSS"}


def speed_table(bench: dict, methods=("bgfn", "transformer", "at_lstm", "mlp"),
                sizes=("quick", "paper")) -> pd.DataFrame:
    """One row per method and size that has a speed figure in ``bench`` (the parsed ``bench.json``).

    The latency is ``infer_ms`` (bench_models.py), else bench_speed.py's own ``speed_bench.latency_ms``.

    Returns
    -------
    DataFrame
        ``model, size, latency (ms, batch 1), throughput (windows/s, batch 64), keeps up with 100 Hz IMU,
        keeps up with 1 Hz GNSS`` (None where not measured); empty when ``bench`` has no speed figure.
    """
    if not any(k in bench for k in SPEED_KEYS):
        return pd.DataFrame()
    fallback = (bench.get("speed_bench") or {}).get("latency_ms") or {}
    recs = []
    for m in methods:
        for size in sizes:
            def get(key):
                return (bench.get(key) or {}).get(m, {}).get(size)
            lat = get("infer_ms") if get("infer_ms") is not None else fallback.get(m, {}).get(size)
            rec = {"model": m, "size": size, "latency (ms, batch 1)": lat,
                   **{col: get(key) for key, col in SPEED_COLUMNS.items()}}
            if any(v is not None for k, v in rec.items() if k not in ("model", "size")):
                recs.append(rec)
    return pd.DataFrame(recs)
