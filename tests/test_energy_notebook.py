"""What notebook 05 calls (bgfn.energy): totals and tables checked by hand, the windows measured, the
checkpoints loaded, the SpikingJelly comparison, the speed table and energy.json."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest
import torch

from bgfn import energy
from bgfn.config import PROJECT_ROOT
from bgfn.studies.odometer.energy import OdometerEnergy, odometer_dataset
from bgfn.report import energy_words
from bgfn.report.odometer_words import odometer_energy_lines
from bgfn.energy.record import REPORTED_KEYS
from bgfn.learning import WindowSet
from bgfn.models import build_model
from bgfn.train import TrainedModel

torch.set_num_threads(1)

TINY = dict(dim=8, ffn_dim=8, depth=2, heads=2, time_steps=2, kernel_size=3)
E_MAC, E_AC = 2.0, 1.0                       # pJ: round numbers for the hand sums below


def _hand_counts():
    """BGFN: encoder 100 MACs, Q 200 dense at rate 0.1 (20 SOPs), SSA 80 dense (20 SOPs), head 10 MACs.
    Twin: encoder 100 MACs, attention 400 MACs, head 50 MACs."""
    LC = energy.LayerCount
    snn = [LC("spike_encoder.conv", "conv", False, 1, 100.0, 1.0, 100.0, 0.0),
           LC("blocks.0.attn.q.linear", "linear", True, 2, 200.0, 0.1, 0.0, 20.0, trains=1),
           LC("blocks.0.attn.qkv_matmul", "ssa", True, 2, 80.0, 0.25, 0.0, 20.0),
           LC("head", "linear", False, 1, 10.0, 1.0, 10.0, 0.0)]
    ann = [LC("conv", "conv", False, 1, 100.0, 1.0, 100.0, 0.0),
           LC("blocks.0.attention", "attention", False, 1, 400.0, 1.0, 400.0, 0.0),
           LC("head", "linear", False, 1, 50.0, 1.0, 50.0, 0.0)]
    return snn, ann


def _hand_tables():
    snn, ann = _hand_counts()
    return snn, {"bgfn": energy.table_from_counts(snn, "bgfn", E_MAC, E_AC),
                 "transformer": energy.table_from_counts(ann, "transformer", E_MAC, E_AC)}


# ----------------------------------------------------------------------------------------------- totals
def test_energy_totals_by_hand():
    snn, tables = _hand_tables()
    t = energy.energy_totals(tables, snn, E_MAC)
    # BGFN: 2 * 100 + 20 + 20 + 2 * 10 = 260 pJ; twin: 2 * (100 + 400 + 50) = 1100 pJ
    assert t.bgfn_uj == pytest.approx(260e-6) and t.twin_uj == pytest.approx(1100e-6)
    assert t.reduction_pct == pytest.approx(100 * (1 - 260 / 1100))
    assert (t.macs, t.sops) == (110.0, 40.0)
    assert t.mac_share == pytest.approx(220 / 260)
    assert t.mean_rate == pytest.approx(40 / (200 + 80))          # SOPs / dense ops of the spike-driven layers
    # attention products: BGFN's SSA 20 pJ, the twin's 800 pJ; without them 240 pJ against 300 pJ
    assert t.attention_uj == pytest.approx({"bgfn": 20e-6, "transformer": 800e-6})
    assert t.reduction_without_attention_pct == pytest.approx(20.0)
    frame = t.frame(66.3)
    assert frame.loc["energy reduction vs Transformer (%)"].tolist() == pytest.approx([t.reduction_pct, 66.3])
    assert frame["paper"].isna().sum() == 3                        # the paper gives only the reduction
    lines = energy_words.totals_lines(t, 64)
    assert "110 MACs + 40 SOPs" in lines[0] and "84.6 %" in lines[0]
    assert "72.7 % of the twin's" in lines[1] and "7.7 % of BGFN's" in lines[1]
    # one trained network measured: each line says so (its windows enough, its seed alone)
    assert all(ln.endswith(" (one seed, 64 windows: no spread between training seeds)") for ln in lines)
    assert lines[1].endswith("20.0 % (one seed, 64 windows: no spread between training seeds)")
    assert energy_words.totals_lines(t, 3)[1].endswith("20.0 % (one seed, 3 windows: no statistics)")
    assert energy_words.totals_lines(t, 64, n_seeds=3)[1].endswith("20.0 %")          # enough of both: nothing


def test_stacked_tables_are_checked_and_show_the_input_trains():
    snn, tables = _hand_tables()
    table = energy.stack_tables(tables)
    assert list(table["model"]) == ["bgfn"] * 5 + ["transformer"] * 4           # layers and a total each
    snn[1].trains = 3
    shown = energy.with_input_trains(table, snn)
    assert shown["input_trains"].tolist() == [1, 3, 1, 1, 1] + [1] * 4
    bad = dict(tables, bgfn=tables["bgfn"].assign(firing_rate=[1.0, 1.2, 0.25, 1.0, 0.5]))
    with pytest.raises(ValueError, match="outside"):
        energy.stack_tables(bad)
    with pytest.raises(ValueError, match="columns"):
        energy.stack_tables({"bgfn": tables["bgfn"].rename(columns={"sops": "synops"})})


def test_break_even_note_says_which_side():
    assert "stays cheaper at any firing rate" in energy_words.break_even_note(3.99)
    assert "costs more than the twin above it" in energy_words.break_even_note(0.4)


# ----------------------------------------------------------------------------------------------- which windows
def test_window_indices_are_the_even_subsample_or_all():
    assert energy.window_indices(10, 4).tolist() == [0, 3, 6, 9]
    assert energy.window_indices(10, None).tolist() == list(range(10))
    assert energy.window_indices(10, 0).tolist() == list(range(10))     # 0 / null: all windows
    assert energy.window_indices(3, 32).tolist() == [0, 1, 2]


def test_same_size_builder_changes_only_the_time_steps():
    build = energy.same_size_builder({"bgfn": TINY, "transformer": TINY}, in_channels=9)
    snn, ann = build(8)
    assert snn.spike_encoder.time_steps == 8 and ann.conv.out_channels == 9 * 8
    assert len(snn.blocks) == TINY["depth"] and ann.embed.out_features == TINY["dim"]
    again, _ = build(8)                                              # seeded: the same untrained weights
    torch.testing.assert_close(again.state_dict(), snn.state_dict())


# ----------------------------------------------------------------------------------------------- which networks
def _measured_checkpoints(tmp_path, monkeypatch, dataset: str, seed: int):
    """Empty checkpoints of BGFN and its twin under ``results/smoke/models/<dataset>/`` (tmp), each loaded as a
    tiny network with T_s = 3; the folder, for the test's cards."""
    from bgfn import config
    from bgfn.energy import checkpoint

    monkeypatch.setattr(config, "RESULTS_ROOT", tmp_path)
    monkeypatch.setattr(checkpoint, "load_trained",
                        lambda p, device=None: TrainedModel("x", build_model("mlp", {"hidden": 4}), None, {},
                                                            {**TINY, "time_steps": 3}))
    folder = tmp_path / "smoke" / "models" / dataset
    folder.mkdir(parents=True)
    for m in energy.MEASURED:
        (folder / f"{m}_seed{seed}.pt").write_bytes(b"")
    return folder


