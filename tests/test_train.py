"""The training loop (bgfn.train): artifacts, references, early stopping, determinism and resume; the learning-rate
search; a profile's training over datasets, methods and seeds, and its tables."""

from __future__ import annotations

import json
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest
import torch

from bgfn import learning as L
from bgfn import models
from bgfn import train as T
from bgfn.errors import DataError
from bgfn.report import training_words
from bgfn.io import sources_hash
from bgfn.train import loop, lr_search
from bgfn.profile_schema import load_profile, with_overrides

torch.set_num_threads(1)


@pytest.fixture(scope="module")
def data():
    imu, att, gnss = L.synthetic_tables(duration_s=300.0, noise=0.05, seed=1)
    return L.build_learning_data(imu, att, gnss, [(1060.0, 20.0)], window=40, margin_s=2.0, val_fraction=0.25,
                                 val_position="end")


def _cfg(**opt):
    base = {"epochs": 3, "batch_size": 16, "lr": 3e-3, "patience": 50, "schedule": "plateau"}
    return {"optimizer": {**base, **opt}}


def test_card_checkpoint_and_references(data, tmp_path):
    card = T.train_model("mlp", data, {"n_recent": 5, "hidden": 16}, _cfg(), seed=0, out_dir=tmp_path,
                         progress=False, extra_card={"dataset": "toy"})
    for key in ("params", "epochs_run", "best_val_loss", "wall_time_s", "device", "history", "val_rmse_m",
                "val_rmse_zero_m", "val_rmse_last_m", "val_rmse_ins_m", "n_train", "n_val", "dataset"):
        assert key in card
    # epoch 0 is the initial network (validated, not trained), then the 3 training epochs
    assert card["epochs_run"] == 3 and [h["epoch"] for h in card["history"]] == [0, 1, 2, 3]
    assert card["history"][0]["train_loss"] is None and card["history"][1]["train_loss"] > 0
    assert {"train_loss", "val_loss", "val_rmse_m"} <= set(card["history"][0])
    assert card["val_rmse_zero_m"] == pytest.approx(L.reference_rmse(data.val)["zero"])
    assert card["val_rmse_last_m"] == pytest.approx(L.reference_rmse(data.val)["last"])
    assert card["val_rmse_ins_m"] == pytest.approx(L.reference_rmse(data.val)["ins"])
    assert card["val_rmse_ins_m"] < card["val_rmse_last_m"]        # toy drive: velocity known, exact fixes
    assert json.loads((tmp_path / "mlp_seed0.json").read_text())["val_rmse_m"] == pytest.approx(card["val_rmse_m"])
    assert not (tmp_path / "mlp_seed0.last.pt").exists()
    # the checkpoint reproduces the card's validation error
    tm = T.load_trained(tmp_path / "mlp_seed0.pt")
    assert L.rmse(tm.predict_windows(data.val), data.val.y) == pytest.approx(card["val_rmse_m"], rel=1e-5)
    # a completed run is not redone
    mtime = (tmp_path / "mlp_seed0.pt").stat().st_mtime_ns
    again = T.train_model("mlp", data, {"n_recent": 5, "hidden": 16}, _cfg(), seed=0, out_dir=tmp_path,
                          progress=False)
    assert again["history"] == card["history"] and (tmp_path / "mlp_seed0.pt").stat().st_mtime_ns == mtime
    # a card written before a reference existed gains it when read back, without training again
    stale = json.loads((tmp_path / "mlp_seed0.json").read_text())
    del stale["val_rmse_ins_m"]
    (tmp_path / "mlp_seed0.json").write_text(json.dumps(stale))
    again = T.train_model("mlp", data, {"n_recent": 5, "hidden": 16}, _cfg(), seed=0, out_dir=tmp_path,
                          progress=False)
    assert again["val_rmse_ins_m"] == pytest.approx(card["val_rmse_ins_m"])
    assert json.loads((tmp_path / "mlp_seed0.json").read_text())["val_rmse_ins_m"] == again["val_rmse_ins_m"]
    assert (tmp_path / "mlp_seed0.pt").stat().st_mtime_ns == mtime


def test_the_code_fingerprints_are_hashes_of_the_source(tmp_path):
    a, b = tmp_path / "a.py", tmp_path / "b.py"
    a.write_text("x = 1\n")
    b.write_text("y = 2\n")
    before = sources_hash([a, b])
    assert sources_hash([a, b, tmp_path / "absent.py"]) == before         # a missing file is skipped
    a.write_text("x = 1\n# a comment\n")                                  # any edit counts
    assert sources_hash([a, b]) != before
    package = Path(models.__file__).parent
    assert models.definition_fingerprint() == sources_hash(sorted(package.glob("*.py")))[:16]
    assert loop.training_fingerprint() == sources_hash([Path(loop.__file__).resolve(),
                                                        Path(loop.__file__).resolve().with_name("objectives.py")])[:16]
    assert {p.name for p in package.glob("*.py")} >= {"bgfn.py", "lif.py", "lif_kernels.py", "baselines.py"}


