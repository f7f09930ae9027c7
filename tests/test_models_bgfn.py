"""BGFN (bgfn.models.bgfn) and its LIF neurons (bgfn.models.lif) against the paper's equations."""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
import torch
from torch.overrides import TorchFunctionMode

from bgfn.models import BGFN, build_model, count_parameters
from bgfn.models.bgfn import SSA
from bgfn.models import lif_kernels
from bgfn.models.lif import (DEFAULT_TAU, atan_surrogate_grad, beta_from_tau, lif_modules, lif_reference,
                             make_lif)
from bgfn.train.speed import torch_threads

torch.set_num_threads(1)

TINY = dict(dim=16, ffn_dim=16, depth=1, heads=2, time_steps=3)


def test_lif_matches_eq_lif_hand_computed():
    # tau = 2 -> beta = 0.5, U_thr = 1, V_reset = 0. Hand computation of Eq. (eq:LIF):
    # t1: U = 0 + 0.6 = 0.6 (no spike), H = 0.3; t2: U = 0.3 + 0.6 = 0.9, H = 0.45;
    # t3: U = 0.45 + 0.6 = 1.05 -> spike, H = 0; t4: U = 0 + 0.2 = 0.2, H = 0.1; t5: U = 0.1 + 1.2 = 1.3 -> spike
    current = torch.tensor([0.6, 0.6, 0.6, 0.2, 1.2]).reshape(5, 1)
    expected_u = torch.tensor([0.6, 0.9, 1.05, 0.2, 1.3]).reshape(5, 1)
    expected_s = torch.tensor([0.0, 0.0, 1.0, 0.0, 1.0]).reshape(5, 1)
    s_ref, u_ref = lif_reference(current, beta=beta_from_tau(2.0), u_thr=1.0)
    assert torch.allclose(u_ref, expected_u) and torch.equal(s_ref, expected_s)
    lif = make_lif(tau=2.0, v_threshold=1.0)
    lif.store_v_seq = True
    s = lif(current)
    assert torch.equal(s, expected_s)
    # SpikingJelly keeps V = (1 - S) U (hard reset to 0), before the leak beta
    assert torch.allclose(lif.v_seq, expected_u * (1 - expected_s))


@pytest.mark.parametrize("tau,thr", [(2.0, 1.0), (4.0, 0.5), (1.25, 0.8)])
def test_lif_matches_eq_lif_random(tau, thr):
    g = torch.Generator().manual_seed(0)
    current = torch.rand(30, 7, generator=g) * 1.2 - 0.1
    s_ref, _ = lif_reference(current, beta=beta_from_tau(tau), u_thr=thr)
    s = make_lif(tau=tau, v_threshold=thr)(current)
    assert torch.equal(s, s_ref)
    assert 0 < s.mean() < 1                                        # the test exercises both branches
    assert beta_from_tau(tau) == pytest.approx(1 - 1 / tau)


@pytest.mark.parametrize("alpha", [2.0, 4.0])
def test_surrogate_gradient_is_atan(alpha):
    thr = 1.0
    x = torch.linspace(-1.0, 3.0, 41, requires_grad=True)
    lif = make_lif(tau=2.0, v_threshold=thr, alpha=alpha)
    s = lif(x.reshape(1, -1))                                      # one step from V = 0: U = x
    assert torch.equal(s.detach()[0], (x.detach() >= thr).float())  # forward: Heaviside
    s.sum().backward()
    # analytic derivative of Eq. (eq:surrogate_gradient): d/dU [arctan(pi/2 alpha (U - thr))/pi + 1/2]
    u = x.detach().clone().requires_grad_(True)
    (torch.atan(math.pi / 2 * alpha * (u - thr)) / math.pi + 0.5).sum().backward()
    assert torch.allclose(x.grad, u.grad, atol=1e-6)
    assert torch.allclose(x.grad, atan_surrogate_grad(x.detach() - thr, alpha), atol=1e-6)
    assert x.grad.max() == pytest.approx(alpha / 2, rel=1e-3)       # peak at the threshold


@pytest.mark.parametrize("tau,thr,alpha,steps", [(2.0, 1.0, 2.0, 2), (4.0, 0.5, 4.0, 8), (1.25, 0.8, 2.0, 5)])
def test_fused_lif_equals_eq_lif_and_spikingjelly_forward_and_backward(tau, thr, alpha, steps):
    g = torch.Generator().manual_seed(steps)
    current = torch.randn(steps, 6, 17, 5, generator=g) * 1.5                    # [T, B, N, D]
    upstream = torch.randn(current.shape, generator=g)
    fused, sj = make_lif(tau, thr, alpha), make_lif(tau, thr, alpha, fused=False)
    assert type(fused).__name__ == "FusedLIFNode" and isinstance(fused, type(sj))
    x_f, x_s = current.clone().requires_grad_(True), current.clone().requires_grad_(True)
    s_f, s_s = fused(x_f), sj(x_s)
    assert torch.equal(s_f, lif_reference(current, beta_from_tau(tau), thr)[0])  # the paper's Eq. (eq:LIF)
    assert torch.equal(s_f, s_s) and torch.equal(fused.v, sj.v)                  # and SpikingJelly's state
    assert 0 < s_f.mean() < 1
    (s_f * upstream).sum().backward()
    (s_s * upstream).sum().backward()
    torch.testing.assert_close(x_f.grad, x_s.grad, rtol=1e-5, atol=1e-6)          # BPTT with the ATan surrogate
    assert x_f.grad.abs().sum() > 0


