"""The top of the results page and the book's first page: which runs the page reads (the run header), the
*At a glance* lines, and ``results/<profile>/findings.md``, those lines as the first page includes them."""

from __future__ import annotations

from pathlib import Path
from typing import Sequence

import pandas as pd

from bgfn.config import RUN_RECORDS
from bgfn.paper import TESTS
from bgfn.report.provenance import meta_line, run_meta
from bgfn.report.reading import read_json, rel
from bgfn.report.sentences import energy_sentences, summary_sentence
from bgfn.report.profile_comparison import reference_sentences

#: The JSON files of notebooks 02-08 (what each holds).
RUN_FILES: dict[str, str] = {RUN_RECORDS["kf_baseline"]: "notebook 02, Kalman filter baseline",
                             RUN_RECORDS["training"]: "notebook 03, training",
                             RUN_RECORDS["evaluation"]: "notebook 04, outage evaluation",
                             RUN_RECORDS["energy"]: "notebook 05, energy estimate",
                             RUN_RECORDS["sweep"]: "notebook 06, outage sweep (beyond the paper)",
                             RUN_RECORDS["odometer"]: "notebook 07, learned odometer (beyond the paper)",
                             RUN_RECORDS["ins_fidelity"]: "notebook 08, the INS's fidelity (beyond the paper)"}


def run_header(profile: str, cfg: dict, results: str | Path, current: dict | None = None) -> list[str]:
    """Markdown lines: the profile of this page and, per JSON file of notebooks 02-08, whether it is there and
    what produced it."""
    results = Path(results)
    lines = [f"Profile **`{profile}`** (`params/{profile}.yaml`): {cfg.get('description', '')}",
             f"Results read from `{rel(results)}/`; the page itself: {meta_line(current) if current else '-'}.", ""]
    for name, what in RUN_FILES.items():
        d = read_json(results / name)
        state = meta_line(run_meta(d), current) if d else "**missing**"
        lines.append(f"- `{name}` ({what}): {state}")
    return lines


def glance_lines(profile: str, ours: dict, paper: dict, energy: dict | None, claims: dict,
                 training_summary: pd.DataFrame | None) -> list[str]:
    """The results page's *At a glance*: per test how often BGFN beats each method (ours and the paper's; the
    real drive, once its table exists, beside the paper's field test), the energy estimate beside the claim,
    BGFN's validation error against the untrained references."""
    # the tests whose table notebook 04 wrote (a profile of one's own drives evaluates none of the paper's)
    tests = [t for t in TESTS if ours.get(t) is not None]
    none = [] if tests else ["No outage table of the paper's tests: this profile evaluates none of their datasets "
                             "(the verdict covers its own drives)."]
    return ([summary_sentence(t, ours[t], paper[t]) for t in tests] + none + energy_sentences(energy, claims)
            + reference_sentences(profile, training_summary))


def findings_markdown(profile: str, lines: Sequence[str]) -> str:
    """The *At a glance* lines as a Markdown list for the book's first page (``results/<profile>/findings.md``,
    included there by the book build)."""
    head = (f"From profile `{profile}` (`params/{profile}.yaml`); how each number is made, and the paper's beside "
            "it, is on the {doc}`results page <notebooks/10_results>`.")
    return head + "\n\n" + "\n".join(f"- {s}" for s in lines) + "\n"