def test_load_measured_reads_dataset_seed_and_cards(tmp_path, monkeypatch):
    cfg = {"energy": {"dataset": "drive-b", "seed": 2, "allow_untrained": False},
           "train": {"datasets": ["drive-a"], "seeds": [0]}}
    folder = _measured_checkpoints(tmp_path, monkeypatch, "drive-b", 2)
    (folder / "bgfn_seed2.json").write_text(json.dumps({"best_epoch": 7, "val_rmse_m": 1.25}))
    measured = energy.load_measured("smoke", cfg)
    assert (measured.dataset, measured.seed, measured.time_steps) == ("drive-b", 2, 3)
    assert measured.cards == {"bgfn": {"best_epoch": 7, "val_rmse_m": 1.25}, "transformer": {}}
    assert "best epoch 7, val RMSE 1.250 m" in energy_words.measured_lines(measured)[0] and "val RMSE nan m" in energy_words.measured_lines(measured)[1]
    assert measured.relative_paths()["bgfn"] == str(folder / "bgfn_seed2.pt")   # outside the project: absolute


# ----------------------------------------------------------------------------------------------- cross-check
def test_comparison_with_spikingjelly_agrees_on_tiny_models():
    torch.manual_seed(0)
    models = {"bgfn": build_model("bgfn", {**TINY, "v_threshold": 0.3, "attn_threshold": 0.2}),
              "transformer": build_model("transformer", TINY)}
    x = torch.randn(3, 6, 9, generator=torch.Generator().manual_seed(1))
    cross = energy.compare_with_spikingjelly(models, {"bgfn": x, "transformer": x}, n_windows=2)
    t = cross.table
    assert t.index.tolist() == ["bgfn", "transformer"] and (t["windows"] == 2).all()
    assert t.loc["transformer", "difference (%)"] == pytest.approx(0.0, abs=1e-9)   # the same matmuls as MACs
    assert t.loc["bgfn", "MACs (ours)"] == pytest.approx(t.loc["bgfn", "MACs (SJ)"])
    # with the exact (nonzero-product) SSA term our count is SpikingJelly's
    assert t.loc["bgfn", "difference, exact SSA count (%)"] == pytest.approx(0.0, abs=1e-9)
    assert cross.worst_pct == pytest.approx(t["difference (%)"].abs().max())
    # SpikingJelly's default rules: the integer residual inputs become MACs, so BGFN costs more
    assert cross.strict_uj["bgfn"] > t.loc["bgfn", "energy SJ (µJ)"]
    assert cross.strict_uj["transformer"] == pytest.approx(t.loc["transformer", "energy SJ (µJ)"])
    assert cross.strict_reduction_pct == pytest.approx(
        100 * (1 - cross.strict_uj["bgfn"] / cross.strict_uj["transformer"]))
    assert energy_words.crosscheck_lines(cross, 5.0)[0] == f"agreement within {cross.worst_pct:.2f} % (tolerance 5.0 %)"


