"""Checkpoint names are built and read back by one module (bgfn.train.checkpoints)."""

from __future__ import annotations

import pytest

from bgfn.train import checkpoints as ck
from bgfn import config


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