@pytest.mark.parametrize("fingerprint", ["definition_fingerprint", "training_fingerprint"])
def test_a_network_trained_under_other_code_is_trained_again(data, tmp_path, monkeypatch, fingerprint):
    size = {"n_recent": 5, "hidden": 16}
    card = T.train_model("mlp", data, size, _cfg(), seed=0, out_dir=tmp_path, progress=False)
    mtime = (tmp_path / "mlp_seed0.pt").stat().st_mtime_ns
    # the same code: reused, not trained
    again = T.train_model("mlp", data, size, _cfg(), seed=0, out_dir=tmp_path, progress=False)
    assert (tmp_path / "mlp_seed0.pt").stat().st_mtime_ns == mtime and again["history"] == card["history"]
    # the layers' code (as when a bias was removed) or the loop's changed: trained again, the checkpoint rewritten
    monkeypatch.setattr(loop, fingerprint, lambda: "other-code")
    retrained = T.train_model("mlp", data, size, _cfg(), seed=0, out_dir=tmp_path, progress=False)
    assert (tmp_path / "mlp_seed0.pt").stat().st_mtime_ns != mtime
    assert retrained["config_hash"] != card["config_hash"]


def test_a_checkpoint_whose_weights_the_code_no_longer_builds_is_refused_by_name(data, tmp_path):
    T.train_model("mlp", data, {"n_recent": 5, "hidden": 16}, _cfg(epochs=1), seed=0, out_dir=tmp_path,
                  progress=False)
    path = tmp_path / "mlp_seed0.pt"
    ck = torch.load(path, weights_only=True)
    first = next(iter(ck["state_dict"]))
    ck["state_dict"]["net.99.bias"] = torch.zeros(3)            # a weight the code does not build (an old bias)
    ck["state_dict"][first] = torch.zeros(7, 7)                 # and one of another shape
    torch.save(ck, path)
    with pytest.raises(DataError) as err:
        T.load_trained(path)
    msg = str(err.value)
    assert "mlp_seed0.pt" in msg and "state_dict" in msg and "unexpected net.99.bias" in msg
    assert f"other shape {first}" in msg and "train it again" in msg


@pytest.mark.parametrize("method,size", [("mlp", {"n_recent": 10, "hidden": 32}), ("at_lstm", {"hidden": 16})])
def test_training_learns_and_beats_zero(data, method, size):
    card = T.train_model(method, data, size, _cfg(epochs=15), seed=0, progress=False)
    h = card["history"]
    assert h[-1]["train_loss"] < 0.5 * h[1]["train_loss"]
    assert card["val_rmse_m"] < 0.8 * card["val_rmse_zero_m"]
    # it improved on the initial network (epoch 0), whose validation error the card keeps
    assert card["best_epoch"] >= 1 and card["val_rmse_m"] < h[0]["val_rmse_m"]


def test_early_stopping(data):
    card = T.train_model("mlp", data, {"hidden": 8}, _cfg(epochs=20, lr=0.0, patience=2, schedule="none"),
                         seed=0, progress=False)
    # nothing learns at lr 0: two training epochs without improvement stop it, and the reported network is the
    # initial one, said as best_epoch 0 (bgfn.energy refuses such a BGFN)
    assert card["epochs_run"] == 2 and card["stopped_early"] and card["best_epoch"] == 0
    assert card["val_rmse_m"] == pytest.approx(card["history"][0]["val_rmse_m"], rel=1e-6)


def test_bgfn_resets_and_is_deterministic(data):
    size = {"dim": 16, "ffn_dim": 16, "depth": 1, "heads": 2, "time_steps": 2}
    a = T.train_model("bgfn", data, size, _cfg(epochs=2, max_train_windows=48), seed=5, progress=False)
    b = T.train_model("bgfn", data, size, _cfg(epochs=2, max_train_windows=48), seed=5, progress=False)
    assert a["history"][-1]["val_loss"] == b["history"][-1]["val_loss"]
    assert a["n_train"] == 48


class _Interrupt(Exception):
    pass


def test_resume_after_interruption_gives_the_same_run(data, tmp_path):
    size = {"hidden": 8, "n_recent": 4}
    full = T.train_model("mlp", data, size, _cfg(epochs=4), seed=2, progress=False)
    calls = {"n": 0}
    orig = loop.predict_normalized

    def flaky(*args, **kwargs):                       # dies in the validation of the 3rd epoch
        calls["n"] += 1
        if calls["n"] == 3:
            raise _Interrupt
        return orig(*args, **kwargs)

    loop.predict_normalized = flaky                   # the name the training loop calls
    try:
        with pytest.raises(_Interrupt):
            T.train_model("mlp", data, size, _cfg(epochs=4), seed=2, out_dir=tmp_path, progress=False)
    finally:
        loop.predict_normalized = orig
    assert (tmp_path / "mlp_seed2.last.pt").exists() and not (tmp_path / "mlp_seed2.json").exists()
    resumed = T.train_model("mlp", data, size, _cfg(epochs=4), seed=2, out_dir=tmp_path, progress=False)
    assert resumed["epochs_run"] == 4
    assert [h["val_loss"] for h in resumed["history"]] == pytest.approx([h["val_loss"] for h in full["history"]],
                                                                         rel=1e-6)