# ----------------------------------------------------------------------------------------------- speed table
def test_speed_table_falls_back_to_bench_speed_latency():
    bench = {"infer_ms": {"bgfn": {"quick": 1.5}},
             "throughput_windows_per_s": {"bgfn": {"quick": 1000.0}},
             "speed_bench": {"latency_ms": {"mlp": {"paper": 0.2}, "bgfn": {"quick": 9.0}}, "threads": 1}}
    t = energy.speed_table(bench)
    assert t[["model", "size"]].values.tolist() == [["bgfn", "quick"], ["mlp", "paper"]]
    assert t["latency (ms, batch 1)"].tolist() == [1.5, 0.2]      # infer_ms first, bench_speed's latency else
    assert t.loc[0, "throughput (windows/s, batch 64)"] == 1000.0 and pd.isna(t.loc[1, "keeps up with 100 Hz IMU"])
    notes = energy_words.speed_notes(bench)
    assert notes[0] == "recorded with: {'threads': 1}"
    assert notes[1].startswith("missing in results/bench.json: realtime_imu_100hz, realtime_gnss_1hz")
    assert energy.speed_table({}).empty
    assert "`make bench` produces them" in energy_words.speed_notes({})[0]


# ----------------------------------------------------------------------------------------------- energy.json
def test_energy_summary_has_what_the_results_page_reads():
    snn, tables = _hand_tables()
    totals = energy.energy_totals(tables, snn, E_MAC)
    folder = PROJECT_ROOT / "results" / "smoke" / "models" / "d"
    measured = energy.MeasuredModels(
        "smoke", "d", 1, {m: folder / f"{m}_seed1.pt" for m in energy.MEASURED},
        {m: TrainedModel(m, None, None, {}, {"time_steps": 4}) for m in energy.MEASURED},
        {"bgfn": {"best_epoch": 3}, "transformer": {}})
    m = np.zeros(5)
    ws = WindowSet(np.zeros((5, 7, 9)), np.zeros((5, 2)), m, m, m, m, np.zeros((5, 2)), m)   # 5 windows [7, 9]
    windows = energy.EvaluationWindows(ws.subset([0, 2, 4]), {}, 5)
    cross = energy.Crosscheck(pd.DataFrame({"model": ["bgfn"], "difference (%)": [0.5]}).set_index("model"),
                              0.5, {"bgfn": 1.0, "transformer": 2.0}, 50.0)
    sweep_t = pd.DataFrame({"time_steps": [1, 2], "reduction_pct": [90.0, 80.0]})
    s = energy.energy_summary(measured, windows, tables, totals, 66.3, {"lif": 0.1}, sweep_t, 3.5, cross, 5.0,
                              E_MAC, E_AC, {"profile": "smoke"})
    assert set(REPORTED_KEYS) <= set(s)
    assert s["checkpoints"] == {m: f"results/smoke/models/d/{m}_seed1.pt" for m in energy.MEASURED}
    assert s["windows"]["n_windows"] == 3 and s["windows"]["n_validation_windows"] == 5
    assert (s["time_steps"], s["seed"], s["checkpoint_epochs"]) == (4, 1, {"bgfn": 3, "transformer": None})
    assert s["macs"] == {"bgfn": 110.0, "transformer": 550.0} and s["sops"] == {"bgfn": 40.0, "transformer": 0.0}
    assert s["reduction_pct"] == totals.reduction_pct and s["reduction_pct_without_attention"] == pytest.approx(20.0)
    json.dumps(s)                                                  # writable as JSON
    md = energy_words.result_markdown(s)
    assert md.startswith("**Result (smoke profile, d, seed 1; one seed, 3 windows: no statistics):** ")
    assert "BGFN 0.00026 µJ vs Transformer twin 0.0011 µJ" in md and "**76.4 % less energy** (paper: 66.3 %)" in md
    assert "takes 73 % of its energy" in md and "the reduction is 20.0 %" in md and md.endswith("it is 50.0 %.")
    assert s["improved"] == {"bgfn": True, "transformer": True}                  # the twin's card says nothing
    # a BGFN that never trained (best epoch 0, let through by energy.allow_untrained): no saving is claimed
    measured.cards["bgfn"] = {"best_epoch": 0}
    s = energy.energy_summary(measured, windows, tables, totals, 66.3, {"lif": 0.1}, sweep_t, 3.5, cross, 5.0,
                              E_MAC, E_AC, {"profile": "smoke"})
    assert s["improved"]["bgfn"] is False
    md = energy_words.result_markdown(s)
    assert "BGFN did not train" in md and "no energy saving against the Transformer twin is claimed" in md
    assert "less energy**" not in md and "76.4" not in md


