"""The learned odometer in the verdict (beyond the paper): its rows in the verdict table, the sixth
question ("does a learned odometer help?") and its clause in each dataset's headline.

Read from notebook 07's odometer tables (:mod:`bgfn.studies.odometer.bars`: ``outage_odometer.csv`` with one row per
start, seed and duration, ``outage_odometer_summary.csv`` with the medians, the ratio to INS+NHC per start and the
Wilcoxon p against it, ``outage_odometer_paper.csv`` with the rows in each drive's two evaluation outages,
``outage_odometer_curve.csv`` with RIDGE-ODO's speed error against its training windows,
``outage_odometer_uncertainty.csv`` with each network's predicted std against its speed error), notebook 07's
``energy_odometer.csv`` (:mod:`bgfn.studies.odometer.energy`), and a run at another model size made on another machine
(``data/measured/odometer_sizes.csv``, :mod:`bgfn.studies.odometer.sizes`: the paper's size on a GPU). Nothing here
is typed by hand; a missing table leaves its cells empty and its sentence says so.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from bgfn.data.names import dataset_id
from bgfn.studies.odometer.sizes import read_measured
from bgfn.studies.odometer.errors import offset_bar_mps
from bgfn.report.odometer_words import uncertainty_sentence
from bgfn.report.sample_words import INPUT_WORDS
from bgfn.studies.odometer.bars import HOLD, LEARNED_ODOMETERS, ORACLE, RIDGE, holm_vs_nhc
from bgfn.paper import METHOD_LABELS, ensemble_label, nhc_label, odometer_label
from bgfn.stats import wilcoxon_p

#: The spiking odometer and its ANN twin.
SUBJECT_ODO, TWIN_ODO = odometer_label("bgfn"), odometer_label("transformer")
#: The network odometers alone.
NETWORKS: tuple[str, ...] = tuple(odometer_label(m) for m in METHOD_LABELS)
#: The spiking odometer's ensemble of seeds (``evaluate.odometer.ensemble``).
SUBJECT_ENS = ensemble_label(SUBJECT_ODO)
#: The learned odometers, the ridge first (the bar the networks must clear), then each network's ensemble: the family
#: whose best the page names, its p-values against INS+NHC Holm-adjusted together.
LEARNED: tuple[str, ...] = LEARNED_ODOMETERS
#: Rows the verdict table gains, in order (the oracle row is built apart).
ODOMETER_ROWS: tuple[str, ...] = (HOLD, *LEARNED)
#: Label of the oracle row: the reference's speed plus white noise as large as BGFN-ODO's own speed error.
ORACLE_ODO_ROW = f"oracle speed at {SUBJECT_ODO}'s speed error"
#: What an odometer reads (the verdict table's ``inputs``).
ODOMETER_INPUTS = "body-frame IMU"
#: The odometer networks' inputs (``evaluate.odometer.inputs``) in words.
#: The coverage of +-2 sigma that a calibrated Gaussian std gives, and the band the issue calls calibrated.
CALIBRATED_COVERAGE = (0.90, 0.98)
#: Wilcoxon p below which a difference is called one (the Holm-adjusted p where the page names the best of several).
ALPHA = 0.05


@dataclass
class OdometerInputs:
    """One dataset's odometer tables (None where a notebook has not written one)."""

    rows: pd.DataFrame | None       # outage_odometer.csv
    summary: pd.DataFrame | None    # outage_odometer_summary.csv
    energy: pd.DataFrame | None     # energy_odometer.csv (only the dataset notebook 07 measured)
    paper: pd.DataFrame | None = None   # outage_odometer_paper.csv (the two evaluation outages)
    curve: pd.DataFrame | None = None   # outage_odometer_curve.csv (RIDGE-ODO against its training windows)
    uncertainty: pd.DataFrame | None = None   # outage_odometer_uncertainty.csv (each network's std against its error)
    sized: pd.DataFrame | None = None   # data/measured/odometer_sizes.csv (the odometers at another size, elsewhere)
    errors: pd.DataFrame | None = None  # outage_odometer_errors.csv (each odometer's offset per outage, fluctuation)
    networks: pd.DataFrame | None = None    # outage_odometer_networks.csv (each network: calibration, correlation)

    @property
    def measured(self) -> bool:
        return self.summary is not None and len(self.summary) > 0

    def cell(self, method: str, duration: float, column: str = "max_h_m") -> float:
        """The summary's ``column`` of ``method`` (not the oracle) at ``duration`` (NaN when absent)."""
        if not self.measured:
            return float("nan")
        s = self.summary
        sel = s[(s["method"] == method) & np.isclose(s["duration_s"].astype(float), duration)]
        return float(sel[column].iloc[0]) if len(sel) else float("nan")

    def outage_cell(self, method: str, outage: int) -> float:
        """Max horizontal error of ``method`` (not the oracle) in evaluation outage ``outage`` (NaN when absent)."""
        p = self.paper
        if p is None or p.empty:
            return float("nan")
        sel = p[(p["method"] == method) & (p["outage"].astype(int) == outage) & p["sigma_mps"].isna()]
        return float(sel["max_h_m"].iloc[0]) if len(sel) else float("nan")

    def holm_p(self, method: str, duration: float) -> float:
        """``method``'s p against INS+NHC at ``duration`` Holm-adjusted over the learned odometers
        (``p_vs_nhc_holm``; computed from ``p_vs_nhc`` where a table written before that column leaves it empty);
        NaN when absent."""
        if not self.measured:
            return float("nan")
        if "p_vs_nhc_holm" in self.summary.columns and np.isfinite(self.cell(method, duration, "p_vs_nhc_holm")):
            return self.cell(method, duration, "p_vs_nhc_holm")
        s = self.summary.assign(p_vs_nhc_holm=holm_vs_nhc(self.summary))
        sel = s[(s["method"] == method) & np.isclose(s["duration_s"].astype(float), duration)]
        return float(sel["p_vs_nhc_holm"].iloc[0]) if len(sel) else float("nan")

    def family_size(self, duration: float) -> int:
        """How many learned odometers were compared with INS+NHC at ``duration`` (those with a p-value): the k of
        "best of k"."""
        return sum(bool(np.isfinite(self.cell(m, duration, "p_vs_nhc"))) for m in LEARNED if self.has(m))

    def has(self, method: str) -> bool:
        return self.measured and bool((self.summary["method"] == method).any())

    def runs(self, method: str) -> int:
        """Runs per start of ``method`` (its seeds)."""
        if self.rows is None or not len(self.rows):
            return 0
        sel = self.rows[self.rows["method"] == method]
        return int(sel.groupby(["duration_s", "start_s"]).size().max()) if len(sel) else 0

    def n_starts(self) -> int:
        if self.rows is None or not len(self.rows):
            return 0
        return int(self.rows.loc[self.rows["method"] == nhc_label("INS"), "start_s"].nunique())

    def oracle_at(self, sigma: float, duration: float) -> float:
        """The oracle speed's median max error at noise ``sigma`` m/s, interpolated in log-log over the grid (NaN
        outside it)."""
        if not self.measured or not np.isfinite(sigma) or sigma <= 0:
            return float("nan")
        s = self.summary
        g = s[(s["method"] == ORACLE) & np.isclose(s["duration_s"].astype(float), duration)].sort_values("sigma_mps")
        g = g[g["sigma_mps"] > 0]
        if len(g) < 2 or not g["sigma_mps"].min() <= sigma <= g["sigma_mps"].max():
            return float("nan")
        return float(np.exp(np.interp(np.log(sigma), np.log(g["sigma_mps"]), np.log(g["max_h_m"]))))

    def oracle_breakeven(self, duration: float) -> float:
        """The largest sigma of the grid at which the oracle speed still beats INS+NHC (NaN: at none)."""
        if not self.measured:
            return float("nan")
        s = self.summary
        g = s[(s["method"] == ORACLE) & np.isclose(s["duration_s"].astype(float), duration)]
        better = g[g["max_h_m"] < self.cell(nhc_label("INS"), duration)]
        return float(better["sigma_mps"].max()) if len(better) else float("nan")

    def pair_p(self, a: str, b: str, duration: float) -> tuple[float, float]:
        """(median per-start difference a - b in m, Wilcoxon p), the seeds' median per start."""
        if self.rows is None or not len(self.rows):
            return float("nan"), float("nan")
        r = self.rows[np.isclose(self.rows["duration_s"].astype(float), duration)]
        per = r[r["method"].isin([a, b])].groupby(["method", "start_s"])["max_h_m"].median().unstack(0)
        if a not in per or b not in per:
            return float("nan"), float("nan")
        diff = (per[a] - per[b]).dropna()
        if not len(diff):
            return float("nan"), float("nan")
        # identical at every start: no difference at all (the signed-rank test has no nonzero pair to rank)
        return float(diff.median()), 1.0 if (diff == 0).all() else wilcoxon_p(diff)

    def energy_improved(self, method: str) -> bool:
        """Whether ``method``'s odometer measured for its energy trained (``energy_odometer.csv``'s ``improved``;
        True for a table written before that column, or without the network)."""
        if self.energy is None or "improved" not in self.energy.columns:
            return True
        sel = self.energy[self.energy["model"] == method]
        return bool(sel["improved"].astype(str).isin(["True", "true", "1", "1.0"]).all()) if len(sel) else True

    def energy_uj(self, method: str) -> float:
        """Energy per prediction of ``method``'s odometer (µJ), NaN when notebook 07 did not measure it."""
        if self.energy is None or not len(self.energy):
            return float("nan")
        sel = self.energy[(self.energy["model"] == method) & (self.energy["layer"] == "total")]
        return float(sel["energy_uj"].iloc[0]) if len(sel) else float("nan")


