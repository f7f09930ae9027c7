"""Plain sentences computed from the numbers of the results page: who has the smaller max error, outage by
outage and in how many cases; BGFN's reduction against INS beside the paper's; the energy estimate beside
the paper's claim. Values equal at the paper's precision (:data:`bgfn.paper.DECIMALS`) are called equal."""

from __future__ import annotations

import math
from typing import Sequence

import numpy as np
import pandas as pd

from bgfn.paper import DECIMALS, TESTS, published_test

#: Everything BGFN is compared with on this page (Transformer: ANN twin; GPS: the lower bound).
BASELINES: tuple[str, ...] = ("INS", "MLP", "AT-LSTM", "Transformer", "GPS")
#: Extra rows of our tables that the paper does not have, and what they are.
EXTRA_METHODS: dict[str, str] = {"Transformer": "the ANN twin of BGFN, not in the paper",
                                 "GPS": "the GPS-aided solution over the same window: the lower bound"}
EXTRA_TAGS: dict[str, str] = {"Transformer": "ANN twin", "GPS": "lower bound"}


def paper_name(test: str) -> str:
    """How a sentence names the paper's values beside ``test``: ``paper``, or ``paper's field test`` beside the
    real drive (the paper has no table of its own for it)."""
    shown = published_test(test)
    return "paper" if shown == test else f"paper's {TESTS[shown]['title']}"


def bullets(lines: Sequence[str]) -> str:
    """``lines`` as one Markdown list (empty text for no lines)."""
    return "\n".join(f"- {s}" for s in lines)


def _m(x: float) -> str:
    return f"{x:.{DECIMALS}f} m"


def _cmp(a: float, b: float) -> str:
    """'better' / 'worse' / 'equal' for a BGFN error ``a`` against a baseline error ``b`` (at table precision)."""
    ra, rb = round(float(a), DECIMALS), round(float(b), DECIMALS)
    return "equal" if ra == rb else ("better" if ra < rb else "worse")


def _verdict(east: str, north: str) -> str:
    if east == north:
        return {"better": "better on both axes", "worse": "worse on both axes",
                "equal": "equal on both axes"}[east]
    return f"{east} in east, {north} in north"


def _lookup(table: pd.DataFrame | None) -> dict:
    if table is None:
        return {}
    return {(int(r.outage), r.method): (float(r.max_east_m), float(r.max_north_m)) for r in table.itertuples()}


def win_counts(table: pd.DataFrame | None, method: str = "BGFN", baselines: Sequence[str] = BASELINES) -> dict:
    """``{baseline: (wins, comparisons)}``: in how many (outage, axis) cases ``method``'s max error is smaller."""
    look = _lookup(table)
    outages = sorted({o for o, _ in look})
    out = {}
    for b in baselines:
        wins = n = 0
        for o in outages:
            if (o, method) in look and (o, b) in look:
                for i in range(2):
                    n += 1
                    wins += _cmp(look[(o, method)][i], look[(o, b)][i]) == "better"
        if n:
            out[b] = (wins, n)
    return out


def summary_sentence(test: str, ours: pd.DataFrame | None, paper: pd.DataFrame | None, method: str = "BGFN") -> str:
    """How often BGFN has the smaller max error against each baseline, ours and in the paper."""
    t = TESTS[test]["title"]
    if ours is None:
        return f"{t.capitalize()}: our table is missing, so no comparison can be made."
    mine, theirs = win_counts(ours, method), win_counts(paper, method)
    parts = []
    for b, (w, n) in mine.items():
        p = theirs.get(b)
        tag = f" ({EXTRA_TAGS[b]})" if b in EXTRA_TAGS else ""
        parts.append(f"against {b}{tag} in {w} of {n}" + (f" ({paper_name(test)}: {p[0]} of {p[1]})" if p else ""))
    return (f"{t.capitalize()}: {method} has the smaller max error (cases: outage x axis) " + "; ".join(parts)
            + ".")


def comparison_sentences(test: str, ours: pd.DataFrame | None, paper: pd.DataFrame | None, method: str = "BGFN",
                         baselines: Sequence[str] = BASELINES) -> list[str]:
    """One sentence per outage and baseline: BGFN's max east/north errors against the baseline's, ours and the
    paper's, and which is smaller."""
    look, plook = _lookup(ours), _lookup(paper)
    lines = []
    for o in sorted({k[0] for k in look} | {k[0] for k in plook}):
        if (o, method) not in look:
            lines.append(f"Outage {o}: no {method} row in our table.")
            continue
        be, bn = look[(o, method)]
        for b in baselines:
            if (o, b) not in look:
                continue
            e, n = look[(o, b)]
            txt = (f"Outage {o}, {method} vs {b}: {method}'s max east error is {_m(be)} vs {b}'s {_m(e)}, its max "
                   f"north error {_m(bn)} vs {_m(n)}; {method} is {_verdict(_cmp(be, e), _cmp(bn, n))}")
            if (o, method) in plook and (o, b) in plook:
                pbe, pbn = plook[(o, method)]
                pe, pn = plook[(o, b)]
                txt += (f" ({paper_name(test)}: {_m(pbe)} vs {_m(pe)} east, {_m(pbn)} vs {_m(pn)} north, "
                        f"{_verdict(_cmp(pbe, pe), _cmp(pbn, pn))})")
            elif b in EXTRA_METHODS:
                txt += f" ({b}: {EXTRA_METHODS[b]})"
            lines.append(txt + ".")
    return lines