def test_the_energy_network_is_the_median_seed_and_must_be_trained(tmp_path, monkeypatch):
    import json

    from bgfn import config
    from bgfn.train.checkpoints import card_path, checkpoint_path
    from bgfn.energy.checkpoint import check_trained, energy_checkpoint, median_seed
    from bgfn.errors import DataError

    monkeypatch.setattr(config, "RESULTS_ROOT", tmp_path)
    for seed, rmse, best in ((0, 3.0, 4), (1, 1.0, 1), (2, 2.0, 2), (3, 9.0, 3), (4, 1.5, 0), (5, 0.5, 0)):
        pt = checkpoint_path("p", "d", "bgfn", seed)
        pt.write_bytes(b"")
        card_path(pt).write_text(json.dumps({"val_rmse_m": rmse, "best_epoch": best}))
    assert median_seed("p", "d", [0, 1, 2]) == 2                 # 1.0 < 2.0 < 3.0: the median is seed 2
    assert median_seed("p", "d", [0, 1, 2, 3]) == 2             # even count: the lower median
    assert median_seed("p", "d", [7]) == 7                      # no card yet: the first seed
    # seeds 4 and 5 never improved on their initial network: the median is taken among the others
    assert median_seed("p", "d", [0, 1, 2, 4, 5]) == 2
    assert median_seed("p", "d", [4, 5, 7]) == 5                # none trained: all cards (then refused)
    cfg = {"energy": {"dataset": None, "seed": None, "allow_untrained": False},
           "train": {"datasets": ["d"], "seeds": [0, 1, 2]}}
    assert energy_checkpoint("p", "bgfn", cfg).name == "bgfn_seed2.pt"
    assert energy_checkpoint("p", "bgfn", {**cfg, "energy": {"seed": 0}}).name == "bgfn_seed0.pt"
    # the dataset: the first of train.datasets where some seed's BGFN learned ('u' has only an untrained one)
    from bgfn.energy.checkpoint import energy_dataset

    pt = checkpoint_path("p", "u", "bgfn", 0)
    pt.write_bytes(b"")
    card_path(pt).write_text(json.dumps({"val_rmse_m": 1.0, "best_epoch": 0}))
    assert energy_dataset("p", {"datasets": ["u", "d"], "seeds": [0, 1]}) == "d"
    assert energy_dataset("p", {"datasets": ["u"], "seeds": [0]}) == "u"      # none learned: the first (refused)
    assert energy_dataset("p", {"datasets": []}) is None
    both = {**cfg, "train": {"datasets": ["u", "d"], "seeds": [0, 1, 2]}}
    assert energy_checkpoint("p", "bgfn", both).parent.name == "d"
    with pytest.raises(DataError, match="best epoch >= 1") as err:
        check_trained({"best_epoch": 0}, "bgfn_seed0.json")
    assert err.value.source == "bgfn_seed0.json" and err.value.field == "best_epoch"
    check_trained({"best_epoch": 0}, "bgfn_seed0.json", allow_untrained=True)
    check_trained({"best_epoch": 3}, "bgfn_seed0.json")


