"""The wall times of the book's "Reproduce it" page: papermill's metadata read back, Amdahl's projection checked
by hand, a recorded run replacing its own rows only."""

from __future__ import annotations

import json

import pandas as pd
import pytest

from bgfn import config
from bgfn.errors import DataError
from bgfn.report import walltimes as W


def _executed(root, profile, durations):
    folder = root / profile / "notebooks"
    folder.mkdir(parents=True)
    for name, seconds in durations.items():
        (folder / f"{name}.ipynb").write_text(json.dumps(
            {"cells": [], "metadata": {"papermill": {"duration": seconds, "end_time": "2026-11-25T17:00:00"}}}))


def test_amdahl_by_hand():
    # 100 s with 1 job, 60 s with 2: 20 % serial -> 4 jobs: 100 (0.2 + 0.8 / 4) = 40 s
    assert W.amdahl(100.0, 60.0, 4) == pytest.approx(40.0)
    assert W.amdahl(100.0, 50.0, 8) == pytest.approx(12.5)          # perfectly parallel
    assert W.amdahl(100.0, 100.0, 8) == pytest.approx(100.0)        # nothing got faster
    assert W.amdahl(100.0, 120.0, 8) == pytest.approx(100.0)        # slower with 2: taken as serial, not worse


def test_notebook_wall_times_come_from_papermill_metadata(tmp_path, monkeypatch):
    monkeypatch.setattr(config, "RESULTS_ROOT", tmp_path)
    _executed(tmp_path, "p", {"01_data_prep": 5.0, "03_bgfn_training": 300.0})
    (tmp_path / "p" / "notebooks" / ".03_bgfn_training.running-1.ipynb").write_text("{}")    # debris: not read
    times = W.notebook_wall_times("p")
    assert times["notebook"].tolist() == ["01_data_prep", "03_bgfn_training"]
    assert times["wall_s"].tolist() == [5.0, 300.0]
    assert times["cpu_s"].isna().all()                                  # no /usr/bin/time record: unknown
    (tmp_path / "p" / "logs").mkdir()
    (tmp_path / "p" / "logs" / "03_bgfn_training.cpu").write_text("300.5_520.25_19.75\n")   # wall_user_sys
    times = W.notebook_wall_times("p")
    assert times["cpu_s"].iloc[1] == pytest.approx(540.0)
    page = W.wall_time_markdown("p", pd.DataFrame(columns=list(W.MEASURED_COLUMNS)))
    assert "| 03_bgfn_training | 5.0 min (300 s) | 9.0 min (540 s) | 180 % |" in page
    assert "| 01_data_prep | 0.1 min (5 s) | - | - |" in page
    (tmp_path / "p" / "notebooks" / "02_kf_baseline.ipynb").write_text(json.dumps({"cells": [], "metadata": {}}))
    with pytest.raises(DataError, match="02_kf_baseline.ipynb.*papermill"):
        W.notebook_wall_times("p")


def test_a_recorded_run_replaces_only_its_own_rows_and_the_page_projects(tmp_path, monkeypatch):
    monkeypatch.setattr(config, "RESULTS_ROOT", tmp_path)
    measured = tmp_path / "measured.csv"
    _executed(tmp_path, "p", {"03_bgfn_training": 600.0, "04_outage_evaluation": 200.0})
    W.record_run("p", 1, total_s=900.0, path=measured)
    W.record_run("p", 1, total_s=1000.0, path=measured)                 # the same run again: replaced
    (tmp_path / "p" / "notebooks" / "03_bgfn_training.ipynb").unlink()
    _executed(tmp_path, "q", {})
    json_2 = {"03_bgfn_training": 330.0, "04_outage_evaluation": 150.0}
    for name, s in json_2.items():
        (tmp_path / "p" / "notebooks" / f"{name}.ipynb").write_text(json.dumps(
            {"cells": [], "metadata": {"papermill": {"duration": s}}}))
    W.record_run("p", 2, total_s=600.0, note="fresh clone", path=measured)
    table = W.read_measured(measured)
    assert len(table) == 6 and table[table["notebook"] == "total"]["wall_s"].tolist() == [1000.0, 600.0]
    scale = W.scaling_table(table, "p", projected=(4,))
    assert scale.index.tolist() == ["03_bgfn_training", "04_outage_evaluation", "total"]
    assert scale.loc["03_bgfn_training", "speed-up"] == pytest.approx(600 / 330)
    assert scale.loc["03_bgfn_training", "serial share"] == pytest.approx(0.1)     # 2 * 330 / 600 - 1
    assert scale.loc["03_bgfn_training", "4 jobs (s), projected"] == pytest.approx(600 * (0.1 + 0.9 / 4))
    assert W.scaling_table(table, "other").empty
    page = W.wall_time_markdown("p", table)
    assert "| 03_bgfn_training | 5.5 min (330 s) |" in page and "Amdahl" in page and "fresh clone" in page
    assert "not this build's" not in page                               # the same notebooks
    (tmp_path / "p" / "notebooks" / "04_outage_evaluation.ipynb").rename(tmp_path / "p" / "notebooks" / "04_x.ipynb")
    page = W.wall_time_markdown("p", table)                             # renamed since the runs were measured
    assert "not this build's: 04_outage_evaluation is not among this build's notebooks" in page


def test_a_measured_file_without_its_columns_is_refused(tmp_path):
    bad = tmp_path / "m.csv"
    pd.DataFrame({"profile": ["p"], "jobs": [1]}).to_csv(bad, index=False)
    with pytest.raises(DataError, match="notebook"):
        W.read_measured(bad)


def test_the_book_build_steps_import_no_torch_and_no_study(tmp_path, monkeypatch):
    """The book's build runs ``python -m bgfn.report.walltimes`` and ``python -m bgfn.report.book_notebooks`` one
    after the other while both cores wait: each must start in a second or two, not the 8 s of torch and the studies."""
    import subprocess
    import sys

    code = ("import sys, bgfn.report.walltimes, bgfn.report.book_notebooks; "
            "sys.exit(' '.join(m for m in sys.modules if m == 'torch' or m.startswith('bgfn.studies')) or None)")
    res = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert res.returncode == 0 and res.stderr == "", res.stderr
    make = (config.PROJECT_ROOT / "Makefile").read_text()
    assert "-m bgfn.report.walltimes --profile" in make and "-m bgfn.report.book_notebooks --profile" in make
    monkeypatch.setattr(config, "RESULTS_ROOT", tmp_path)
    out = tmp_path / "wall_times.md"
    assert W.main(["--profile", "smoke", "--markdown", str(out)]) == 0
    assert out.read_text().startswith("### This build (`smoke`)\n\nNo executed notebook of this profile yet.")