def _pct_phrase(pct: float) -> str:
    if not math.isfinite(pct):
        return "undefined"
    return f"reduced by {pct:.1f} %" if pct >= 0 else f"increased by {-pct:.1f} %"


def reduction_sentences(comp: pd.DataFrame, method: str = "BGFN", test: str | None = None) -> list[str]:
    """Sentences from :func:`bgfn.report.tables.reduction_comparison`: our reduction against INS beside the
    paper's (of ``test``; beside the real drive, the paper's field test's)."""
    theirs = paper_name(test) if test else "paper"
    theirs = "paper's" if theirs == "paper" else theirs
    lines = []
    for row in comp.index:
        for axis in ("East", "North"):
            ours = comp.loc[row, ("ours", axis)]
            if not np.isfinite(ours):
                continue
            txt = f"{row}, {axis.lower()}: with {method} the max error of INS is {_pct_phrase(ours)}"
            ptab, ptxt = comp.loc[row, ("paper (table)", axis)], comp.loc[row, ("paper (text)", axis)]
            ref = []
            if np.isfinite(ptab):
                ref.append(f"{theirs} table: {_pct_phrase(ptab)}")
            if np.isfinite(ptxt):
                ref.append(f"{theirs} text: {ptxt:.1f} %")
            lines.append(txt + (f" ({'; '.join(ref)})" if ref else "") + ".")
    return lines


def network_improved(energy: dict, method: str = "bgfn") -> bool:
    """Whether ``method``'s network in ``energy.json`` improved on its initial network in training (its
    ``improved`` flag; from ``checkpoint_epochs`` for a file written before the flag: best epoch >= 1; True when
    neither says)."""
    flags = energy.get("improved") or {}
    if method in flags:
        return bool(flags[method])
    epoch = (energy.get("checkpoint_epochs") or {}).get(method)
    return epoch is None or int(epoch) >= 1


def energy_sentences(energy: dict | None, claims: dict) -> list[str]:
    """BGFN's theoretical energy against its Transformer twin, and the paper's claim; for a BGFN that did not
    train (:func:`network_improved`), a sentence saying so in place of any saving."""
    paper = claims.get("energy_reduction_vs_transformer_pct")
    if not energy:
        return ["`energy.json` is missing: notebook 05 has not run for this profile, so there is no energy "
                "estimate to compare with the paper's claim."]
    if not network_improved(energy):
        epoch = (energy.get("checkpoint_epochs") or {}).get("bgfn", 0)
        return [f"BGFN did not train: the checkpoint measured (best epoch {epoch}) is its initial network, which "
                "training never improved on, so its firing rates, and the energy they "
                "give, are an untrained network's: no energy saving against the Transformer twin is claimed"
                + (f" (the paper states {float(paper):.1f} % less)." if paper is not None else ".")]
    e = energy.get("energy_uj_per_prediction", {})
    red = float(energy.get("reduction_pct", float("nan")))
    verb = "less" if red >= 0 else "more"
    txt = (f"BGFN needs {e.get('bgfn', float('nan')):.3g} µJ per prediction against "
           f"{e.get('transformer', float('nan')):.3g} µJ for its ANN Transformer twin, {abs(red):.1f} % {verb} "
           f"energy (45 nm, {energy.get('e_mac_pj')} pJ per MAC, {energy.get('e_ac_pj')} pJ per accumulate, "
           f"T_s = {energy.get('time_steps')})")
    if paper is not None:
        txt += f"; the paper states {float(paper):.1f} % less than a conventional Transformer"
        diff = red - float(paper)
        txt += (f", so our estimate is {abs(diff):.1f} percentage points "
                + ("higher" if diff > 0 else "lower" if diff < 0 else "equal") + "")
    lines = [txt + "."]
    if energy.get("reduction_pct_without_attention") is not None:
        lines.append(f"Leaving the attention products out of both counts, the reduction is "
                     f"{float(energy['reduction_pct_without_attention']):.1f} %.")
    return lines