def test_predict_increments_for_an_outage(data, tmp_path):
    T.train_model("at_lstm", data, {"hidden": 8}, _cfg(epochs=1), seed=0, out_dir=tmp_path, progress=False)
    tm = T.load_trained(tmp_path / "at_lstm_seed0.pt")
    imu, att, _ = L.synthetic_tables(duration_s=300.0, noise=0.05, seed=1)
    epochs = np.arange(1060.0, 1081.0)
    dp = tm.predict_increments(imu, att, epochs)
    assert dp.shape == (20, 2) and np.isfinite(dp).all()


def test_profile_helpers():
    tc = {"size": "quick", "sizes": {"mlp": {"quick": {"hidden": 4}}}, "lr": {"bgfn": 5e-4},
          "optimizer": {"lr": 1e-3}}
    assert T.size_config(tc, "mlp") == {"hidden": 4}
    assert T.method_lr(tc, "bgfn") == 5e-4 and T.method_lr(tc, "mlp") == 1e-3
    with pytest.raises(ValueError):
        T.size_config(tc, "bgfn")
    with pytest.raises(ValueError):
        T.optimizer_options({"optimizer": {"epoch": 3}})


def test_heading_frame_predictions_come_back_in_ned(tmp_path):
    imu, att, gnss = L.synthetic_tables(duration_s=300.0, noise=0.05, seed=1)
    data = L.build_learning_data(imu, att, gnss, [], window=40, val_fraction=0.25, target_frame="heading")
    card = T.train_model("mlp", data, {"n_recent": 10, "hidden": 16}, _cfg(epochs=8), seed=0, out_dir=tmp_path,
                         progress=False)
    tm = T.load_trained(tmp_path / "mlp_seed0.pt")
    pred = tm.predict_windows(data.val)
    assert L.rmse(pred, data.val.y) == pytest.approx(card["val_rmse_m"], rel=1e-5)
    assert card["val_rmse_m"] < 0.3 * card["val_rmse_zero_m"]      # heading frame: only the speed to learn
    table = tm.increment_table(imu, att, np.arange(1100.0, 1111.0))
    assert list(table.columns) == ["time", "delta_p_n", "delta_p_e"] and len(table) == 10


def test_profile_train_sections_are_complete_and_consistent():
    from bgfn.config import PROFILES
    from bgfn.profile_schema import load_profile
    from bgfn.models import METHODS, build_model

    sections = {p: load_profile(p)["train"] for p in PROFILES}
    sizes = [s["sizes"] for s in sections.values()]
    assert all(s == sizes[0] for s in sizes), "train.sizes must be the same blocks in every profile"
    for name, tc in sections.items():
        T.optimizer_options(tc)
        assert set(L.learning_options(tc)) == set(L.LEARNING_DEFAULTS)
        assert set(tc["methods"]) == set(METHODS)
        for m in METHODS:
            assert T.method_lr(tc, m) > 0
            build_model(m, T.size_config(tc, m))
    paper = sections["paper"]
    assert paper["window"] == 200 and paper["optimizer"]["batch_size"] == 8 and paper["optimizer"]["epochs"] == 1000
    assert {k: T.size_config(paper, "bgfn")[k] for k in ("dim", "ffn_dim", "depth")} == {"dim": 256, "ffn_dim": 256,
                                                                                           "depth": 4}


def test_summary_table_aggregates_seeds():
    base = {"dataset": "d", "method": "bgfn", "params": 10, "epochs_run": 4, "best_epoch": 2, "n_train": 5,
            "n_val": 2, "val_rmse_zero_m": 3.0, "val_rmse_last_m": 1.0, "device": "cpu"}
    cards = [{**base, "seed": 0, "wall_time_s": 1.0, "val_rmse_m": 2.0},
             {**base, "seed": 1, "wall_time_s": 3.0, "val_rmse_m": 2.5}]
    s = T.summary_table(cards)
    assert len(s) == 1 and s.loc[0, "seeds"] == 2
    assert s.loc[0, "val_rmse_m_mean"] == pytest.approx(2.25) and s.loc[0, "train_time_s_total"] == 4.0


def test_result_tables_leave_wall_clock_out():
    """Saved result tables must be identical between runs: wall-clock columns go to their own table."""
    cards = [{"dataset": "d", "method": m, "seed": s, "params": 10, "epochs_run": 3, "best_epoch": 2,
              "wall_time_s": 1.0 + s, "val_rmse_m": 0.5, "val_rmse_zero_m": 1.0, "val_rmse_last_m": 0.2}
             for m in ("bgfn", "mlp") for s in (0, 1)]
    runs, summary = T.cards_table(cards), T.summary_table(cards)
    for table in (runs, summary):
        kept = T.without_timing(table)
        assert not set(T.TIMING_COLUMNS) & set(kept.columns)
        assert len(kept.columns) == len(table.columns) - len(set(T.TIMING_COLUMNS) & set(table.columns))
    times = T.timing_table(summary)
    assert list(times.columns) == ["dataset", "method", "train_time_s_mean", "train_time_s_total"]
    assert times["train_time_s_total"].tolist() == [3.0, 3.0]  # 1 s + 2 s per method