def test_fused_lif_backward_leaves_its_saved_tensors_so_a_second_pass_gives_the_same_gradient():
    x = (torch.rand(3, 4, 5) * 2).requires_grad_(True)
    s = make_lif()(x)
    s.sum().backward(retain_graph=True)
    first = x.grad.clone()
    s.sum().backward()
    torch.testing.assert_close(x.grad, 2 * first, rtol=0, atol=0)


@pytest.mark.parametrize("threads", [1, 2])
def test_fused_lif_gives_the_same_bits_with_any_number_of_threads(threads):
    # more neurons than one chunk of the kernels, so that several chunks (and threads) share them
    g = torch.Generator().manual_seed(3)
    current = torch.randn(4, 3, lif_kernels.CHUNK + 77, generator=g) * 1.5
    upstream = torch.randn(current.shape, generator=g)

    def run(n):
        x = current.clone().requires_grad_(True)
        with torch_threads(n):
            s = make_lif()(x)
            (s * upstream).sum().backward()
        return s.detach(), x.grad

    s_1, g_1 = run(1)
    s_n, g_n = run(threads)
    assert torch.equal(s_1, s_n) and torch.equal(g_1, g_n)
    assert torch.equal(s_1, lif_reference(current, beta_from_tau(DEFAULT_TAU))[0])


def test_fused_lif_falls_back_to_spikingjelly_when_the_membrane_is_not_at_rest():
    fused, sj = make_lif(), make_lif(fused=False)
    x = torch.rand(3, 4, 5) * 1.5
    for _ in range(2):                         # the second call starts from the state the first one left
        assert torch.equal(fused(x), sj(x))
    assert torch.equal(fused.v, sj.v)


def test_bgfn_with_fused_lif_trains_exactly_like_spikingjelly():
    from spikingjelly.activation_based import neuron

    torch.manual_seed(0)
    fused = build_model("bgfn", TINY)
    sj = copy.deepcopy(fused)
    for m in sj.modules():
        if type(m).__name__ == "FusedLIFNode":
            m.__class__ = neuron.LIFNode
    x, y = torch.randn(4, 20, 9), torch.randn(4, 2)
    out_f, out_s = fused(x), sj(x)
    torch.testing.assert_close(out_f, out_s, rtol=0, atol=1e-6)
    torch.nn.functional.mse_loss(out_f, y).backward()
    torch.nn.functional.mse_loss(out_s, y).backward()
    for (name, p_f), p_s in zip(fused.named_parameters(), sj.parameters()):
        torch.testing.assert_close(p_f.grad, p_s.grad, rtol=1e-4, atol=1e-6, msg=name)


