"""Energy estimate (bgfn.energy): firing-rate hooks, MAC/SOP counts and energies against hand computations."""

from __future__ import annotations

import math

import pytest
import torch
from torch import nn
from torch.overrides import TorchFunctionMode

from bgfn import energy
from bgfn.models import build_model
from bgfn.models.bgfn import SSA
from bgfn.models.lif import make_lif

torch.set_num_threads(1)


# ----------------------------------------------------------------------------------------------- toy models
class LIFOnly(nn.Module):
    """Windows [B, T, K] of currents -> one LIF layer (multi-step) -> spikes [T, B, K]."""

    spiking = True

    def __init__(self):
        super().__init__()
        self.lif = make_lif(tau=2.0, v_threshold=1.0)

    def forward(self, x):                       # [B, T, K]
        return self.lif(x.transpose(0, 1).contiguous())


class TwoLayer(nn.Module):
    """Real input -> Linear (MAC) -> LIF over T steps -> Linear on spikes (SOP) -> mean. [B, N, C] -> [B, 4]."""

    spiking = True

    def __init__(self, time_steps: int = 2):
        super().__init__()
        self.time_steps = time_steps
        self.fc1 = nn.Linear(2, 3, bias=False)
        self.lif = make_lif(tau=2.0, v_threshold=1.0)
        self.fc2 = nn.Linear(3, 4, bias=False)
        with torch.no_grad():
            self.fc1.weight.copy_(torch.tensor([[2.0, 0.0], [0.0, 2.0], [2.0, 2.0]]))
            self.fc2.weight.fill_(0.5)

    def forward(self, x):                                      # [B, N, C]
        cur = self.fc1(x)                                      # [B, N, 3], once (real-valued input)
        s = self.lif(cur.unsqueeze(0).repeat(self.time_steps, 1, 1, 1))   # [T, B, N, 3] spikes
        return self.fc2(s).mean(dim=(0, 2))                    # [B, 4]


class FixedSpikes(nn.Module):
    """Ignores its input and returns a fixed spike tensor (stands in for SSA's Q/K/V layers)."""

    def __init__(self, spikes):
        super().__init__()
        self.register_buffer("spikes", spikes)

    def forward(self, x):
        return self.spikes


class SSAOnly(nn.Module):
    """A single SSA with fixed Q/K/V spikes; windows [B, T, N, D] -> SSA output."""

    spiking = True

    def __init__(self, q, k, v, heads):
        super().__init__()
        dim = q.shape[-1]
        self.ssa = SSA(dim, heads, 0.125, 2.0, 1.0, 0.5, 2.0)
        self.ssa.q, self.ssa.k, self.ssa.v = FixedSpikes(q), FixedSpikes(k), FixedSpikes(v)

    def forward(self, x):
        return self.ssa(x.transpose(0, 1))


def _row(table, layer):
    r = table[table["layer"] == layer]
    assert len(r) == 1, f"{layer} not in {list(table['layer'])}"
    return r.iloc[0]


# ----------------------------------------------------------------------------------------------- firing rates
def test_firing_rate_hooks_give_the_exact_fraction_of_ones():
    # Currents of 1.5 fire at every step (>= threshold 1 even from a reset membrane), currents of 0 never
    # (the membrane after a spike is 0, after no spike it only decays): the spikes equal the 1.5-mask.
    g = torch.Generator().manual_seed(3)
    mask = (torch.rand(5, 4, 6, generator=g) < 0.3).float()   # [B, T, K]
    windows = 1.5 * mask
    rates = energy.measure_firing_rates(LIFOnly(), windows, batch_size=2)   # pooled over 3 batches
    assert list(rates) == ["lif"]
    assert rates["lif"] == pytest.approx(float(mask.sum()) / mask.numel(), abs=1e-15)
    assert 0.0 < rates["lif"] < 1.0