def test_inner_split_never_touches_the_validation_block(data):
    inner = L.inner_split(data, 0.25, position="end")
    lo_v, hi_v = data.val.span
    for ws in (inner.train, inner.val):
        lo, hi = ws.span
        assert not L.overlaps(lo, hi, np.array([[lo_v.min(), hi_v.max()]])).any()
    # the tuning block is the end of the training windows, and no tuning-train window overlaps it
    assert inner.val.t_to.min() > inner.train.t_to.max()
    lo, hi = inner.train.span
    assert not L.overlaps(lo, hi, np.array([[inner.val.span[0].min(), inner.val.span[1].max()]])).any()
    assert len(inner.val) == pytest.approx(0.25 * (len(inner.train) + len(inner.val)), abs=len(data.train) * 0.05)
    # normalization from the tuning-train windows only
    x = inner.train.x.reshape(-1, inner.train.x.shape[-1]).astype(float)
    np.testing.assert_allclose(inner.norm.x_mean, x.mean(0),
                               rtol=1e-9, atol=1e-12)


def test_inner_split_puts_the_tuning_block_where_the_validation_block_is(data):
    import dataclasses

    for position in ("start", "middle"):
        d = dataclasses.replace(data, options={**data.options, "val_position": position})
        inner = L.inner_split(d, 0.25)
        before = (inner.train.t_to < inner.val.t_from.min()).sum()
        after = (inner.train.t_from > inner.val.t_to.max()).sum()
        assert before + after == len(inner.train)
        if position == "start":
            assert before == 0 and after > 0
        else:
            assert before > 0 and after > 0


def test_learning_rate_search_picks_the_lowest_tuning_loss(data, tmp_path):
    cfg = {**_cfg(epochs=4), "lr_search": {"grid": [0.0, 3e-3], "fraction": 0.25, "seed": 0}}
    t = T.search_learning_rates(data, ["mlp"], {**cfg, "sizes": {"mlp": {"s": {"n_recent": 5, "hidden": 16}}},
                                              "size": "s"}, out_dir=tmp_path)
    assert list(t.columns) == ["method", "lr", "tuning_rmse_m", "tuning_loss", "epochs_run", "selected"]
    assert t["selected"].sum() == 1
    # lr 0 cannot learn: the search must keep 3e-3 (lower tuning loss)
    assert t.loc[t["selected"], "lr"].item() == 3e-3
    assert t.loc[t["lr"] == 0.0, "tuning_loss"].item() > t.loc[t["lr"] == 3e-3, "tuning_loss"].item()
    chosen = T.with_selected_lr({"lr": {"mlp": 1e-3, "bgfn": 1e-3}}, t)
    assert chosen["lr"] == {"mlp": 3e-3, "bgfn": 1e-3}
    assert T.with_selected_lr({"lr": {"mlp": 1e-3}}, None) == {"lr": {"mlp": 1e-3}}
    with pytest.raises(DataError, match="grid"):
        T.search_learning_rates(data, ["mlp"], {**cfg, "lr_search": {"grid": []}})
    with pytest.raises(DataError, match="fractoin"):
        T.lr_search_options({"lr_search": {"fractoin": 0.2}})


def test_next_learning_rate_steps_past_an_edge_only():
    grid = [1e-3, 3e-3, 1e-2]
    assert T.next_learning_rate(grid, 1e-2) == pytest.approx(1e-2 * 1e-2 / 3e-3)
    assert T.next_learning_rate(grid, 1e-3) == pytest.approx(1e-3 / 3.0)
    assert T.next_learning_rate(grid, 3e-3) is None
    assert T.next_learning_rate([0.0, 1e-3], 0.0) is None          # no geometric step below 0
    assert T.next_learning_rate([1e-3], 1e-3) is None


def test_learning_rate_search_extends_past_the_grid_edge(data, tmp_path):
    # two rates far too small for 4 epochs: the larger wins, at the grid's top edge
    cfg = {**_cfg(epochs=4), "sizes": {"mlp": {"s": {"n_recent": 5, "hidden": 16}}}, "size": "s"}
    plain = T.search_learning_rates(data, ["mlp"], {**cfg, "lr_search": {"grid": [1e-5, 1e-4], "fraction": 0.25,
                                                                         "extend": 0}})
    assert plain["lr"].tolist() == [1e-5, 1e-4] and plain.loc[plain["selected"], "lr"].item() == 1e-4
    ext = T.search_learning_rates(data, ["mlp"], {**cfg, "lr_search": {"grid": [1e-5, 1e-4], "fraction": 0.25,
                                                                       "extend": 2}})
    # 1e-3 is tried because 1e-4 was best; 1e-2 only if 1e-3 beat 1e-4 in turn
    assert ext["lr"].tolist()[:3] == pytest.approx([1e-5, 1e-4, 1e-3])
    best3 = ext.loc[ext["lr"].isin([1e-5, 1e-4, 1e-3]), "tuning_loss"].idxmin()
    assert (len(ext) == 4) == (ext.loc[best3, "lr"] == pytest.approx(1e-3))
    # the first two rows are the plain search's, unchanged (same seed, same data)
    np.testing.assert_allclose(ext["tuning_loss"].to_numpy()[:2], plain["tuning_loss"].to_numpy())
    assert ext["selected"].sum() == 1
    assert ext.loc[ext["selected"], "tuning_loss"].item() == ext["tuning_loss"].min()


