"""Input and protocol variants: the honest and leaky protocols of bgfn.learning.split, the
variants of a profile (bgfn.train.variants) merged and schema-checked like profiles, their outage table
(bgfn.studies.outage_sweep.variant_outages), and the learning-rate search's budget (bgfn.train.lr_search)."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
import torch
import yaml

from bgfn import config
from bgfn import evaluate as ev, studies
from bgfn import learning as L
from bgfn import train as T
from bgfn.errors import DataError
from bgfn.config import MAIN_VARIANT, variant_config
from bgfn.profile_schema import load_profile, with_overrides
from bgfn.report import training_words

torch.set_num_threads(1)

OUTAGES = [(1080.0, 30.0), (1150.0, 10.0)]
MARGIN_S = 5.0


@pytest.fixture(scope="module")
def tables():
    return L.synthetic_tables(duration_s=240.0, noise=0.1, seed=3)


def _split(tables, protocol):
    imu, att, gnss = tables
    return L.build_learning_data(imu, att, gnss, OUTAGES, window=100, margin_s=MARGIN_S, val_fraction=0.25,
                                 val_position="start", protocol=protocol)


def _touches(ws, intervals) -> np.ndarray:
    """Boolean per window: its input span or target interval meets one of ``intervals`` (closed)."""
    lo, hi = ws.span
    return np.array([any(a <= h and l <= b for a, b in intervals) for l, h in zip(lo, hi)], dtype=bool)


# ----------------------------------------------------------------------------------------------- protocols
def test_merged_spans_is_the_union_of_the_spans():
    lo, hi = np.array([5.0, 0.0, 1.0, 9.0]), np.array([6.0, 2.0, 3.0, 9.5])
    np.testing.assert_array_equal(L.merged_spans(lo, hi), [[0.0, 3.0], [5.0, 6.0], [9.0, 9.5]])
    assert L.merged_spans(np.array([]), np.array([])).shape == (0, 2)


def test_honest_keeps_the_outages_and_their_margin_out_of_training(tables):
    data = _split(tables, "honest")
    widened = [(s - MARGIN_S, s + d + MARGIN_S) for s, d in OUTAGES]
    assert not _touches(data.train, widened).any() and not _touches(data.val, widened).any()
    assert data.info["n_outage_excluded"] > 0 and data.info["n_outage_in_train"] == 0
    assert data.info["protocol"] == "honest" and data.options["protocol"] == "honest"


def test_leaky_trains_on_the_test_outages_and_validates_where_honest_does(tables):
    honest, leaky = _split(tables, "honest"), _split(tables, "leaky")
    # the same validation windows: only the training set differs
    np.testing.assert_array_equal(leaky.val.t_to, honest.val.t_to)
    np.testing.assert_array_equal(leaky.val.x, honest.val.x)
    # every honest training window is a leaky one; the extra ones are exactly those touching outage +- margin
    assert set(honest.train.t_to) < set(leaky.train.t_to)
    extra = ~np.isin(leaky.train.t_to, honest.train.t_to)
    widened = [(s - MARGIN_S, s + d + MARGIN_S) for s, d in OUTAGES]
    np.testing.assert_array_equal(extra, _touches(leaky.train, widened))
    # each outage's own windows (target interval inside the outage) train, all of them
    every = L.make_windows(*tables, window=100)
    for s, d in OUTAGES:
        inside = every.t_to[(every.t_from >= s) & (every.t_to <= s + d)]
        assert len(inside) >= d - 1 and np.isin(inside, leaky.train.t_to).all()
        assert not np.isin(inside, honest.train.t_to).any()
    assert leaky.info["n_outage_excluded"] == 0
    assert leaky.info["n_outage_in_train"] == int(extra.sum()) > 0
    with pytest.raises(DataError, match="protocol"):
        _split(tables, "paper")
    # a validation block whose two parts lie either side of an outage: the outage still trains when leaky
    imu, att, gnss = tables
    one = [(1100.0, 20.0)]
    split = {p: L.build_learning_data(imu, att, gnss, one, window=100, margin_s=MARGIN_S, val_fraction=0.25,
                                      val_position="middle", protocol=p) for p in L.PROTOCOLS}
    lo, hi = split["honest"].info["val_block"]
    assert lo < 1100.0 and hi > 1120.0                                  # the block's hull spans the outage
    np.testing.assert_array_equal(split["leaky"].val.t_to, split["honest"].val.t_to)
    inside = every.t_to[(every.t_from >= 1100.0) & (every.t_to <= 1120.0)]
    assert np.isin(inside, split["leaky"].train.t_to).all()
    vlo, vhi = split["leaky"].val.span
    assert not _touches(split["leaky"].train, list(zip(vlo, vhi))).any()   # no time shared with validation


# ----------------------------------------------------------------------------------------------- profile keys
def test_variants_merge_into_the_profile_as_profiles_merge(params):
    (params / "mine.yaml").write_text(
        "profile: mine\nbase: smoke\ndescription: v\n"
        "variants: {wide: {train: {optimizer: {epochs: 7}, sizes: {mlp: {smoke: {hidden: 8}}}}}}\n")
    cfg = load_profile("mine")
    merged = variant_config(cfg, "wide")
    # key by key, as a base: chain: the variant's keys replace, everything it does not name is the profile's
    assert merged["train"]["optimizer"] == {**cfg["train"]["optimizer"], "epochs": 7}
    assert merged["train"]["sizes"]["mlp"]["smoke"] == {**cfg["train"]["sizes"]["mlp"]["smoke"], "hidden": 8}
    assert merged["train"]["sizes"]["bgfn"] == cfg["train"]["sizes"]["bgfn"]
    assert merged == config.merge_sections({k: v for k, v in cfg.items() if k not in ("variants", "variant_runs")},
                                           cfg["variants"]["wide"])
    assert "variants" not in merged and set(cfg["variants"]) == {"velocity", "leaky", "velocity-leaky", "wide"}
    # the training section a dataset trains with: the selected rate stays unless the variant sets one
    tuned = {**cfg["train"], "lr": {"mlp": 0.02}}
    assert T.variant_train_section(tuned, cfg["variants"]["wide"])["lr"] == {"mlp": 0.02}


def test_the_velocity_variant_is_quick_headings_learning_problem():
    own = yaml.safe_load((config.PARAMS_DIR / "quick-heading.yaml").read_text())["train"]
    for profile in config.PROFILES:
        cfg = load_profile(profile)
        assert cfg["variants"]["velocity"]["train"] == own, profile
        assert cfg["variants"]["velocity-leaky"]["train"] == {**own, "protocol": "leaky"}, profile
        assert cfg["variants"]["leaky"]["train"] == {"protocol": "leaky"}, profile
    quick = load_profile("quick")
    heading = load_profile("quick-heading")
    assert variant_config(quick, "velocity")["train"] == {k: v for k, v in heading["train"].items()}


def test_variant_plan_takes_variant_runs_and_describes_each_variant():
    plan = T.TrainingPlan.of(with_overrides(load_profile("quick"), {"train.methods": ["mlp", "bgfn"]}))
    vplan = T.VariantPlan.of(plan)
    assert vplan.names == ["velocity", "leaky", "velocity-leaky"]
    # variant_runs' own order (quick: bgfn, at_lstm, mlp), cut to the plan's methods; quick's drive list: the real one
    assert vplan.methods == ["bgfn", "mlp"] and vplan.seeds == [0] and vplan.datasets == ["rtklib-drive0708"]
    full = T.VariantPlan.of(T.TrainingPlan.of(load_profile("full")))        # null: every drive trained
    assert full.datasets == T.TrainingPlan.of(load_profile("full")).datasets and len(full.datasets) == 3
    # variant_runs' own lists are cut to what notebook 03 trains (its parameters may narrow train:)
    smoke = T.VariantPlan.of(T.TrainingPlan.of(with_overrides(load_profile("smoke"), {"train.methods": ["mlp", "at_lstm"]})))
    assert (smoke.methods, smoke.datasets) == (["mlp"], ["turin-sim-mpu6000"])
    assert T.variant_options(vplan.train_section(MAIN_VARIANT)) == {"inputs": "eq21", "protocol": "honest"}
    velocity = "eq21+v_along+v_cross; yaw relative; heading frame"
    assert T.variant_options(vplan.train_section("velocity-leaky")) == {"inputs": velocity, "protocol": "leaky"}
    folder = vplan.models_dir("leaky", "turin-sim-mpu6000", create=False)
    assert folder.parts[-4:] == ("models", "variants", "leaky", "turin-sim-mpu6000")
    assert vplan.models_dir(MAIN_VARIANT, "turin-sim-mpu6000", create=False).parts[-2:] == ("models",
                                                                                            "turin-sim-mpu6000")
    assert f"velocity-leaky: inputs {velocity}, protocol leaky" in training_words.variants_text(vplan)


# ----------------------------------------------------------------------------------------------- outage table
class _Fixed:
    """Fake network: a constant increment along north; its options are those of the Eq. (eq21) inputs."""

    def __init__(self, dn: float):
        self.options = {"window": 20, "alignment": "ending", "yaw_encoding": "unwrap", "extra_channels": [],
                        "target_frame": "ned"}
        self.dn = dn

    def predict_windows(self, ws):
        return np.column_stack([np.full(len(ws), self.dn), np.zeros(len(ws))])


def test_variant_table_counts_the_networks_of_every_cell(tmp_path, monkeypatch):
    from test_evaluate import NAV, WINDOWS, _drive

    monkeypatch.setattr(config, "RESULTS_ROOT", tmp_path)
    cfg = {"profile": "toy", "outage_windows": [list(w) for w in WINDOWS], "nav": NAV, "evaluate": {},
           "train": {"protocol": "honest"},
           "variants": {"leaky": {"train": {"protocol": "leaky"}}}}
    vplan = T.VariantPlan("toy", cfg, cfg["variants"], ["turin-sim-ekinox"], ["mlp", "bgfn"], [0, 1, 2],
                          [tuple(w) for w in WINDOWS])
    seen = []

    def loader(path):
        seen.append(path.relative_to(tmp_path).as_posix())
        return _Fixed(dn=1.0 + 0.1 * len(seen))

    per_run = studies.outage_sweep.variant_runs(vplan, drives={"turin-sim-ekinox": _drive(5.0)}, loader=loader)
    table = studies.outage_sweep.variant_table(per_run)
    assert list(table.columns) == list(studies.outage_sweep.VARIANT_COLUMNS)
    # the main networks are notebook 03's, the variant's under models/variants/<variant>/<dataset>/
    assert "toy/models/turin-sim-ekinox/mlp_seed2.pt" in seen
    assert "toy/models/variants/leaky/turin-sim-ekinox/bgfn_seed0.pt" in seen and len(seen) == 2 * 2 * 3
    nets = table[table["variant"] != studies.outage_sweep.NO_VARIANT]
    assert len(nets) == 2 * 2 * 2 and (nets["n_runs"] == 3).all()          # 2 outages x 2 variants x 2 methods
    ins = table[table["variant"] == studies.outage_sweep.NO_VARIANT]
    assert ins["method"].tolist() == ["INS", "INS"] and (ins["n_runs"] == 0).all()
    # a cell is the median over its networks: recomputed from the runs
    cell = per_run[(per_run["variant"] == "leaky") & (per_run["method"] == "BGFN") & (per_run["outage"] == 2)]
    row = nets[(nets["variant"] == "leaky") & (nets["method"] == "BGFN") & (nets["outage"] == 2)]
    assert len(cell) == 3 and row["max_h_m"].item() == pytest.approx(np.median(cell["max_h_m"]))
    assert row[["inputs", "protocol", "test"]].values.tolist() == [["eq21", "leaky", "dataset"]]
    # fewer networks in a cell: n_runs follows
    fewer = studies.outage_sweep.variant_table(per_run[~((per_run["variant"] == "leaky") & (per_run["seed"] == 2))])
    assert fewer.loc[fewer["variant"] == "leaky", "n_runs"].eq(2).all()
    assert fewer.loc[fewer["variant"] == MAIN_VARIANT, "n_runs"].eq(3).all()
    wide = studies.outage_sweep.variant_pivot(table)
    assert list(wide.columns) == [MAIN_VARIANT, "leaky", "INS"] and len(wide) == 4
    with pytest.raises(DataError, match="checkpoint"):
        studies.outage_sweep.variant_runs(vplan, drives={"turin-sim-ekinox": _drive(5.0)})     # nothing trained in tmp_path


def test_train_variants_stores_networks_apart_with_the_main_learning_rate(tmp_path, monkeypatch):
    monkeypatch.setattr(config, "RESULTS_ROOT", tmp_path)
    imu, att, gnss = L.synthetic_tables(duration_s=200.0, noise=0.05, seed=1)
    drive = T.TrainingDataset("toy", SimpleNamespace(imu=imu, gnss=gnss), att, None)
    tc = {"window": 40, "margin_s": 2.0, "val_fraction": 0.25, "val_position": "end", "size": "s",
          "sizes": {"mlp": {"s": {"n_recent": 5, "hidden": 16}}},
          "optimizer": {"epochs": 2, "batch_size": 16, "patience": 5}, "lr": {"mlp": 1e-3}}
    cfg = {"profile": "toy", "train": tc, "variants": {"leaky": {"train": {"protocol": "leaky"}}}}
    vplan = T.VariantPlan("toy", cfg, cfg["variants"], ["toy"], ["mlp"], [0], [(1100.0, 20.0)])
    cards = T.train_variants(vplan, {"toy": drive}, {"toy": {**tc, "lr": {"mlp": 4e-3}}})
    (card,) = cards
    assert card["lr"] == 4e-3 and card["lr_from"] == "main search"          # the selected rate, not train.lr
    assert (card["variant"], card["inputs"], card["protocol"]) == ("leaky", "eq21", "leaky")
    assert (tmp_path / "toy" / "models" / "variants" / "leaky" / "toy" / "mlp_seed0.pt").exists()
    assert card["split"]["n_outage_in_train"] > 0
    runs = T.variant_cards_table(cards)
    assert runs[["variant", "inputs", "protocol", "n_outage_in_train"]].values.tolist() == [
        ["leaky", "eq21", "leaky", card["split"]["n_outage_in_train"]]]


# ----------------------------------------------------------------------------------------------- search budget
@pytest.fixture(scope="module")
def data():
    imu, att, gnss = L.synthetic_tables(duration_s=300.0, noise=0.05, seed=1)
    return L.build_learning_data(imu, att, gnss, [(1060.0, 20.0)], window=40, margin_s=2.0, val_fraction=0.25,
                                 val_position="end")


def test_search_budget_caps_epochs_and_patience_for_every_method():
    tc = {"optimizer": {"epochs": 25, "patience": 6, "lr": 1e-3}, "lr_search": {"grid": [1e-3], "epochs": 15,
                                                                               "patience": 4}}
    capped = T.search_train_config(tc)
    assert capped["optimizer"] == {"epochs": 15, "patience": 4, "lr": 1e-3}
    assert tc["optimizer"]["epochs"] == 25                                 # not modified
    # the window caps of a tuning run replace the optimizer's (quick: 250 and 200 against 1000 and 400 for the reported
    # networks); a cap the search leaves unset stays the optimizer's
    opt = {**tc["optimizer"], "max_train_windows": 1000, "max_val_windows": 400}
    few = T.search_train_config({**tc, "optimizer": opt,
                                 "lr_search": {**tc["lr_search"], "max_train_windows": 250, "max_val_windows": 200}})
    assert few["optimizer"]["max_train_windows"] == 250 and few["optimizer"]["max_val_windows"] == 200
    assert few["optimizer"]["epochs"] == 15
    some = T.search_train_config({**tc, "optimizer": opt, "lr_search": {**tc["lr_search"], "max_train_windows": 250}})
    assert some["optimizer"]["max_val_windows"] == 400
    assert T.search_train_config({**tc, "lr_search": {"grid": [1e-3]}}) == {**tc, "lr_search": {"grid": [1e-3]}}


def test_a_capped_search_is_the_prefix_of_the_full_budget(data):
    sizes = {"sizes": {"mlp": {"s": {"n_recent": 5, "hidden": 16}}}, "size": "s"}
    opt = {"optimizer": {"epochs": 6, "batch_size": 16, "lr": 3e-3, "patience": 50, "schedule": "none"}}
    grid = {"grid": [1e-3, 1e-2], "fraction": 0.25, "extend": 0}
    capped = T.search_learning_rates(data, ["mlp"], {**opt, **sizes, "lr_search": {**grid, "epochs": 3}})
    assert capped["epochs_run"].tolist() == [3, 3] and capped["selected"].sum() == 1
    # same seed, same tuning split: a capped tuning run is the first epochs of the full one, so its tuning loss
    # is the best validation loss of those epochs of the full run (history[0]: the initial network)
    inner = L.inner_split(data, 0.25)
    for lr, loss in zip(capped["lr"], capped["tuning_loss"]):
        card = T.train_model("mlp", inner, sizes["sizes"]["mlp"]["s"], {**opt, "lr": {"mlp": lr}}, seed=0,
                             progress=False)
        assert card["epochs_run"] == 6
        assert loss == pytest.approx(min(h["val_loss"] for h in card["history"][:4]), rel=1e-6)


def test_the_command_line_trains_the_variants_only_when_asked(monkeypatch, tmp_path):
    import bgfn.train.runs as R
    from bgfn.__main__ import main

    monkeypatch.setattr(config, "RESULTS_ROOT", tmp_path)                  # no search ran: train.lr
    monkeypatch.setattr(R, "prepare_datasets", lambda plan: {d: T.TrainingDataset(d, None, None, f"data {d}")
                                                             for d in plan.datasets})
    monkeypatch.setattr(R, "train_datasets", lambda plan, learning, cfgs, *a, **kw: [
        {"dataset": d, "data": data} for d, data in learning.items()])
    calls = []
    monkeypatch.setattr(R, "train_variants", lambda vplan, prepared, cfgs, **kw: calls.append(
        (vplan.names, vplan.datasets, sorted(prepared), sorted(cfgs))) or [])
    assert main(["train", "--profile", "smoke", "--dataset", "turin-sim-mpu6000"]) == 0
    assert calls == []
    main(["train", "--profile", "smoke", "--dataset", "turin-sim-mpu6000", "--variants"])
    smoke = load_profile("smoke")
    assert calls == [(list(smoke["variants"]), ["turin-sim-mpu6000"], ["turin-sim-mpu6000"], ["turin-sim-mpu6000"])]