# ----------------------------------------------------------------------------------------------- toy network
def test_two_layer_toy_network_matches_hand_count():
    # x tokens: (0.7, 0) -> currents (1.4, 0, 1.4) -> spikes (1, 0, 1) at both steps; (0, 0) -> none;
    # (0.7, 0.7) -> (1.4, 1.4, 2.8) -> (1, 1, 1); (0, 0.7) -> (0, 1.4, 1.4) -> (0, 1, 1).
    x = torch.tensor([[[0.7, 0.0], [0.0, 0.0], [0.7, 0.7]],
                      [[0.0, 0.7], [0.0, 0.0], [0.0, 0.0]]])      # B=2 windows, N=3 tokens, C=2
    model = TwoLayer(time_steps=2)
    T, B, N, C, H, O = 2, 2, 3, 2, 3, 4
    spikes_per_step = (2 + 0 + 3) + (2 + 0 + 0)                   # both windows
    rate = T * spikes_per_step / (T * B * N * H)                  # 14 / 36 = 7 / 18
    macs_fc1 = N * C * H                                          # 18 per prediction (fc1 runs once)
    sops_fc2 = rate * T * (N * H * O)                             # r * T * FLOPs = 7/18 * 2 * 36 = 28
    assert sops_fc2 == pytest.approx(T * spikes_per_step / B * O)  # = input spikes per prediction * fan-out
    e_mac, e_ac = 4.6, 0.9
    energy_uj = (e_mac * macs_fc1 + e_ac * sops_fc2) * 1e-6       # 108 pJ

    assert energy.measure_firing_rates(model, x)["lif"] == pytest.approx(7 / 18)
    table = energy.energy_table(model, x, e_mac, e_ac, name="toy")
    assert list(table.columns) == list(energy.COLUMNS)
    assert list(table["layer"]) == ["fc1", "fc2", "total"]
    fc1, fc2, total = _row(table, "fc1"), _row(table, "fc2"), _row(table, "total")
    assert (fc1["macs"], fc1["sops"], fc1["firing_rate"]) == (macs_fc1, 0.0, 1.0)
    assert fc2["macs"] == 0.0
    assert fc2["sops"] == pytest.approx(28.0, abs=1e-12)
    assert fc2["firing_rate"] == pytest.approx(7 / 18, abs=1e-15)
    assert total["macs"] == macs_fc1 and total["sops"] == pytest.approx(28.0)
    assert total["energy_uj"] == pytest.approx(energy_uj, rel=1e-12)
    assert energy_uj == pytest.approx(108e-6)
    assert total["firing_rate"] == pytest.approx(7 / 18)           # sops / (T * FLOPs) of the SOP layers
    # the energy parameters are used as given
    t2 = energy.energy_table(model, x, e_mac=1.0, e_ac=10.0)
    assert _row(t2, "total")["energy_uj"] == pytest.approx((18 + 280) * 1e-6)
    # the same network, one window per batch: same per-prediction counts
    t3 = energy.energy_table(model, x, e_mac, e_ac, batch_size=1)
    assert _row(t3, "total")["energy_uj"] == pytest.approx(energy_uj, rel=1e-12)


# ----------------------------------------------------------------------------------------------- SSA
def _hand_spikingjelly_count(q, k, v, heads):
    """Loops: SpikingJelly's count of Q (K^T V) (dh < N) or (Q K^T) V. The first product multiplies two spike
    matrices: its nonzero products. The second multiplies spikes with the first result: nonzero products if
    that result is binary (max over all heads and steps: one bmm call), else spikes x fan-out."""
    T, B, N, D = q.shape
    dh = D // heads
    first, inter = 0, []
    for t in range(T):
        for b in range(B):
            for h in range(heads):
                sl = slice(h * dh, (h + 1) * dh)
                qh, kh, vh = q[t, b, :, sl].tolist(), k[t, b, :, sl].tolist(), v[t, b, :, sl].tolist()
                if dh < N:       # K^T V [dh, dh], then Q [N, dh] times it
                    m = [[sum(kh[n][d] * vh[n][e] for n in range(N)) for e in range(dh)] for d in range(dh)]
                    inter.append((qh, m, "left"))
                else:            # Q K^T [N, N], then times V [N, dh]
                    m = [[sum(qh[i][d] * kh[j][d] for d in range(dh)) for j in range(N)] for i in range(N)]
                    inter.append((vh, m, "right"))
                first += sum(sum(row) for row in m)            # entries count the nonzero products
    binary = max(x for _, m, _ in inter for row in m for x in row) <= 1
    second = 0
    for spikes, m, side in inter:
        if side == "left":                                     # Q m: Q spike (n, d) adds row d of m
            for n in range(N):
                for d in range(dh):
                    if spikes[n][d]:
                        second += sum(1 for x in m[d] if x) if binary else dh
        else:                                                  # m V: V spike (j, e) adds column j of m
            for j in range(N):
                for e in range(dh):
                    if spikes[j][e]:
                        second += sum(1 for i in range(N) if m[i][j]) if binary else N
    return first + second