def test_tuned_config_reads_the_saved_search(tmp_path, monkeypatch):
    monkeypatch.setattr(lr_search, "results_dir", lambda profile, create=True: tmp_path / profile)
    cfg = {"train": {"lr": {"mlp": 1e-3}, "lr_search": {"grid": [1e-3, 1e-2]}}}
    assert T.tuned_train_config(cfg, "p", "d1") is cfg["train"]              # not run yet
    (tmp_path / "p" / "tables").mkdir(parents=True)
    (tmp_path / "p" / "tables" / T.LR_SEARCH_FILE).write_text(
        "dataset,method,lr,tuning_rmse_m,tuning_loss,epochs_run,selected\n"
        "d1,mlp,0.001,1,1,3,False\nd1,mlp,0.01,1,0.5,3,True\nd2,mlp,0.001,1,0.1,3,True\nd2,mlp,0.01,1,1,3,False\n")
    assert T.method_lr(T.tuned_train_config(cfg, "p", "d1"), "mlp") == 0.01
    assert T.method_lr(T.tuned_train_config(cfg, "p", "d2"), "mlp") == 0.001
    off = {"train": {"lr": {"mlp": 1e-3}, "lr_search": {"grid": None}}}
    assert T.method_lr(T.tuned_train_config(off, "p", "d1"), "mlp") == 0.001   # no search in the profile


# ----------------------------------------------------------------------------------------------- a profile's training
def _toy_plan(datasets=("toy",), methods=("mlp",), seeds=(0,), **train):
    tc = {"size": "s", "sizes": {"mlp": {"s": {"n_recent": 5, "hidden": 16}}, "at_lstm": {"s": {"hidden": 8}}},
          **_cfg(epochs=3), **train}
    return T.TrainingPlan("toyprofile", {"profile": "toyprofile", "description": "toy", "train": tc}, list(datasets),
                          list(methods), list(seeds), [(1060.0, 20.0)])


@pytest.fixture
def models_in_tmp(tmp_path, monkeypatch):
    """``results/<profile>/models/<dataset>/`` under ``tmp_path``."""
    from bgfn.train import checkpoints

    monkeypatch.setattr(checkpoints, "models_dir", lambda profile, dataset, fold=None, create=True:
                        tmp_path / profile / dataset)
    return tmp_path


def test_training_plan_takes_the_profile_unless_told():
    from bgfn.profile_schema import load_profile
    from bgfn.nav.outages import outage_windows

    cfg = load_profile("smoke")
    plan = T.TrainingPlan.of(cfg)
    tc = cfg["train"]
    assert (plan.datasets, plan.methods, plan.seeds) == (tc["datasets"], tc["methods"], tc["seeds"])
    assert plan.outage_windows == outage_windows(cfg) and plan.train_cfg == tc
    mine = T.TrainingPlan.of(with_overrides(cfg, {"train.datasets": ["turin-sim-mpu6000"], "train.methods": ["mlp"],
                                                  "train.seeds": [np.int64(3)]}), outage_windows=[(1.0, 2.0)])
    assert (mine.datasets, mine.methods, mine.seeds, mine.outage_windows) == (["turin-sim-mpu6000"], ["mlp"], [3],
                                                                             [(1.0, 2.0)])
    assert type(mine.seeds[0]) is int                      # the card and file name take a plain int
    text = training_words.plan_text(mine)
    assert "methods ['mlp'], seeds [3], size 'smoke'" in text and f"+- {tc['margin_s']} s" in text


def test_train_dataset_trains_every_method_and_seed_into_the_models_folder(data, models_in_tmp):
    plan = _toy_plan(methods=("mlp", "at_lstm"), seeds=(0, 1))
    lines = []
    cards = T.train_dataset(plan, "toy", data, echo=lines.append)
    assert [(c["method"], c["seed"]) for c in cards] == [("mlp", 0), ("mlp", 1), ("at_lstm", 0), ("at_lstm", 1)]
    assert all(c["dataset"] == "toy" and c["profile"] == "toyprofile" and c["size"] == "s" for c in cards)
    folder = models_in_tmp / "toyprofile" / "toy"
    assert sorted(p.name for p in folder.glob("*.pt")) == ["at_lstm_seed0.pt", "at_lstm_seed1.pt", "mlp_seed0.pt",
                                                           "mlp_seed1.pt"]
    # one progress line per finished run: which run, what it reports, the runs left
    assert [line.split(" | ")[0] for line in lines] == [f"[training toy] toy {m} seed {s}" for m, s in
                                                       [("mlp", 0), ("mlp", 1), ("at_lstm", 0), ("at_lstm", 1)]]
    assert f"val RMSE {cards[0]['val_rmse_m']:.3f} m" in lines[0] and f"{cards[0]['epochs_run']} epochs" in lines[0]
    assert [line.split(" | ")[3] for line in lines[:3]] == ["3 left", "2 left", "1 left"]
    assert lines[3].split(" | ")[-1].startswith("all 4 in ")
    # the figure of the validation block reads the same checkpoints back: the cards' validation error
    preds = T.checkpoint_predictions(folder, data.val, ["mlp", "at_lstm"], seed=1)
    assert list(preds) == ["mlp", "at_lstm"]
    for method, card in zip(("mlp", "at_lstm"), cards[1::2]):
        assert L.rmse(preds[method], data.val.y) == pytest.approx(card["val_rmse_m"], rel=1e-5)


