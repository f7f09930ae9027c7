"""The figures of the results page: the paper's figures that carry data or structure (and what regenerates
each), the figures beyond the paper, and the four drawings notebook 10 makes itself from the profile.

The drawing code is :mod:`bgfn.report.diagrams` (imported here as ``drawings``); this module decides *which*
figures the page shows, with which caption, and what to say when one is missing.
"""

from __future__ import annotations

from pathlib import Path
from typing import Sequence

import matplotlib.pyplot as plt

from bgfn.data.names import dataset_id
from bgfn.io import save_figure
from bgfn.learning import CHANNELS
from bgfn.models import build_model
from bgfn.report import diagrams as drawings
from bgfn.report.reading import ProfileResults, missing_note, rel
from bgfn.train import size_config

#: The paper's figures that carry data or structure, and what regenerates each (``{dataset}``: per dataset).
PAPER_FIGURES: tuple[dict[str, str], ...] = (
    {"label": "ins-gps-loose", "file": "diagram_loosely_coupled.png", "by": "notebook 10 (bgfn.report.diagrams)",
     "caption": "A block diagram of a loosely coupled GPS/INS integration."},
    {"label": "fig:LIF", "file": "lif_neuron.png", "by": "notebook 10 (bgfn.report.diagrams)",
     "caption": "The LIF neuron: a SpikingJelly LIF node with the model's time constant and threshold, driven by "
                "an input current; membrane potential, threshold and output spikes."},
    {"label": "BGFN", "file": "diagram_hybrid_system.png", "by": "notebook 10 (bgfn.report.diagrams)",
     "caption": "The GPS/INS integrated navigation system based on BGFN (training mode solid, prediction mode "
                "dashed)."},
    {"label": "BGFN-arc", "file": "diagram_bgfn_architecture.png", "by": "notebook 10 (bgfn.report.diagrams)",
     "caption": "The architecture of the BGFN, read from the model this profile builds."},
    {"label": "3d", "file": "trajectory_3d.png", "by": "notebook 01",
     "caption": "The NaveGo dataset trajectory, the two outages in red."},
    {"label": "out1-exin", "file": "outage_dataset_1.png", "by": "notebook 04",
     "caption": "The position errors among different algorithms during the first outage in the dataset test."},
    {"label": "out2-exin", "file": "outage_dataset_2.png", "by": "notebook 04",
     "caption": "The position errors among different algorithms during the second outage in the dataset test."},
    {"label": "rob_tra (b)", "file": "trajectory_map.png", "by": "notebook 01",
     "caption": "The vehicle trajectory of the field test; here the Turin drive on which the MPU-6000 stand-in is "
                "simulated (panel (a), a photograph of the vehicle, carries no data)."},
    {"label": "out1-mpu", "file": "outage_field_1.png", "by": "notebook 04",
     "caption": "The position errors among different algorithms during the first outage in the field test."},
    {"label": "out2-mpu", "file": "outage_field_2.png", "by": "notebook 04",
     "caption": "The position errors among different algorithms during the second outage in the field test."},
)

#: Figures beyond the paper shown on the results page (``{dataset}`` expands to every dataset; an entry with a
#: ``test`` is shown only when that test's table exists: the real drive, which not every profile evaluates).
EXTRA_FIGURES: tuple[dict[str, str], ...] = (
    {"label": "energy per layer", "file": "energy_per_layer.png", "by": "notebook 05",
     "caption": "Theoretical energy per layer, BGFN and its Transformer twin (the paper gives no figure for "
                "its energy claim)."},
    {"label": "firing rates", "file": "energy_firing_rates.png", "by": "notebook 05",
     "caption": "Firing rate of every LIF layer of the trained BGFN."},
    {"label": "energy sweeps", "file": "energy_sweeps.png", "by": "notebook 05",
     "caption": "Energy reduction as a function of T_s and of the firing rate."},
    *({"label": f"the GPS row in outage {k} of the dataset test", "file": f"outage_dataset_{k}_gps.png",
       "by": "notebook 04",
       "caption": "East and north error of the GPS row beside the errors of the real GNSS fixes it follows (dots) "
                  "and the standalone INS from the same state."} for k in (1, 2)),
    *({"label": f"outage {k} of the real drive", "file": f"outage_real_{k}.png", "by": "notebook 04",
       "test": "real",
       "caption": f"The position errors among different algorithms during outage {k} of the recorded car drive "
                  "(not in the paper; the rule cruise_and_manoeuvre makes outage 1 the cruise and outage 2 the "
                  "manoeuvre, as in the paper's field test)."} for k in (1, 2)),
    {"label": "outage sweep", "file": "outage_sweep_{dataset}.png", "by": "notebook 06", "datasets": "sweep",
     "caption": "Max horizontal error over many outage starts and durations ({dataset})."},
    {"label": "the filter's consistency in outages", "file": "outage_nees_{dataset}.png", "by": "notebook 06",
     "datasets": "sweep",
     "caption": "Median NEES of the horizontal position at the outage end against the filter's own covariance, "
                "per method and duration ({dataset}); a consistent filter stays near the dashed median line."},
    {"label": "training curves", "file": "training_curves_{dataset}.png", "by": "notebook 03",
     "caption": "Training and validation loss per epoch ({dataset})."},
    {"label": "headings and speeds seen", "file": "motion_coverage_{dataset}.png", "by": "notebook 03",
     "caption": "Heading and speed of the training and validation windows and of the evaluation outages "
                "({dataset}): what the networks must extrapolate to."},
)