def test_only_the_spiking_network_must_have_learned(tmp_path, monkeypatch):
    """BGFN's firing rates depend on training, the twin's MAC count does not: an untrained twin is accepted, an
    untrained BGFN refused."""
    from bgfn.errors import DataError

    cfg = {"energy": {"dataset": "d", "seed": 0, "allow_untrained": False}, "train": {"datasets": ["d"], "seeds": [0]}}
    folder = _measured_checkpoints(tmp_path, monkeypatch, "d", 0)
    (folder / "transformer_seed0.json").write_text(json.dumps({"best_epoch": 0}))
    (folder / "bgfn_seed0.json").write_text(json.dumps({"best_epoch": 4}))
    assert energy.load_measured("smoke", cfg).cards["transformer"]["best_epoch"] == 0
    (folder / "bgfn_seed0.json").write_text(json.dumps({"best_epoch": 0}))
    with pytest.raises(DataError, match="best epoch >= 1"):
        energy.load_measured("smoke", cfg)


# ----------------------------------------------------------------------------------------------- odometers
def test_the_odometer_audit_measures_the_recorded_drive_and_sums_by_hand():
    from_cfg = {"evaluate": {"sweep": {"datasets": ["turin-sim-mpu6000", "rtklib-drive0708"]},
                             "odometer": {"datasets": None, "methods": ["bgfn", "transformer"]}}}
    assert odometer_dataset(from_cfg) == "rtklib-drive0708"                      # the recorded drive first
    from_cfg["evaluate"]["odometer"]["methods"] = []
    assert odometer_dataset(from_cfg) is None                                    # no odometer network trained
    snn, ann = _hand_counts()
    odo = OdometerEnergy("d", 0, {}, {"bgfn": energy.table_from_counts(snn, "BGFN-ODO", E_MAC, E_AC),
                                      "transformer": energy.table_from_counts(ann, "Transformer-ODO", E_MAC, E_AC)},
                         0.1, 8)
    # the same hand sums as the paper's model: 260 pJ against 1100 pJ
    assert odo.totals().set_index("model")["energy_uj"].to_dict() == pytest.approx(
        {"BGFN-ODO": 260e-6, "Transformer-ODO": 1100e-6})
    assert odo.reduction_pct == pytest.approx(100 * (1 - 260 / 1100))
    assert list(odo.table.columns[:2]) == ["dataset", "model"] and set(odo.table["dataset"]) == {"d"}
    alone = OdometerEnergy("d", 0, {}, {"bgfn": odo.tables["bgfn"]}, 0.1, 8)
    assert np.isnan(alone.reduction_pct) and "no Transformer-ODO was trained" in odometer_energy_lines(alone)[1]
    assert "improved" not in odo.table.columns                       # the audit said nothing of training
    # a BGFN-ODO whose best epoch is 0: measured, but no saving against its twin
    untrained = OdometerEnergy("d", 0, {}, odo.tables, 0.1, 8, {"bgfn": False, "transformer": True})
    assert np.isnan(untrained.reduction_pct) and "less energy" not in " ".join(odometer_energy_lines(untrained))
    assert "BGFN-ODO did not train (best epoch 0), so no energy saving" in odometer_energy_lines(untrained)[1]
    t = untrained.table
    assert t.columns[-1] == "improved" and t.groupby("model")["improved"].all().to_dict() == {
        "BGFN-ODO": False, "Transformer-ODO": True}
