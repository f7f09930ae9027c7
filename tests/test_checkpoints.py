"""Checkpoint names are built and read back by one module (bgfn.train.checkpoints)."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from bgfn.train import checkpoints as ck
from bgfn import config
from bgfn.errors import DataError


def test_checkpoint_path_round_trips_through_the_parser(tmp_path, monkeypatch):
    monkeypatch.setattr(config, "RESULTS_ROOT", tmp_path)
    best = ck.checkpoint_path("p", "turin-sim-mpu6000", "at_lstm", 2)
    assert best == tmp_path / "p" / "models" / "turin-sim-mpu6000" / "at_lstm_seed2.pt"
    assert ck.parse_checkpoint(best) == ("at_lstm", 2, None)
    fold = ck.checkpoint_path("p", "d", "bgfn", 0, fold=1)
    assert fold.parent.name == "fold1" and ck.parse_checkpoint(fold) == ck.Checkpoint("bgfn", 0, 1)
    # the card and the resumable state sit beside the best checkpoint and parse to the same network
    assert ck.card_path(best).name == "at_lstm_seed2.json" and ck.last_path(best).name == "at_lstm_seed2.last.pt"
    assert ck.parse_checkpoint(ck.card_path(best)) == ck.parse_checkpoint(ck.last_path(best)) == ("at_lstm", 2, None)


def test_cards_lists_only_network_cards_of_the_folder(tmp_path):
    for name in ("bgfn_seed0.json", "mlp_seed10.json", "notes.json", "bgfn_seed0.pt"):
        (tmp_path / name).write_text("{}")
    (tmp_path / "fold0").mkdir()
    (tmp_path / "fold0" / "bgfn_seed1.json").write_text("{}")
    assert [p.name for p in ck.cards(tmp_path)] == ["bgfn_seed0.json", "mlp_seed10.json"]


@pytest.mark.parametrize("name", ["bgfn.pt", "bgfn_seedx.pt", "bgfn_seed1.npz", "_seed1.pt"])
def test_a_foreign_file_name_is_refused(name):
    with pytest.raises(ValueError, match="not a network file"):
        ck.parse_checkpoint(name)


def test_a_drive_named_by_its_folder_path_keeps_every_model_folder_under_results(tmp_path, monkeypatch):
    results = tmp_path / "results"
    monkeypatch.setattr(config, "RESULTS_ROOT", results)
    log = tmp_path / "logs" / "run 3"
    log.mkdir(parents=True)
    # the variants, the odometers and the recheck of a drive given by an absolute path: its id, never the path
    for folder in (ck.variant_models_dir("p", "velocity", str(log)), ck.odometer_models_dir("p", str(log), 0),
                   ck.all_windows_models_dir("p", str(log)), ck.models_dir("p", str(log))):
        assert folder.is_relative_to(results / "p" / "models") and "run-3" in folder.parts
    assert list(log.iterdir()) == []                       # nothing written into the user's data folder
    with pytest.raises(DataError, match="a folder under"):
        ck._made(tmp_path / "elsewhere", create=True)
    assert not (tmp_path / "elsewhere").exists()


def test_a_corrupt_or_foreign_checkpoint_is_one_error_naming_its_file(tmp_path, monkeypatch):
    monkeypatch.setattr(config, "RESULTS_ROOT", tmp_path)
    path = ck.checkpoint_path("p", "d", "bgfn", 0)
    path.write_bytes(b"not a checkpoint")
    with pytest.raises(DataError, match=r"bgfn_seed0\.pt.*make reproduce PROFILE=p"):
        ck.read_checkpoint(path)
    # a pickle that would run code (weights_only refuses it) is not loaded either
    torch.save({"state_dict": {}, "hook": np.random.default_rng(0)}, path)
    with pytest.raises(DataError, match="checkpoint"):
        ck.read_checkpoint(path)
    torch.save({"state_dict": {"w": torch.ones(2)}, "norm": {"x_mean": [0.0]}}, path)
    assert ck.read_checkpoint(path)["state_dict"]["w"].sum() == 2.0


def test_the_advice_for_a_corrupt_checkpoint_deletes_the_notebook_that_trains_it(tmp_path, monkeypatch):
    monkeypatch.setattr(config, "PROJECT_ROOT", tmp_path)
    monkeypatch.setattr(config, "RESULTS_ROOT", tmp_path / "results")
    cases = {ck.checkpoint_path("p", "d", "bgfn", 0): "03_bgfn_training",
             ck.variant_models_dir("p", "velocity", "d") / "mlp_seed1.pt": "03_bgfn_training",
             ck.checkpoint_path("p", "d", "bgfn", 2, fold=1): "06_outage_sweep",
             ck.odometer_models_dir("p", "d", 0) / "mlp_seed0.pt": "07_learned_odometer"}
    for path, notebook in cases.items():
        assert ck.writer_notebook(path) == notebook
        path.write_bytes(b"truncated")
        with pytest.raises(DataError) as err:
            ck.read_checkpoint(path)
        rel = path.relative_to(tmp_path).as_posix()
        assert f"`rm -f {rel} results/p/notebooks/{notebook}.ipynb && make reproduce PROFILE=p`" in str(err.value)


def test_the_train_command_the_energy_step_suggests_passes_the_profile_check(tmp_path, monkeypatch):
    import re
    import shlex

    from bgfn.__main__ import train_config
    from bgfn.energy.checkpoint import energy_checkpoint
    from bgfn.profile_schema import load_profile

    monkeypatch.setattr(config, "RESULTS_ROOT", tmp_path)
    for profile in ("smoke", "quick"):
        with pytest.raises(FileNotFoundError) as err:
            energy_checkpoint(profile, "bgfn", load_profile(profile))
        words = shlex.split(re.search(r"`python -m bgfn train ([^`]*)`", str(err.value)).group(1))
        opts = dict(zip(words[::2], words[1::2]))
        cfg = train_config(opts["--profile"], [opts["--dataset"]], [opts["--method"]], [int(opts["--seed"])])
        assert cfg["train"]["datasets"] == [opts["--dataset"]] and cfg["variants"] == {}
        assert load_profile(profile)["variants"] or profile == "smoke"       # the profile's own are untouched