def same_dataset(column: pd.Series, dataset: str) -> pd.Series:
    """Which rows of a table's ``dataset`` column name ``dataset``: by its id (:func:`bgfn.data.names.dataset_id`), so
    a CSV drive matches whether a table wrote its folder path or its own name."""
    target, names = dataset_id(dataset), column.astype(str)
    return names.map({d: d == dataset or dataset_id(d) == target for d in names.unique()})


def read_odometer_inputs(odometer: pd.DataFrame | None, summary: pd.DataFrame | None,
                         energy: pd.DataFrame | None, dataset: str,
                         paper: pd.DataFrame | None = None, curve: pd.DataFrame | None = None,
                         uncertainty: pd.DataFrame | None = None,
                         sized: pd.DataFrame | None = None, errors: pd.DataFrame | None = None,
                         networks: pd.DataFrame | None = None) -> OdometerInputs:
    """The tables restricted to ``dataset`` (the energy table only when its ``dataset`` column names it);
    ``sized`` defaults to the recorded runs at other sizes (:func:`bgfn.studies.odometer.sizes.read_measured`)."""
    def of(df):
        return None if df is None or "dataset" not in df.columns else df[same_dataset(df["dataset"], dataset)]

    sized = read_measured() if sized is None else sized
    return OdometerInputs(of(odometer), of(summary), of(energy), of(paper), of(curve), of(uncertainty), of(sized),
                          of(errors), of(networks))


