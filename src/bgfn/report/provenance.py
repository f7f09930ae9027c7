"""Where each number on the results page came from: the line under every table naming its file, the run's
metadata (profile, parameter-file hash, commit, versions), the dataset, seeds and trained networks."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Sequence

from bgfn.config import RESULTS_ROOT
from bgfn.data.names import dataset_id
from bgfn.paper import TESTS, test_of
from bgfn.report.reading import rel
from bgfn.train import checkpoints


def model_cards(profile: str, dataset: str, results_root: str | Path | None = None) -> list[dict]:
    """The model cards ``results/<profile>/models/<dataset id>/<method>_seed<k>.json`` (fold models excluded)."""
    d = Path(results_root or RESULTS_ROOT) / profile / "models" / dataset_id(dataset)
    cards = []
    for p in checkpoints.cards(d):
        try:
            cards.append({**json.loads(p.read_text(encoding="utf-8")), "_file": rel(p)})
        except json.JSONDecodeError:
            continue
    return cards


def _fmt_size(method: str, size_cfg: dict) -> str:
    keys = {"bgfn": ("dim", "ffn_dim", "depth", "heads", "time_steps"),
            "transformer": ("dim", "ffn_dim", "depth", "heads", "time_steps")}.get(method)
    items = [(k, size_cfg[k]) for k in (keys or sorted(size_cfg)) if k in size_cfg]
    names = {"time_steps": "T_s", "ffn_dim": "FFN"}
    return ", ".join(f"{names.get(k, k)} {v}" for k, v in items)


def cards_line(cards: list[dict]) -> str:
    """One line on the trained networks behind a table: methods, seeds, size block, window, epochs."""
    if not cards:
        return "no model cards found"
    methods = list(dict.fromkeys(c.get("method") for c in cards))
    seeds = sorted({int(c["seed"]) for c in cards if c.get("seed") is not None})
    sizes = sorted({str(c.get("size")) for c in cards if c.get("size")})
    windows = sorted({int(c["options"]["window"]) for c in cards if c.get("options", {}).get("window")})
    epochs = [int(c["epochs_run"]) for c in cards if c.get("epochs_run") is not None]
    by = sorted({str(c.get("trained_by")) for c in cards if c.get("trained_by")})
    bgfn = next((c for c in cards if c.get("method") == "bgfn" and c.get("size_cfg")), None)
    parts = [f"networks {', '.join(methods)}", f"seeds {', '.join(map(str, seeds)) or '?'}",
             f"size block {', '.join(sizes) or '?'}"]
    if bgfn:
        parts.append(f"BGFN {_fmt_size('bgfn', bgfn['size_cfg'])}")
    if windows:
        parts.append(f"window N = {', '.join(map(str, windows))}")
    if epochs:
        parts.append(f"epochs run {min(epochs)}" + (f"-{max(epochs)}" if max(epochs) != min(epochs) else ""))
    if by:
        parts.append(f"trained by {', '.join(by)}")
    return "; ".join(parts)


def meta_line(meta: dict | None, current: dict | None = None) -> str:
    """Profile, parameter file (hash, and whether it changed since), commit and key versions of a run."""
    if not meta:
        return "no run metadata recorded"
    sha = str(meta.get("params_sha256") or "")
    txt = f"profile `{meta.get('profile')}` (`{meta.get('params_file')}`, sha256 `{sha[:12]}`"
    if current and current.get("params_sha256"):
        txt += (", unchanged since" if current["params_sha256"] == sha else
                f", **changed since**: now `{str(current['params_sha256'])[:12]}`")
    txt += f"), seed {meta.get('seed')}"
    commit = meta.get("git_commit")
    if commit:
        txt += f", commit `{str(commit)[:7]}`" + (" with uncommitted changes" if meta.get("git_dirty") else "")
    pk = meta.get("packages") or {}
    vers = ", ".join(f"{k} {pk[k]}" for k in ("torch", "spikingjelly") if pk.get(k))
    return txt + (f"; {vers}" if vers else "")


def run_meta(run: dict | None) -> dict | None:
    """The run metadata of a notebook's JSON file (notebooks 02-04 write it as ``meta``, 05 as ``metadata``)."""
    if not run:
        return None
    return run.get("meta") or run.get("metadata")


def provenance(source: str | Path, meta: dict | None, current: dict | None = None, **facts: Any) -> str:
    """Markdown line stating what produced a table: its file, the run's metadata and any ``facts``
    (e.g. ``dataset=...``, ``seeds=...``), in the order given."""
    def fmt(v):
        return ", ".join(map(str, v)) if isinstance(v, (list, tuple)) else str(v)

    extra = "; ".join(f"{k.replace('_', ' ')} {fmt(v)}" for k, v in facts.items() if v not in (None, "", []))
    return f"*Source: `{rel(source)}`; {meta_line(meta, current)}" + (f"; {extra}" if extra else "") + ".*"


def short_source(paths: Sequence[str | Path], profile: str, **facts: Any) -> str:
    """A one-line source note for a table derived from ``paths`` (the full metadata line is above it)."""
    files = ", ".join(f"`{rel(p)}`" for p in paths)
    extra = "; ".join(f"{k.replace('_', ' ')} {', '.join(map(str, v)) if isinstance(v, (list, tuple)) else v}"
                      for k, v in facts.items() if v not in (None, "", []))
    return f"*From {files}; profile `{profile}`" + (f"; {extra}" if extra else "") + ".*"


def outage_datasets(evaluation: dict | None) -> dict[str, str]:
    """``{test: dataset}`` of the outage tables, from ``outage_evaluation.json`` (its ``datasets`` in order)."""
    if not evaluation:
        return {}
    out = {}
    for name in evaluation.get("datasets", []):
        test = test_of(name)
        if test and test not in out:
            out[test] = name
    return out


def outage_provenance(profile: str, test: str, results: str | Path, evaluation: dict | None,
                      current: dict | None = None) -> str:
    """Metadata line under an outage table: file, run metadata, dataset, seeds, aggregation, networks."""
    results = Path(results)
    dataset = outage_datasets(evaluation).get(test)
    ev = (evaluation or {}).get("evaluate", {})
    seeds = ev.get("seeds")
    agg = ev.get("seed_aggregate")
    by_dataset = (evaluation or {}).get("outage_windows_by_dataset") or {}   # per dataset (a rule's differ)
    recorded = by_dataset.get(dataset) if dataset in by_dataset else (evaluation or {}).get("outage_windows", [])
    windows = ", ".join(f"{d:g} s from {s:g} s (GPS time of week)" for s, d in recorded or [])
    return provenance(results / "tables" / TESTS[test]["file"], run_meta(evaluation), current,
                      dataset=f"`{dataset}`" if dataset else None,
                      seeds=(f"{', '.join(map(str, seeds))} ({agg} over seeds)" if seeds else None),
                      outages=windows or None,
                      model_cards=(cards_line(model_cards(profile, dataset, results.parent)) if dataset else None))
