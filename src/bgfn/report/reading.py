"""Reading what notebooks 01-05 wrote under ``results/<profile>/`` for the results page.

A missing file is read as ``None`` and reported on the page (:func:`missing_note`), never fatal: the page of
a profile whose notebooks ran only in part still builds and says what is not there.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import pandas as pd

from bgfn import paper, row_labels
from bgfn.config import PROJECT_ROOT, RUN_RECORDS, SHARED_TABLES, read_profile, results_dir, run_metadata
from bgfn.data.names import with_dataset_ids


def rel(path: str | Path) -> str:
    """``path`` relative to the project root (for messages), else as given."""
    p = Path(path)
    try:
        return p.resolve().relative_to(PROJECT_ROOT).as_posix()
    except ValueError:
        return str(p)


def read_csv(path: str | Path) -> pd.DataFrame | None:
    """A CSV table (``#`` comment lines skipped), or ``None`` when the file does not exist. Its rows keyed as the
    code keys them (:func:`bgfn.row_labels.key_labels`: a walker's ``INS+ZUPT`` row reads as ``INS+NHC``; the page
    names it by the aids that ran again, :mod:`bgfn.report.aid_words`)."""
    path = Path(path)
    if not path.is_file():
        return None
    try:
        return row_labels.key_labels(pd.read_csv(path, comment="#"))
    except pd.errors.EmptyDataError:         # a table with nothing to say (no rows, no header): empty, not missing
        return pd.DataFrame()


def read_json(path: str | Path) -> dict | None:
    """A JSON file as a dict, or ``None`` when it does not exist."""
    path = Path(path)
    if not path.is_file():
        return None
    return json.loads(path.read_text(encoding="utf-8"))


def missing_note(path: str | Path, what: str, producer: str) -> str:
    """Markdown line for a table or figure that is not there (instead of failing)."""
    return f"*`{rel(path)}` is missing: {what} was not produced for this profile ({producer}).*"


@dataclass
class ProfileResults:
    """Everything the results page reads for one profile; an input that is missing is ``None``.

    Attributes
    ----------
    profile : str
    cfg : dict
        :func:`bgfn.config.load_profile` of ``params/<profile>.yaml``.
    out : Path
        ``results/<profile>/``.
    current : dict
        :func:`bgfn.config.run_metadata` of the page itself (to say whether a parameter file changed since a
        notebook ran).
    claims : dict
        The percentages the paper states in its text (:func:`bgfn.paper.claims`).
    kf, training, evaluation, energy : dict or None
        ``kf_baseline.json`` (02), ``training.json`` (03), ``outage_evaluation.json`` (04), ``energy.json`` (05).
    sweep_record : dict or None
        ``outage_sweep.json`` (06): the sweep's sizes, wall times and run metadata.
    ours, published : dict
        ``{test: table}`` of :data:`bgfn.paper.TESTS`: our outage table (notebook 04) and the paper's beside it
        (:func:`bgfn.paper.published_values`: for the real drive, the paper's field test).
    training_summary, training_times, sweep, sweep_pairs : DataFrame or None
        ``tables/training_summary.csv``, ``tables/training_times.csv`` (03), ``tables/outage_sweep_summary.csv``
        and ``tables/outage_sweep_pairs.csv`` (06).
    """

    profile: str
    cfg: dict
    out: Path
    current: dict
    claims: dict
    kf: dict | None
    training: dict | None
    evaluation: dict | None
    energy: dict | None
    ours: dict[str, pd.DataFrame | None]
    published: dict[str, pd.DataFrame]
    training_summary: pd.DataFrame | None
    training_times: pd.DataFrame | None
    sweep: pd.DataFrame | None
    sweep_pairs: pd.DataFrame | None
    sweep_record: dict | None = None

    def table(self, name: str) -> Path:
        """Path of ``results/<profile>/tables/<name>``."""
        return self.out / "tables" / name


def read_results(profile: str, out: str | Path | None = None) -> ProfileResults:
    """Read the results page's inputs of ``profile`` from ``out`` (default ``results/<profile>/``, created).

    Raises
    ------
    bgfn.errors.DataError
        ``params/<profile>.yaml`` is missing or invalid (the page needs the profile; a missing *result* is
        ``None``).
    """
    cfg = with_dataset_ids(read_profile(profile), profile)   # an own log by its id, as the notebooks named it
    out = Path(out) if out is not None else results_dir(profile)
    tables = out / "tables"
    return ProfileResults(
        profile=profile, cfg=cfg, out=out, current=run_metadata(profile), claims=paper.claims(),
        kf=read_json(out / RUN_RECORDS["kf_baseline"]), training=read_json(out / RUN_RECORDS["training"]),
        evaluation=read_json(out / RUN_RECORDS["evaluation"]), energy=read_json(out / RUN_RECORDS["energy"]),
        ours={t: read_csv(tables / spec["file"]) for t, spec in paper.TESTS.items()},
        published={t: paper.published_values(t) for t in paper.TESTS},   # the real drive: the field test's
        training_summary=read_csv(tables / SHARED_TABLES["training_summary"]),
        training_times=read_csv(tables / SHARED_TABLES["training_times"]),
        sweep=read_csv(tables / SHARED_TABLES["sweep_summary"]), sweep_pairs=read_csv(tables / SHARED_TABLES["sweep_pairs"]),
        sweep_record=read_json(out / RUN_RECORDS["sweep"]))