def curve_sentence(odo: OdometerInputs) -> str:
    """Whether more training windows of this drive made the learned speed finer: RIDGE-ODO's speed RMSE in its
    outages with the fewest and the most folds of ``outage_odometer_curve.csv`` (empty without two points)."""
    c = odo.curve
    if c is None or len(c) < 2:
        return ""
    c = c.sort_values("folds")
    lo, hi = c.iloc[0], c.iloc[-1]
    return (f" Would more of this drive help? {RIDGE} refitted with the starts in {int(hi['folds'])} folds instead "
            f"of {int(lo['folds'])} learns from {hi['n_train']:.0f} windows per fold instead of {lo['n_train']:.0f} "
            f"({hi['n_train'] / lo['n_train']:.1f} times as many), and its speed RMSE in its "
            f"{hi['duration_s']:g} s outages goes from {lo['outage_speed_rmse_mps']:.2f} to "
            f"{hi['outage_speed_rmse_mps']:.2f} m/s (notebook 07's learning curve).")


def offset_sentence(odo: OdometerInputs, duration: float) -> str:
    """Why white noise of the oracle's size helps and BGFN-ODO's error does not: its offset per outage against the
    offset that alone costs INS+NHC's whole error, its fluctuation, and its correlation in the outages against the
    kappa it was fused with (``outage_odometer_errors.csv``, ``outage_odometer_networks.csv``; empty without them)."""
    e = odo.errors
    if e is None or e.empty:
        return ""
    sel = e[(e["method"] == SUBJECT_ODO) & np.isclose(e["duration_s"].astype(float), duration)]
    if sel.empty:
        return ""
    r, nhc = sel.iloc[0], nhc_label("INS")
    bar = offset_bar_mps(odo.cell(nhc, duration), duration)
    n = odo.networks
    fused = (n.loc[n["method"] == SUBJECT_ODO, "correlation"].median()
             if n is not None and "correlation" in n.columns else float("nan"))
    return (f" Why does white noise help and its error not? Over the first {duration:g} s of an outage "
            f"{SUBJECT_ODO}'s speed is off by {r['offset_rms_mps']:.2f} m/s on average (RMS over the outages), an "
            f"offset the filter cannot average away (alone, more than {bar:.2f} m/s costs as much as {nhc}'s whole "
            f"{_m(odo.cell(nhc, duration))} in {duration:g} s), and fluctuates by {r['fluctuation_mps']:.2f} m/s "
            f"around it; consecutive errors there carry the information of one in {r['outage_correlation']:.1f} epochs"
            + (f", against {fused:.1f} on its validation windows (the kappa `evaluate.odometer.correlation` fuses it "
               "with)"
               if np.isfinite(fused) else "") + ".")