@pytest.mark.parametrize("N,D,heads,density", [(3, 4, 2, 1.0), (2, 4, 2, 1.0), (3, 4, 2, 0.2), (2, 4, 2, 0.2)])
def test_ssa_count_follows_spikformer_formula(N, D, heads, density):
    # dh = 2 < N = 3: Q (K^T V); dh = 2 >= N = 2: (Q K^T) V. Dense spikes make K^T V (Q K^T) integer-valued,
    # sparse ones keep it binary: both of SpikingJelly's cases of the second product.
    T, B = 2, 1
    g = torch.Generator().manual_seed(N)
    q = (torch.rand(T, B, N, D, generator=g) < 0.5 * density).float()
    k = (torch.rand(T, B, N, D, generator=g) < 0.8 * density).float()
    v = (torch.rand(T, B, N, D, generator=g) < 0.6 * density).float()
    rq, rk, rv = (float(t.double().mean()) for t in (q, k, v))
    dh = D // heads
    if dh < N:
        expected = (min(rk, rv) + rq) * T * heads * N * dh ** 2
    else:
        expected = (min(rq, rk) + rv) * T * heads * N ** 2 * dh
    model = SSAOnly(q, k, v, heads)
    counts = {c.name: c for c in energy.layer_counts(model, torch.zeros(B, T, N, D))}
    row = counts["ssa.qkv_matmul"]
    assert row.kind == "ssa" and row.spiking and row.macs == 0.0
    assert row.sops == pytest.approx(expected, rel=1e-12)
    assert (row.geometry["rate_q"], row.geometry["rate_k"], row.geometry["rate_v"]) == pytest.approx((rq, rk, rv))
    assert row.geometry["exact_sops"] == _hand_spikingjelly_count(q, k, v, heads)
    assert row.geometry["exact_sops"] <= row.sops + 1e-9          # the sparser operand bounds the coincidences
    assert energy.ssa_sops(T, heads, N, dh, rq, rk, rv) == pytest.approx(expected)
    # SpikingJelly's own counter on the same SSA: its synaptic operations of the two products
    sj = energy.spikingjelly_counts(model, torch.zeros(B, T, N, D))
    proj = counts["ssa.proj.linear"]
    assert sj["synops"] == pytest.approx(row.geometry["exact_sops"] + proj.sops)


def test_ssa_count_by_hand_numbers():
    # T=2, H=2, N=3, dh=2: T*H*N*dh^2 = 48; r_q = 0.25, r_k = 0.5, r_v = 0.125 -> (0.125 + 0.25) * 48 = 18
    assert energy.ssa_sops(2, 2, 3, 2, 0.25, 0.5, 0.125) == pytest.approx(18.0)
    # dh >= N: T*H*N^2*dh = 2*2*4*2 = 32; (min(0.25, 0.5) + 0.125) * 32 = 12
    assert energy.ssa_sops(2, 2, 2, 2, 0.25, 0.5, 0.125) == pytest.approx(12.0)


# ----------------------------------------------------------------------------------------------- ANN twin
def test_transformer_macs_by_hand():
    cfg = dict(dim=4, ffn_dim=6, depth=1, heads=2, time_steps=2, kernel_size=3)
    C, N, D, F, Ts, k = 2, 5, 4, 6, 2, 3
    model = build_model("transformer", cfg, in_channels=C)
    expected = {
        "conv": C * Ts * N * k,            # groups=C: each of the C*T_s output maps sees one channel, kernel 3
        "embed": N * (C * Ts) * D,
        "blocks.0.qkv": N * D * 3 * D,
        "blocks.0.attention": 2 * N * N * D,   # Q K^T and A V: H * N * N * dh each, H * dh = D
        "blocks.0.proj": N * D * D,
        "blocks.0.ffn.0": N * D * F,
        "blocks.0.ffn.2": N * F * D,
        "head": D * 2,
    }                                       # 60 + 80 + 240 + 200 + 80 + 120 + 120 + 8 = 908
    x = torch.randn(3, N, C)
    table = energy.energy_table(model, x)
    assert _row(table, "total")["model"] == "transformer"
    body = table[table["layer"] != "total"]
    assert dict(zip(body["layer"], body["macs"])) == {key: float(v) for key, v in expected.items()}
    assert (body["sops"] == 0).all() and (body["firing_rate"] == 1.0).all()
    total = sum(expected.values())
    assert total == 908
    assert _row(table, "total")["energy_uj"] == pytest.approx(total * 4.6e-6)
    # SpikingJelly's MAC counter (BN folded, math attention kernel) finds the same matmuls
    sj = energy.spikingjelly_counts(model, x)
    assert sj["macs"] == total and sj["synops"] == 0


