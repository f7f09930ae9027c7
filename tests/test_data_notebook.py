"""Notebook 01 follows the notebook conventions (stored without outputs, papermill parameters cell)."""

from __future__ import annotations

import json

from bgfn.config import PROJECT_ROOT

NB = PROJECT_ROOT / "notebooks" / "01_data_prep.ipynb"


def test_notebook_01_is_stored_clean_with_a_parameters_cell():
    nb = json.loads(NB.read_text())
    code = [c for c in nb["cells"] if c["cell_type"] == "code"]
    assert all(not c.get("outputs") and c.get("execution_count") is None for c in code)
    first = code[0]
    assert "parameters" in first["metadata"].get("tags", [])
    src = "".join(first["source"])
    assert 'profile = "quick"' in src
    assert "outage_windows(cfg, d, e)" in "".join("".join(c["source"]) for c in code)    # the profile's one key
    assert "from bgfn.profile_schema import load_profile" in "".join(code[1]["source"])   # checked at the edge
    body = "".join("".join(c["source"]) for c in code)
    for name in ("trajectory_3d.png", "trajectory_map.png", "imu_channels.png", "dataset_{name}.csv"):
        assert name in body