def fusion_words(correlation) -> str:
    """How a recorded run fused its odometers (its ``correlation`` column; absent or NaN: recorded before it)."""
    if correlation is None or pd.isna(correlation):
        return " (fused as white errors, R = std^2: recorded before `evaluate.odometer.correlation`)"
    return "" if str(correlation) in ("True", "1", "1.0") else " (fused as white errors, R = std^2)"


def size_sentence(odo: OdometerInputs, durations) -> str:
    """What the odometers gave at another model size, in a run recorded from another machine
    (``data/measured/odometer_sizes.csv``): per recorded profile, INS+NHC and BGFN-ODO at ``durations`` there,
    BGFN-ODO's speed RMSE there and here, the best network there, and whether the windows were this run's
    (INS+NHC within 1 % at every duration: the same starts and filter). Empty without such a run for this drive."""
    sized = odo.sized
    if sized is None or not len(sized):
        return ""
    nhc, d_long, out = nhc_label("INS"), max(durations), []
    for profile, g in sized.groupby("profile", sort=False):
        there = OdometerInputs(None, g.drop(columns=["profile"]).reset_index(drop=True), None)
        if not there.has(nhc):
            continue
        same = odo.measured and all(np.isclose(there.cell(nhc, d), odo.cell(nhc, d), rtol=0.01) for d in durations)
        r = g.iloc[0]

        def pair(m, src=there):
            return "/".join(f"{src.cell(m, d):.1f}" for d in durations) + " m"

        nets = {m: there.cell(m, d_long) for m in NETWORKS if there.has(m)}
        best = min(nets, key=nets.get) if nets else None
        reads = f", reading {INPUT_WORDS.get(r['inputs'], r['inputs'])}" if isinstance(r.get("inputs"), str) else ""
        text = (f" Is it the model size? At the {r['size']} size{reads} (profile `{profile}`: up to "
                f"{r['epochs_max']:.0f} epochs, batch {r['batch_size']:.0f}; run on {r['device']} on {r['date']} at "
                f"commit {r['commit']}, `data/measured/odometer_sizes.csv`), in "
                + ("the same windows as here" if same else "its own windows") + fusion_words(r.get("correlation"))
                + f", {nhc} {pair(nhc)}")
        if there.has(SUBJECT_ODO):
            p_there = "/".join(_p(there.cell(SUBJECT_ODO, d, "p_vs_nhc")) for d in durations)
            text += (f", {SUBJECT_ODO} {pair(SUBJECT_ODO)} (p against {nhc} {p_there}"
                     f"; speed RMSE {there.cell(SUBJECT_ODO, d_long, 'speed_rmse_mps'):.2f} m/s at {d_long:g} s"
                     + (f" against {odo.cell(SUBJECT_ODO, d_long, 'speed_rmse_mps'):.2f} m/s here)"
                        if odo.has(SUBJECT_ODO) else ")"))
        if best is not None:
            text += (f"; its best network at {d_long:g} s, {best} ({_m(there.cell(best, d_long))}), "
                     + (f"beats {nhc}" if beats(there, best, d_long) else f"does not beat {nhc} significantly")
                     + f" ({best_of(there, best, d_long)})")
        out.append(text + ".")
    return "".join(out)