def test_lstm_is_refused():
    with pytest.raises(ValueError, match="LSTM"):
        energy.layer_counts(build_model("at_lstm", {"hidden": 4}), torch.zeros(1, 5, 9))


# ----------------------------------------------------------------------------------------------- BGFN
TINY = dict(dim=8, ffn_dim=8, depth=2, heads=2, time_steps=2, kernel_size=3, v_threshold=0.3, attn_threshold=0.2)


def _tiny_bgfn():
    torch.manual_seed(0)
    return build_model("bgfn", TINY)


def test_bgfn_counts_residual_trains_and_agrees_with_spikingjelly():
    model = _tiny_bgfn()
    x = torch.randn(3, 6, 9, generator=torch.Generator().manual_seed(1))    # B=3, N=6 > dh=4: Q (K^T V)
    counts = energy.layer_counts(model, x)
    by = {c.name: c for c in counts}
    assert not by["spike_encoder.conv"].spiking and not by["head"].spiking      # real-valued inputs -> MACs
    # residual stream: 1 + 2l trains into Q/K/V of block l, 2 + 2l into its first MLP layer
    for l in range(2):
        for m in ("q", "k", "v"):
            assert by[f"blocks.{l}.attn.{m}.linear"].trains == 1 + 2 * l
        assert by[f"blocks.{l}.mlp.fc1.linear"].trains == 2 + 2 * l
        assert by[f"blocks.{l}.attn.proj.linear"].trains == 1 and by[f"blocks.{l}.mlp.fc2.linear"].trains == 1
    spiking = [c for c in counts if c.spiking]
    assert sum(c.sops for c in spiking) > 0
    for c in spiking:
        assert 0.0 <= c.rate <= 1.0
        if c.kind != "ssa":
            assert c.sops == pytest.approx(c.trains * c.rate * c.dense)
    # SpikingJelly 2.0's counters on the BN-folded copy (same spikes): MACs equal ours, SynOps equal our
    # count with the exact (nonzero-product) SSA term
    sj = energy.spikingjelly_counts(model, x)
    ours = energy.layer_counts(sj["model"], x)
    assert sj["macs"] == pytest.approx(sum(c.macs for c in ours))
    exact = sum(c.geometry["exact_sops"] if c.kind == "ssa" else c.sops for c in ours)
    assert sj["synops"] == pytest.approx(exact, rel=1e-9)
    # SpikingJelly's default rules count the integer residual inputs as dense MACs
    strict = energy.spikingjelly_counts(model, x, multispike=False)
    assert strict["macs"] > sj["macs"]


def test_fold_batchnorm_is_exact():
    torch.manual_seed(1)
    twin = build_model("transformer", dict(dim=4, ffn_dim=4, depth=1, heads=2, time_steps=2), in_channels=3)
    with torch.no_grad():
        twin.bn.running_mean.uniform_(-1, 1)
        twin.bn.running_var.uniform_(0.5, 2.0)
        twin.bn.weight.uniform_(0.5, 1.5)
    twin.eval()
    x = torch.randn(2, 7, 3)
    folded = energy.fold_batchnorm(twin)
    assert isinstance(folded.bn, nn.Identity) and not isinstance(twin.bn, nn.Identity)
    torch.testing.assert_close(folded(x), twin(x), rtol=1e-5, atol=1e-6)
    model = _tiny_bgfn().eval()
    fb = energy.fold_batchnorm(model)
    assert not any(isinstance(m, nn.modules.batchnorm._BatchNorm) for m in fb.modules())
    xb = torch.randn(2, 6, 9)
    r1, r2 = energy.measure_firing_rates(model, xb), energy.measure_firing_rates(fb, xb)
    assert r1.keys() == r2.keys()
    assert max(abs(r1[k] - r2[k]) for k in r1) < 0.02          # float rounding may flip a spike at threshold