def test_profile_search_selects_per_dataset(data, models_in_tmp):
    imu, att, gnss = L.synthetic_tables(duration_s=300.0, noise=0.05, seed=2)
    other = L.build_learning_data(imu, att, gnss, [], window=40, val_fraction=0.25)
    plan = _toy_plan(datasets=("a", "b"), lr_search={"grid": [0.0, 3e-3], "fraction": 0.25})
    table = T.search_profile_learning_rates(plan.profile, {"a": data, "b": other}, ["mlp"], plan.train_cfg)
    assert list(table.columns) == list(T.LR_SEARCH_COLUMNS)
    assert table["dataset"].tolist() == ["a", "a", "b", "b"]
    assert (models_in_tmp / "toyprofile" / "b" / "lr_search" / "lr0.003" / "mlp_seed0.json").exists()
    alone = T.search_learning_rates(data, ["mlp"], plan.train_cfg)
    np.testing.assert_allclose(table.loc[table["dataset"] == "a", "tuning_loss"], alone["tuning_loss"])
    assert table.groupby("dataset")["selected"].sum().tolist() == [1, 1]
    cfgs = T.selected_train_configs(plan.train_cfg, table, ["a", "b"])
    assert T.chosen_learning_rates(cfgs, ["mlp"]) == {"a": {"mlp": 3e-3}, "b": {"mlp": 3e-3}}   # lr 0 learns nothing
    # no grid: no search, the profile's rates for every dataset
    no_grid = _toy_plan(lr_search={"grid": None}).train_cfg
    assert T.search_profile_learning_rates(plan.profile, {"a": data}, ["mlp"], no_grid) is None
    plain = T.selected_train_configs(plan.train_cfg, None, ["a", "b"])
    assert plain == {"a": plan.train_cfg, "b": plan.train_cfg}


def test_selected_train_configs_keep_each_datasets_rates():
    search = pd.DataFrame({"dataset": ["d1", "d1", "d2", "d2"], "method": "mlp", "lr": [1e-3, 1e-2, 1e-3, 1e-2],
                           "selected": [False, True, True, False]})
    tc = {"lr": {"mlp": 5e-4, "bgfn": 2e-4}}
    cfgs = T.selected_train_configs(tc, search, ["d1", "d2"])
    assert T.chosen_learning_rates(cfgs, ["mlp", "bgfn"]) == {"d1": {"mlp": 1e-2, "bgfn": 2e-4},
                                                              "d2": {"mlp": 1e-3, "bgfn": 2e-4}}
    assert tc == {"lr": {"mlp": 5e-4, "bgfn": 2e-4}}       # the profile's section is not changed


def _toy_dataset(name, seed, gnss_rate_hz=1.0):
    imu, att, gnss = L.synthetic_tables(duration_s=200.0, noise=0.05, seed=seed)
    drive = SimpleNamespace(imu=imu, gnss=gnss, reference=att, meta={"gnss_rate_hz": gnss_rate_hz})
    data = L.build_learning_data(imu, att, gnss, [(1100.0, 10.0)], window=40, margin_s=2.0, val_fraction=0.25)
    return T.TrainingDataset(name, drive, att, data)


def test_windows_and_val_position_tables_have_one_block_per_dataset():
    prepared = {"a": _toy_dataset("a", 1), "b": _toy_dataset("b", 2, gnss_rate_hz=5.0)}
    windows = T.windows_table(prepared)
    assert list(windows.columns) == ["dataset", "gnss_rate_hz", "windows", "excluded_outages", "purged_near_val",
                                     "screened", "train", "val", "val_block_s", *L.REFERENCES.values()]
    assert windows["dataset"].tolist() == ["a", "b"] and windows["gnss_rate_hz"].tolist() == [1.0, 5.0]
    assert windows.iloc[1].drop(["dataset", "gnss_rate_hz"]).to_dict() == L.split_summary(prepared["b"].data)
    plan = _toy_plan(datasets=("a", "b"), window=40, margin_s=2.0, val_fraction=0.25)
    plan.outage_windows = [(1100.0, 10.0)]
    positions = T.val_position_tables(plan, prepared)
    assert positions.columns[0] == "dataset"
    assert positions["dataset"].tolist() == ["a"] * len(L.VAL_POSITIONS) + ["b"] * len(L.VAL_POSITIONS)
    alone = T.val_position_table(plan.cfg, prepared["b"].drive, attitude=prepared["b"].attitude,
                                 outage_windows=plan.outage_windows)
    pd.testing.assert_frame_equal(positions[positions["dataset"] == "b"].drop(columns="dataset")
                                  .reset_index(drop=True), alone)