def odometer_rows(odo: OdometerInputs, durations) -> list[dict]:
    """The verdict table's odometer rows: the held speed, every learned odometer (in the two evaluation outages when
    notebook 07 ran them there, ``evaluate.odometer.paper_outages``, and in the sweep), then the oracle speed at
    BGFN-ODO's own speed RMSE (sweep only); ``p``: Wilcoxon of the row against INS+NHC over the starts, ``Holm p``
    that p Holm-adjusted over the learned odometers (:meth:`OdometerInputs.holm_p`)."""
    if not odo.measured:
        return []
    rows = []
    for method in ODOMETER_ROWS:
        if not odo.has(method):
            continue
        rows.append({"row": method, "inputs": ODOMETER_INPUTS if method != HOLD else "speed at the outage start",
                     "protocol": "honest" if method != HOLD else "-", "outage 1": odo.outage_cell(method, 1),
                     "outage 2": odo.outage_cell(method, 2),
                     **{f"sweep {d:g} s": odo.cell(method, d) for d in durations},
                     **{f"p {d:g} s": odo.cell(method, d, "p_vs_nhc") for d in durations},
                     **{f"Holm p {d:g} s": odo.holm_p(method, d) if method in LEARNED else np.nan for d in durations},
                     "runs": odo.runs(method)})
    if odo.has(SUBJECT_ODO) and odo.has(ORACLE):
        at = {d: odo.oracle_at(odo.cell(SUBJECT_ODO, d, "speed_rmse_mps"), d) for d in durations}
        rmse = "/".join(f"{odo.cell(SUBJECT_ODO, d, 'speed_rmse_mps'):.2g}" for d in durations)
        rows.append({"row": ORACLE_ODO_ROW, "protocol": "-", "outage 1": np.nan, "outage 2": np.nan,
                     "inputs": (f"speed RMSE {rmse} m/s" + ("" if all(np.isfinite(list(at.values())))
                                                            else ": beyond the oracle's grid where empty")),
                     **{f"sweep {d:g} s": at[d] for d in durations},
                     **{f"p {d:g} s": np.nan for d in durations}, "runs": 0})
    return rows


def calibration_word(coverage: float) -> str:
    """``calibrated`` when the +-2 sigma coverage lies in :data:`CALIBRATED_COVERAGE`, else ``overconfident``
    (below) or ``underconfident`` (above)."""
    lo, hi = CALIBRATED_COVERAGE
    return "calibrated" if lo <= coverage <= hi else "overconfident" if coverage < lo else "underconfident"


def _m(x: float) -> str:
    return "n/a" if not np.isfinite(x) else f"{x:.1f} m"


def _p(p: float) -> str:
    return "n/a" if not np.isfinite(p) else f"{p:.2g}"


def best_of(odo: OdometerInputs, method: str, duration: float) -> str:
    """The statistics of ``method`` named as the best of the learned odometers at ``duration``: ``best of k,
    Holm-corrected p x, raw y`` over the k compared, ``p y`` when it was the only one."""
    k, raw = odo.family_size(duration), odo.cell(method, duration, "p_vs_nhc")
    if k <= 1:
        return f"p {_p(raw)}"
    return f"best of {k}, Holm-corrected p {_p(odo.holm_p(method, duration))}, raw {_p(raw)}"