def test_reduction_and_sweeps_are_consistent():
    model = _tiny_bgfn()
    twin = build_model("transformer", {k: v for k, v in TINY.items() if k not in ("v_threshold", "attn_threshold")})
    x = torch.randn(2, 6, 9)
    snn, ann = energy.layer_counts(model, x), energy.layer_counts(twin, x)
    ts, ta = energy.table_from_counts(snn, "bgfn"), energy.table_from_counts(ann, "transformer")
    red = energy.reduction_pct(ts, ta)
    assert red == pytest.approx(100 * (1 - energy.total_energy_uj(ts) / energy.total_energy_uj(ta)))
    assert math.isfinite(red)
    # the same rates reproduce the same counts; at the measured mean rate the rate sweep gives `red`
    again = energy.with_rates(snn, snn)
    assert [c.sops for c in again] == pytest.approx([c.sops for c in snn])
    r0 = energy.mean_rate(snn)
    assert r0 == pytest.approx(_row(ts, "total")["firing_rate"])
    sweep = energy.reduction_vs_rate(snn, ann, [0.0, r0, 1.0])
    assert sweep["reduction_pct"].iloc[1] == pytest.approx(red)
    be = sweep.attrs["break_even_rate"]
    assert energy.reduction_vs_rate(snn, ann, [be])["reduction_pct"].iloc[0] == pytest.approx(0.0, abs=1e-9)
    # T_s sweep at the trained T_s reproduces the measured reduction (rates held fixed)
    def build(t):
        torch.manual_seed(5)
        return (build_model("bgfn", {**TINY, "time_steps": t}),
                build_model("transformer", {k: v for k, v in {**TINY, "time_steps": t}.items()
                                            if k not in ("v_threshold", "attn_threshold")}))
    df = energy.reduction_vs_time_steps(build, x, snn, [TINY["time_steps"], 2 * TINY["time_steps"]])
    assert df["reduction_pct"].iloc[0] == pytest.approx(red)
    assert df["snn_energy_uj"].iloc[1] > df["snn_energy_uj"].iloc[0]


def test_missing_checkpoint_names_the_file(tmp_path, monkeypatch):
    from bgfn import config

    monkeypatch.setattr(config, "RESULTS_ROOT", tmp_path)
    cfg = {"energy": {"dataset": None, "seed": None}, "train": {"datasets": ["drive-a", "drive-b"], "seeds": [3]}}
    expected = tmp_path / "smoke" / "models" / "drive-a" / "bgfn_seed3.pt"
    with pytest.raises(FileNotFoundError) as err:
        energy.energy_checkpoint("smoke", "bgfn", cfg)
    assert str(expected) in str(err.value) and "03_bgfn_training" in str(err.value)
    expected.parent.mkdir(parents=True)
    expected.write_bytes(b"")
    assert energy.energy_checkpoint("smoke", "bgfn", cfg) == expected


# ----------------------------------------------------------------------------------------------- speed helpers
def test_realtime_flags_use_the_sample_periods():
    from bgfn.train.speed import realtime_flags

    assert realtime_flags(9.9) == {"imu": True, "gnss": True}          # 100 Hz IMU: 10 ms per sample
    assert realtime_flags(10.0) == {"imu": True, "gnss": True}
    assert realtime_flags(10.1) == {"imu": False, "gnss": True}        # 1 Hz GNSS: 1000 ms per epoch
    assert realtime_flags(1000.1) == {"imu": False, "gnss": False}
    assert realtime_flags(30.0, imu_rate_hz=20.0, gnss_rate_hz=50.0) == {"imu": True, "gnss": False}
    with pytest.raises(ValueError):
        realtime_flags(float("nan"))


def test_timing_helpers_restore_threads_and_count_calls():
    from bgfn.train import speed

    calls = []
    t = speed.median_time(lambda: calls.append(1), repeats=3, warmup=2)
    assert len(calls) == 5 and t >= 0.0
    before = torch.get_num_threads()
    model = build_model("mlp", {"hidden": 4})
    assert speed.throughput(model, window=5, batch=4, repeats=1, threads=1) > 0
    assert speed.latency_ms(model, window=5, repeats=1, threads=1) > 0
    assert torch.get_num_threads() == before