def test_training_metrics_gather_what_training_json_holds():
    prepared = {"a": _toy_dataset("a", 1)}
    cards = [{"dataset": "a", "method": "mlp", "seed": 0, "params": 10, "epochs_run": 3, "best_epoch": 2,
              "wall_time_s": 1.5, "val_rmse_m": 0.5, "val_rmse_zero_m": 1.0, "val_rmse_last_m": 0.2}]
    runs, summary = T.cards_table(cards), T.summary_table(cards)
    plan = T.TrainingPlan.of(with_overrides(load_profile("smoke"), {"train.datasets": ["a"],
                                                                    "variant_runs.datasets": ["a"]}),
                             outage_windows=[(1100.0, 10.0)])
    m = T.training_metrics(plan, prepared, runs, summary, T.windows_table(prepared))
    assert list(m) == ["runs", "summary", "windows", "learning_options", "outage_windows", "meta"]
    assert m["runs"][0]["wall_time_s"] == 1.5                     # training.json keeps the times
    assert m["learning_options"] == {"a": prepared["a"].data.options}
    assert m["outage_windows"] == {"a": [[1100.0, 10.0]]}         # per dataset: the windows its data left out
    assert m["windows"][0]["dataset"] == "a" and m["meta"]["profile"] == "smoke"


def test_paper_training_estimate_is_epochs_times_windows_over_the_measured_rate():
    paper = {"train": {"methods": ["bgfn", "mlp"], "seeds": [0, 1, 2], "optimizer": {"epochs": 1000}}}
    bench = {"train_windows_per_s": {"bgfn": {"paper": 10.0, "quick": 99.0}, "mlp": {"paper": 400.0}}}
    table = T.paper_training_estimate({"a": 3600, "b": 1800}, paper, bench)
    t = table.set_index("method")
    # BGFN: one epoch = 3600/10 + 1800/10 = 540 s; 3 seeds x 1000 epochs = 1.62e6 s = 450 h
    assert t.loc["bgfn", "epoch_s"] == pytest.approx(540.0) and t.loc["bgfn", "hours"] == pytest.approx(450.0)
    assert t.loc["mlp", "hours"] == pytest.approx(450.0 * 10 / 400) and t.loc["bgfn", "runs"] == 6
    assert "at most 461.2 h" in training_words.estimate_lines(table)[0]
    assert T.paper_training_estimate({"a": 1}, paper, {"train_windows_per_s": {"bgfn": {"quick": 5.0}}}) is None
    assert "make bench" in training_words.estimate_lines(None)[0]


def test_speed_lines_give_the_ratio_to_the_twin_and_the_ceiling_of_the_matrix_products():
    bench = {"train_ratio_bgfn_over_twin": {"quick": 0.85, "paper": 0.25},
             "train_step_profile": {"bgfn": {"paper": {"matmul_s": 0.5, "step_s": 0.7}},
                                    "transformer": {"paper": {"matmul_s": 0.1, "step_s": 0.2}}},
             "train_ratio_ceiling": {"paper": 0.2 / 0.5}}
    lines = training_words.speed_lines(bench, {"train": {"sizes": {"bgfn": {"paper": {"time_steps": 4}}}}})
    assert lines[0] == ("BGFN's training throughput over its ANN twin's (windows/s, both measured in one run): 0.85 "
                        "at the quick size, 0.25 at the paper size")
    assert "take 0.50 s of its 0.70 s, the twin's whole step 0.20 s" in lines[1]
    assert "at most 0.40 of the twin's throughput: with T_s = 4 SNN steps" in lines[1]
    assert len(training_words.speed_lines({k: v for k, v in bench.items() if k != "train_ratio_ceiling"})) == 1   # older bench
    # without the profiler: products replayed alone, 300 of 400 ms; the twin's step over them 0.4, of which 0.25
    replay = {"paper": {"matmul_ms": 300.0, "step_ms": 400.0, "matmul_share": {"median": 0.75},
                        "ceiling": {"median": 0.4}}}
    third = training_words.speed_lines({**bench, "train_ceiling_replay": replay})[2]
    assert "take 300 ms of its 400 ms step (75 %); the ceiling they set is 0.40, of which BGFN reaches 62 %" in third
    assert training_words.speed_lines({}) == [] and training_words.speed_lines(None) == []