def test_ssa_shapes_and_attention_without_softmax():
    torch.manual_seed(0)
    T, B, N, D, H = 3, 2, 11, 16, 4
    ssa = SSA(D, H, scale=0.125, tau=2.0, v_threshold=1.0, attn_threshold=0.5, alpha=2.0)
    x = (torch.rand(T, B, N, D) > 0.5).float()
    assert ssa(x).shape == (T, B, N, D)
    q, k, v = ((torch.rand(T, B, H, N, D // H) > 0.5).float() for _ in range(3))
    a = ssa.attend(q, k, v)
    assert a.shape == (T, B, H, N, D // H)
    assert torch.allclose(a, (q @ k.transpose(-2, -1) @ v) * 0.125)   # Q K^T V * scale, either order
    assert torch.allclose(ssa.attend(q, k, 3 * v), 3 * a)              # linear in V: no normalization
    assert torch.allclose(ssa.attend(2 * q, k, v), 2 * a)              # softmax would not scale like this
    attn = q @ k.transpose(-2, -1) * 0.125
    assert not torch.allclose(attn.sum(-1), torch.ones(()))            # rows do not sum to 1


class _Calls(TorchFunctionMode):
    def __init__(self):
        super().__init__()
        self.names = set()

    def __torch_function__(self, func, types, args=(), kwargs=None):
        self.names.add(getattr(func, "__name__", str(func)))
        return func(*args, **(kwargs or {}))


def test_bgfn_forward_calls_no_softmax_and_spikes_are_binary():
    torch.manual_seed(1)
    model = BGFN(in_channels=9, **TINY)
    seen = []
    hooks = [m.register_forward_hook(lambda mod, inp, out: seen.append(out.detach())) for m in lif_modules(model)]
    with _Calls() as calls:
        y = model(torch.randn(4, 20, 9))
    for h in hooks:
        h.remove()
    assert y.shape == (4, 2)
    assert not any("softmax" in n for n in calls.names)
    # encoder, embedding, per block q/k/v/attn/proj + 2 MLP layers
    assert len(seen) == 2 + TINY["depth"] * 7
    for out in seen:
        assert out.shape[0] == TINY["time_steps"]
        assert torch.all((out == 0) | (out == 1))
    rates = [float(o.mean()) for o in seen]
    assert max(rates) > 0.01                                           # the network does fire


def test_spike_encoder_shape_and_time_axis():
    model = BGFN(in_channels=9, **TINY)
    s = model.spike_encoder(torch.randn(5, 20, 9))
    assert s.shape == (TINY["time_steps"], 5, 20, 9)                   # [T_s, B, N, C]
    assert model.embedding(s).shape == (TINY["time_steps"], 5, 20, TINY["dim"])


def test_encoder_neurons_resolve_a_constant_input_finer():
    """K neurons per channel: a constant input is coded by K*T_s binary values instead of T_s (population code)."""
    torch.manual_seed(0)
    levels = {}
    for k in (1, 8):
        model = BGFN(in_channels=1, **{**TINY, "encoder_neurons": k}).eval()
        enc = model.spike_encoder
        with torch.no_grad():                    # spread the thresholds by the BN offsets: neuron j fires above ~j/k
            enc.conv.weight.fill_(1.0 / 3)       # kernel 3 on a constant input: the input value
            enc.bn.bias.copy_(-torch.linspace(0, 1, k * TINY["time_steps"]))
        x = torch.linspace(-0.5, 1.5, 400)[:, None, None].expand(400, 5, 1)   # [B, N=5, C=1], constant in time
        s = enc(x)                               # [T_s, B, N, K]
        assert s.shape == (TINY["time_steps"], 400, 5, k)
        assert torch.all((s == 0) | (s == 1))
        codes = {tuple(c.tolist()) for c in s[:, :, 2].permute(1, 0, 2).reshape(400, -1)}
        levels[k] = len(codes)
    assert levels[1] <= TINY["time_steps"] + 1
    assert levels[8] > 3 * levels[1]
    assert BGFN(in_channels=9, **{**TINY, "encoder_neurons": 4}).embedding.layer.linear.in_features == 36


@pytest.mark.parametrize("train_mode", [True, False])
def test_membrane_state_is_reset_between_batches(train_mode):
    torch.manual_seed(2)
    model = BGFN(in_channels=9, **TINY).train(train_mode)
    lifs = lif_modules(model)
    start_v = []
    hooks = [m.register_forward_pre_hook(lambda mod, inp: start_v.append(torch.as_tensor(mod.v).abs().max()))
             for m in lifs]
    x = torch.randn(3, 20, 9)
    y1 = model(x)
    assert any(torch.as_tensor(m.v).abs().max() > 0 for m in lifs)   # state is left after a batch ...
    y2 = model(x)
    assert torch.allclose(y1, y2, atol=1e-6)                           # ... but not carried into the next
    assert all(float(v) == 0.0 for v in start_v)
    for h in hooks:
        h.remove()


def test_readout_last_and_heads_must_divide():
    model = BGFN(in_channels=9, readout="last", **TINY)
    assert model(torch.randn(2, 12, 9)).shape == (2, 2)
    with pytest.raises(ValueError):
        BGFN(dim=256, heads=6)                                         # the paper's 6 heads do not divide 256


def test_paper_size_builds():
    model = build_model("bgfn", dict(dim=256, ffn_dim=256, depth=4, heads=8, time_steps=4))
    n = count_parameters(model)
    # 4 blocks x (4 D^2 + 2 D F) weights dominate: ~1.6 M
    assert 1.4e6 < n < 1.8e6


def test_tiny_bgfn_overfits_32_windows():
    torch.manual_seed(0)
    g = np.random.default_rng(0)
    x = torch.tensor(g.normal(size=(32, 24, 9)), dtype=torch.float32)
    # a smooth target of the inputs: mean of two channels over the last half of the window
    y = torch.stack([x[:, 12:, 3].mean(1), x[:, 12:, 6].mean(1)], dim=1)
    y = (y - y.mean(0)) / y.std(0)
    model = BGFN(in_channels=9, dim=32, ffn_dim=32, depth=1, heads=4, time_steps=2)
    opt = torch.optim.AdamW(model.parameters(), lr=3e-3, weight_decay=0.0)
    first = None
    for _ in range(250):
        loss = torch.nn.functional.mse_loss(model(x), y)
        first = float(loss.detach()) if first is None else first
        opt.zero_grad()
        loss.backward()
        opt.step()
    model.eval()
    with torch.no_grad():
        final = float(torch.nn.functional.mse_loss(model(x), y))
    model.train()
    with torch.no_grad():
        final_train = float(torch.nn.functional.mse_loss(model(x), y))
    assert min(final, final_train) < first / 10, (first, final, final_train)