def best_learned(odo: OdometerInputs, duration: float) -> str | None:
    """The learned odometer with the smallest median max error at ``duration`` among those that beat INS+NHC
    (:func:`beats`), else among all (None without any)."""
    vals = {m: odo.cell(m, duration) for m in LEARNED if odo.has(m)}
    vals = {m: v for m, v in vals.items() if np.isfinite(v)}
    winners = {m: v for m, v in vals.items() if beats(odo, m, duration)}
    pool = winners or vals
    return min(pool, key=pool.get) if pool else None


def beats(odo: OdometerInputs, method: str, duration: float) -> bool:
    """``method`` below INS+NHC at ``duration`` in median and significantly so: Wilcoxon p < :data:`ALPHA`, for a
    learned odometer its p Holm-adjusted over the learned odometers (:meth:`OdometerInputs.holm_p`: the page names
    the best of them)."""
    p = odo.holm_p(method, duration) if method in LEARNED else odo.cell(method, duration, "p_vs_nhc")
    return odo.cell(method, duration) < odo.cell(nhc_label("INS"), duration) and p < ALPHA


def twin_word(odo: OdometerInputs, duration: float) -> str | None:
    """BGFN-ODO against its ANN twin over the starts: "no different from", "better than" or "worse than" (Wilcoxon
    at :data:`ALPHA`); None without the twin."""
    diff, p = odo.pair_p(SUBJECT_ODO, TWIN_ODO, duration)
    if not np.isfinite(p):
        return None
    return "no different from" if p >= ALPHA else "better than" if diff < 0 else "worse than"


def twin_comparison(odo: OdometerInputs, duration: float) -> str:
    """:func:`twin_word` with the twin's error, the median difference per start and the p-value."""
    word = twin_word(odo, duration)
    if word is None:
        return "not compared with its ANN twin (no Transformer-ODO)"
    diff, p = odo.pair_p(SUBJECT_ODO, TWIN_ODO, duration)
    return (f"{word} its ANN twin ({_m(odo.cell(TWIN_ODO, duration))}; median difference per start {diff:+.1f} m, "
            f"Wilcoxon p {_p(p)})")


def _energy(odo: OdometerInputs) -> str:
    e_snn, e_ann = odo.energy_uj("BGFN-ODO"), odo.energy_uj("Transformer-ODO")
    if not np.isfinite(e_snn):
        return "its energy was not measured for this drive (notebook 07 audits one drive's odometers)"
    if not odo.energy_improved("BGFN-ODO"):
        return ("its energy not compared with the twin's: the BGFN-ODO measured did not train (best epoch 0), so no "
                "saving is claimed")
    if not np.isfinite(e_ann):
        return f"at {e_snn:.3g} µJ per prediction"
    return (f"at {e_snn:.3g} µJ per prediction against the twin's {e_ann:.3g} µJ "
            f"({100 * (1 - e_snn / e_ann):.0f} % less)")