def test_learning_check_names_the_runs_that_never_improved_on_their_initial_network():
    def card(method, seed, best, initial=2.0):
        return {"dataset": "d", "method": method, "seed": seed, "best_epoch": best, "epochs_run": 7,
                "history": [{"epoch": 0, "val_rmse_m": initial}, {"epoch": 1, "val_rmse_m": 1.0}]}

    fitted = {**card("at_lstm", 2, 0), "history": [{"epoch": 0, "train_loss": None}, {"epoch": 1, "train_loss": 0.8},
                                                   {"epoch": 2, "train_loss": 0.456}, {"epoch": 3, "train_loss": 0.5}]}
    cards = [card("bgfn", 0, 3), card("mlp", 0, 0), card("mlp", 1, 1), fitted]
    lines = training_words.learning_check(cards)
    assert lines[0] == "2 of 4 runs improved on their initial network (best epoch >= 1)"
    assert lines[1] == "  not improved: d mlp seed 0: the initial network is kept"
    # the lowest training loss of epochs >= 1 (epoch 0 has none), against the 1.0 of predicting the mean
    assert lines[2] == ("  not improved: d at_lstm seed 2: the initial network is kept; its training loss fell to "
                        "0.46 (predicting the training mean: about 1)")
    lines = training_words.learning_check(cards[:3])
    assert lines[2].startswith("1 runs kept their first training epoch") and lines[2].endswith("d mlp seed 1")
    assert training_words.learning_check([card("bgfn", 0, 2)]) == ["1 of 1 runs improved on their initial network (best epoch >= 1)"]
    # the table carries the initial network's validation error; an older card (no epoch 0) leaves it empty
    runs = T.cards_table([card("bgfn", 0, 3, initial=4.5), {**card("mlp", 0, 2), "history": [{"epoch": 1}]}, fitted])
    assert runs["val_rmse_initial_m"].tolist()[0] == 4.5 and runs["val_rmse_initial_m"].isna().tolist()[1]
    assert runs["train_loss_min"].isna().tolist()[:2] == [True, True] and runs["train_loss_min"].tolist()[2] == 0.456


def test_runs_that_never_improved_are_trained_again_on_all_windows_only_when_the_cap_left_some_out(
        data, tmp_path, monkeypatch):
    from bgfn import config

    monkeypatch.setattr(config, "RESULTS_ROOT", tmp_path)
    n = len(data.train)
    tc = {"size": "s", "sizes": {"mlp": {"s": {"n_recent": 5, "hidden": 16}}}, "lr": {"mlp": 3e-3},
          **_cfg(epochs=2, max_train_windows=n // 4), "recheck_all_windows": True, "recheck_runs": "all"}
    prepared = {"toy": T.TrainingDataset("toy", None, None, data), "small": T.TrainingDataset("small", None, None,
                                                                                                SimpleNamespace(train=[0] * 10))}
    cfgs = {"toy": tc, "small": tc}

    def card(dataset, seed, best):
        return {"dataset": dataset, "method": "mlp", "seed": seed, "best_epoch": best, "n_train": n // 4}

    cards = [card("toy", 0, 0), card("toy", 1, 3), card("small", 0, 0)]
    # seed 1 improved; 'small' has fewer windows than the cap (it trained on all): only toy seed 0 is rechecked
    assert T.capped_runs(cards, prepared, cfgs) == [cards[0]]
    plan = SimpleNamespace(profile="p", train_cfg=tc)
    assert T.recheck_all_windows(SimpleNamespace(profile="p", train_cfg={**tc, "recheck_all_windows": False}),
                                 cards, prepared, cfgs) == []
    (pair,) = T.recheck_all_windows(plan, cards, prepared, cfgs)
    assert pair["capped"] is cards[0] and pair["all"]["n_train"] == n > n // 4     # every training window
    assert (tmp_path / "p" / "models" / "all_windows" / "toy" / "mlp_seed0.pt").exists()
    assert not (tmp_path / "p" / "models" / "toy").exists()                         # reported networks untouched
    table = T.recheck_table([pair])
    assert list(table.columns) == list(T.RECHECK_COLUMNS) and table["n_train_all"].tolist() == [n]
    lines = training_words.recheck_lines(table, tc)
    improved = int(pair["all"]["best_epoch"] >= 1)
    assert lines[0].startswith(f"trained again on all their training windows, {improved} of 1 runs")
    assert lines[1] == f"  toy mlp seed 0: {n // 4} -> {n} windows, best epoch 0 -> {pair['all']['best_epoch']}"
    assert training_words.recheck_lines(table.iloc[:0], tc)[0].startswith("no run to recheck")
    off = {"recheck_all_windows": False}
    assert training_words.recheck_lines(table, off)[0] == "not rechecked (train.recheck_all_windows is false)"


def test_recheck_runs_first_keeps_the_lowest_seed_of_each_dataset_and_method():
    def card(dataset, method, seed):
        return {"dataset": dataset, "method": method, "seed": seed, "best_epoch": 0}

    cards = [card("a", "mlp", 2), card("a", "mlp", 1), card("a", "bgfn", 1), card("b", "mlp", 0), card("a", "mlp", 0)]
    # a/mlp: seed 0 (the last card), a/bgfn: its only run, b/mlp: its only run; in the cards' order
    assert T.first_per_method(cards) == [cards[2], cards[3], cards[4]]
    lines = training_words.recheck_lines(pd.DataFrame({"dataset": ["a"], "method": ["mlp"], "seed": [0], "n_train": [10],
                                          "n_train_all": [40], "best_epoch": [0], "best_epoch_all": [2],
                                          "train_loss_min_all": [0.5]}), {"recheck_all_windows": True,
                                                                          "recheck_runs": "first"})
    assert "the first of each dataset and method" in lines[0] and lines[0].startswith(
        "trained again on all their training windows, 1 of 1 runs")