def figure_list(figures_dir: str | Path, entries: Sequence[dict],
                datasets: Sequence[str] | dict[str, Sequence[str]] = ()) -> list[dict]:
    """``entries`` with ``path`` and ``exists`` filled in; ``{dataset}`` entries expanded per dataset.

    ``datasets`` is a list, or a dict naming lists (an entry's ``datasets`` key picks one, default ``all``).
    """
    out = []
    for e in entries:
        if "{dataset}" in e["file"]:
            dsets = (list(datasets.get(e.get("datasets", "all"), ())) if isinstance(datasets, dict)
                     else list(datasets))
        else:
            dsets = [None]
        for d in dsets:
            d = dataset_id(d) if d is not None else None          # the id names the file, never a folder path
            name = e["file"].format(dataset=d)
            p = Path(figures_dir) / name
            out.append({**e, "file": name, "caption": e["caption"].format(dataset=d), "path": p,
                        "exists": p.is_file()})
    return out


def draw_diagrams(cfg: dict, evaluation: dict | None, figures_dir: str | Path) -> list[Path]:
    """Draw the paper's four figures that come from code, from the profile ``cfg``, into ``figures_dir``.

    The loosely coupled integration (IMU and GNSS rates, bias model), the LIF neuron (a SpikingJelly LIF node
    with the model's time constant and threshold), the hybrid system (window, fusion rate and pseudo-GPS
    standard deviation: those notebook 04 used, from ``outage_evaluation.json``, else the profile's) and
    BGFN's architecture (read from the model the profile builds).

    Returns
    -------
    list of Path
        The files written, in the order of :data:`PAPER_FIGURES`.
    """
    tc = cfg["train"]
    # the network input: Eq. (eq21)'s channels, then the profile's extra channels (as notebook 03 trains it)
    in_channels = len(CHANNELS) + len(tc.get("extra_channels") or [])
    model = build_model("bgfn", size_config(tc, "bgfn"), in_channels=in_channels)
    imu_rate = cfg["data"]["imu_rate_hz"]
    gnss_rates = {d: cfg["data"][d]["gnss_rate_hz"] for d in cfg["data"].get("datasets", [])
                  if isinstance(cfg["data"].get(d), dict) and "gnss_rate_hz" in cfg["data"][d]}
    pseudo = (evaluation or {}).get("evaluate", {}).get("pseudo_gps") or cfg["evaluate"].get("pseudo_gps") or {}
    made = {
        "diagram_loosely_coupled.png": drawings.plot_loosely_coupled(imu_rate, gnss_rates,
                                                                     bias_model=cfg["nav"].get("bias_model")),
        "lif_neuron.png": drawings.plot_lif(drawings.simulate_lif(drawings.default_lif_current(),
                                                                  **drawings.lif_settings(model))),
        "diagram_hybrid_system.png": drawings.plot_hybrid_system(int(tc["window"]), gnss_rates,
                                                                 float(pseudo["fusion_rate_hz"]),
                                                                 pseudo.get("std_m"), imu_rate),
        "diagram_bgfn_architecture.png": drawings.plot_bgfn_architecture(
            drawings.architecture_spec(model, int(tc["window"]))),
    }
    written = []
    for name, fig in made.items():
        written.append(save_figure(fig, Path(figures_dir) / name))
        plt.close(fig)
    return written


def _datasets(res: ProfileResults) -> dict[str, list[str]]:
    """The dataset lists ``{dataset}`` figures expand over: ``all`` trained, ``sweep`` swept (notebook 06)."""
    return {"all": res.cfg["train"].get("datasets", []),
            "sweep": (res.evaluation or {}).get("evaluate", {}).get("sweep", {}).get("datasets", [])}


def _figure_pieces(res: ProfileResults, entries: Sequence[dict], heading) -> list:
    pieces: list = []
    entries = [e for e in entries if "test" not in e or res.ours.get(e["test"]) is not None]
    for f in figure_list(res.out / "figures", entries, _datasets(res)):
        pieces.append(heading(f))
        pieces.append(f["path"] if f["exists"] else missing_note(f["path"], "this figure", f["by"]))
    return pieces


def paper_figure_section(res: ProfileResults) -> list:
    """The paper's figures (:data:`PAPER_FIGURES`) of ``res``: per figure a Markdown heading (label, caption,
    what regenerated it and where), then its file (a :class:`~pathlib.Path`) or a missing note."""
    return _figure_pieces(res, PAPER_FIGURES, lambda f: (f"**Fig. {f['label']}** (paper). {f['caption']} "
                                                         f"*Regenerated by {f['by']}: `{rel(f['path'])}`.*"))


def extra_figure_section(res: ProfileResults) -> list:
    """The figures beyond the paper (:data:`EXTRA_FIGURES`), as :func:`paper_figure_section`."""
    return _figure_pieces(res, EXTRA_FIGURES, lambda f: (f"**{f['label'].capitalize()}.** {f['caption']} "
                                                         f"*Written by {f['by']}: `{rel(f['path'])}`.*"))