def test_matmul_share_of_a_training_step_counts_only_dense_products():
    from types import SimpleNamespace

    from bgfn.train import speed

    ev = [SimpleNamespace(key=k, self_cpu_time_total=us) for k, us in
          [("aten::mm", 3e5), ("aten::addmm", 1e5), ("aten::add_", 5e5), ("aten::bmm", 1e5)]]
    assert speed.matmul_seconds(ev) == pytest.approx((0.5, 1.0))              # (0.3 + 0.1 + 0.1) s of 1.0 s

    class Scale(torch.nn.Module):                                            # elementwise only: no product
        def __init__(self):
            super().__init__()
            self.w = torch.nn.Parameter(torch.ones(9))

        def forward(self, x):                                                # [B, N, 9] -> [B, 2]
            return (x * self.w).mean(1)[:, :2]

    assert speed.training_step_profile(Scale(), window=5, batch=4)["matmul_s"] == 0.0
    p = speed.training_step_profile(build_model("mlp", {"hidden": 64}), window=5, batch=16)
    assert 0.0 < p["matmul_s"] < p["step_s"]


def test_interleaved_profiles_alternate_the_steps_and_the_ceiling_is_taken_round_by_round():
    from bgfn.train import speed

    calls = []
    out = speed.interleaved_profiles({"a": lambda: calls.append("a"), "b": lambda: calls.append("b")}, repeats=2)
    assert calls == ["a", "b", "a", "b", "a", "b"]                     # a warm-up round, then two profiled rounds
    assert [len(v) for v in out.values()] == [2, 2] and out["a"][0]["matmul_s"] == 0.0
    # the twin's step over BGFN's matrix products per round, and BGFN's products over its own step
    twin = [{"step_s": 0.3, "matmul_s": 0.2}, {"step_s": 0.6, "matmul_s": 0.4}, {"step_s": 0.3, "matmul_s": 0.2}]
    bgfn = [{"step_s": 1.0, "matmul_s": 0.6}, {"step_s": 2.0, "matmul_s": 1.2}, {"step_s": 1.5, "matmul_s": 1.2}]
    c = speed.ceiling_spread(twin, bgfn)
    assert c["ceiling"]["median"] == pytest.approx(0.5) and c["ceiling"]["q25"] == pytest.approx(0.375)
    assert c["ceiling"]["rounds"] == 3                                # 0.5, 0.5, 0.25: a slow round moves both
    assert c["matmul_share"]["median"] == pytest.approx(0.6) and c["matmul_share"]["q75"] == pytest.approx(0.7)
    assert speed.median_profile(bgfn) == {"step_s": 1.5, "matmul_s": 1.2}
    with pytest.raises(ValueError):
        speed.ceiling_spread(twin, bgfn[:2])


def test_matmul_calls_record_a_steps_products_and_the_replay_runs_the_same_products_again():
    from bgfn.train import speed

    lin = torch.nn.Linear(5, 3, bias=False)

    def macs(calls):                                   # [a, b] x [b, c]: a b c multiply-accumulates each
        return sum(a * b * c for _, ((a, b), (_b, c)) in calls)

    x = torch.randn(4, 5)
    calls = speed.matmul_calls(lambda: lin(x).sum().backward())
    # forward x W^T (4 x 5 x 3) and the weight's gradient (another 60): 120; the input needs no gradient
    assert {name for name, _ in calls} == {"aten::mm"} and len(calls) == 2 and macs(calls) == 120
    x.requires_grad_(True)
    assert macs(speed.matmul_calls(lambda: lin(x).sum().backward())) == 180     # + the input's gradient

    ran = []

    class Spy(TorchFunctionMode):
        def __torch_function__(self, func, types, args=(), kwargs=None):
            if func is torch.mm:
                ran.append(tuple(tuple(a.shape) for a in args))
            return func(*args, **(kwargs or {}))

    replay = speed.matmul_replay(calls)
    with Spy():
        replay()
    assert ran == [shapes for _, shapes in calls]      # the same products, in the same order, no other work


def test_twin_ratios_divide_bgfn_by_its_twin_per_size_measured_for_both():
    from bgfn.train.speed import twin_ratios

    rates = {"bgfn": {"quick": 600.0, "paper": 6.0}, "transformer": {"quick": 750.0, "paper": 30.0}}
    profiles = {"bgfn": {"paper": {"matmul_s": 0.8, "step_s": 1.3}}, "transformer": {"paper": {"step_s": 0.24}}}
    out = twin_ratios(rates, profiles)
    assert out["train_ratio_bgfn_over_twin"] == pytest.approx({"quick": 0.8, "paper": 0.2})    # 600/750, 6/30
    assert out["train_ratio_ceiling"] == pytest.approx({"paper": 0.3})                         # 0.24 / 0.8
    assert twin_ratios({"bgfn": {"quick": 1.0}}, {}) == {"train_ratio_bgfn_over_twin": {}, "train_ratio_ceiling": {}}