def answer_odometer(odo: OdometerInputs, durations) -> str:
    """Question 6: does a learned odometer beat INS+NHC, does the spiking one match its twin, how calibrated is it,
    how far is it from an oracle speed, at what energy."""
    q = "Does a learned odometer help?"
    if not odo.measured:
        return f"{q} Not measured: notebook 07's odometer bars have not run for this drive (`evaluate.odometer`)."
    d_long = max(durations)
    nhc = nhc_label("INS")

    def pair(m):
        vals = [odo.cell(m, d) for d in durations]
        return "n/a" if not np.isfinite(vals).any() else "/".join(f"{v:.1f}" for v in vals) + " m"

    text = [f"{q} In the sweep's windows ({odo.n_starts()} starts, every odometer trained on its fold's other "
            f"windows), median max horizontal error at {'/'.join(f'{d:g}' for d in durations)} s: {nhc} "
            f"{pair(nhc)} (no learning), the speed held from the outage start {pair(HOLD)}"]
    for m in LEARNED:
        if odo.has(m):
            ratio = "/".join(f"{odo.cell(m, d, 'ratio_to_nhc'):.2f}" for d in durations)
            text.append(f"{m} {pair(m)} ({ratio} of {nhc} per start, p {'/'.join(_p(odo.cell(m, d, 'p_vs_nhc')) for d in durations)})")
    out = "; ".join(text) + "."
    best = best_learned(odo, d_long)
    if best is not None:
        won = [d for d in durations if beats(odo, best, d)]
        out += (f" The best learned odometer at {d_long:g} s (the lowest median among those that beat {nhc}, else "
                f"among all) is {best}: it "
                + (f"beats {nhc} at {' and '.join(f'{d:g} s' for d in won)}" if won
                   else f"does not beat {nhc} significantly")
                + f" ({best_of(odo, best, d_long)} at {d_long:g} s; significant below {ALPHA:g}).")
    if odo.has(SUBJECT_ODO):
        rmse = odo.cell(SUBJECT_ODO, d_long, "speed_rmse_mps")
        cov = odo.cell(SUBJECT_ODO, d_long, "coverage_2sigma")
        lo, hi = CALIBRATED_COVERAGE
        calib = calibration_word(cov)
        out += (f" {SUBJECT_ODO} is {twin_comparison(odo, d_long)} at {d_long:g} s, {_energy(odo)}. Its speed error in "
                f"the outages: RMSE {rmse:.2f} m/s, {100 * cov:.0f} % of epochs within its +-2 sigma ({calib}: "
                f"{100 * lo:.0f}-{100 * hi:.0f} % is the band of a calibrated std).")
        u = odo.uncertainty
        if u is not None and (u["method"] == SUBJECT_ODO).any():
            said = uncertainty_sentence(u[u['method'] == SUBJECT_ODO])
            out += f" Does it know when it is wrong? {said[:1].upper()}{said[1:]}."
        if odo.has(SUBJECT_ENS):
            n = odo.runs(SUBJECT_ODO)
            e_rmse, e_cov = (odo.cell(SUBJECT_ENS, d_long, c) for c in ("speed_rmse_mps", "coverage_2sigma"))
            e_snn = odo.energy_uj(SUBJECT_ODO)
            out += (f" {SUBJECT_ODO}'s {n} seeds as one ensemble ({SUBJECT_ENS}: the mean speed, the std of the "
                    "members' mixture): "
                    f"{_m(odo.cell(SUBJECT_ENS, d_long))} at {d_long:g} s, speed RMSE {e_rmse:.2f} m/s, "
                    f"{100 * e_cov:.0f} % within +-2 sigma ({calibration_word(e_cov)}), at {n} times the energy per prediction"
                    + (f" ({n * e_snn:.3g} µJ)" if np.isfinite(e_snn) else "") + ".")
        be = odo.oracle_breakeven(d_long)
        at = odo.oracle_at(rmse, d_long)
        out += (f" An oracle speed (the reference's plus white noise) beats {nhc} at {d_long:g} s "
                + (f"up to a noise of {be:g} m/s" if np.isfinite(be) else "at no noise level of its grid")
                + (f"; at {SUBJECT_ODO}'s speed error it reaches {_m(at)}" if np.isfinite(at) else "")
                + " (how accurate a speed must be, and what better learning could give with this filter).")
        out += offset_sentence(odo, d_long)
    return out + curve_sentence(odo) + size_sentence(odo, durations)


def odometer_headline(odo: OdometerInputs, durations) -> str:
    """One clause for the dataset's headline: whether a learned odometer beats INS+NHC at the longest duration,
    and BGFN-ODO against its twin and at what energy; empty when not measured."""
    if not odo.measured:
        return ""
    d = max(durations)
    nhc = nhc_label("INS")
    best = best_learned(odo, d)
    if best is None:
        return ""
    head = (f"a learned odometer beats {nhc} at {d:g} s: {best} {_m(odo.cell(best, d))} against "
            f"{_m(odo.cell(nhc, d))} ({best_of(odo, best, d)})" if beats(odo, best, d) else
            f"no learned odometer beats {nhc} significantly at {d:g} s ({_m(odo.cell(nhc, d))}; best {best} "
            f"{_m(odo.cell(best, d))}, {best_of(odo, best, d)})")
    if odo.has(SUBJECT_ODO):
        word = twin_word(odo, d)
        head += (f"; {SUBJECT_ODO} {_m(odo.cell(SUBJECT_ODO, d))}"
                 + (f" is {word} its ANN twin ({_m(odo.cell(TWIN_ODO, d))})" if word else "") + f", {_energy(odo)}")
    return head
