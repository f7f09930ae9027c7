"""Baselines (bgfn.models.baselines) and the registry build_model."""

from __future__ import annotations

import pytest
import torch

from bgfn.models import ATLSTM, METHODS, MLP, TransformerTwin, build_model, count_parameters, is_spiking

torch.set_num_threads(1)


@pytest.mark.parametrize("method", METHODS)
def test_every_method_maps_a_window_to_two_outputs(method):
    torch.manual_seed(0)
    small = {"bgfn": dict(dim=16, ffn_dim=16, depth=1, heads=2, time_steps=2),
             "transformer": dict(dim=16, ffn_dim=16, depth=1, heads=2, time_steps=2),
             "at_lstm": dict(hidden=8), "mlp": dict(hidden=8)}[method]
    model = build_model(method, small)
    y = model(torch.randn(3, 30, 9))
    assert y.shape == (3, 2) and torch.isfinite(y).all()
    assert is_spiking(model) == (method == "bgfn")
    y.sum().backward()
    assert all(p.grad is not None for p in model.parameters() if p.requires_grad)


def test_build_model_rejects_unknown():
    with pytest.raises(ValueError, match="unknown method"):
        build_model("lstm", {})
    with pytest.raises(TypeError):
        build_model("mlp", {"no_such_option": 1})


def test_mlp_is_static_on_recent_samples():
    torch.manual_seed(0)
    model = MLP(in_channels=9, n_recent=3, hidden=8).eval()
    x = torch.randn(2, 50, 9)
    x2 = x.clone()
    x2[:, :47] = torch.randn(2, 47, 9)                  # change all but the 3 most recent samples
    assert torch.allclose(model(x), model(x2))
    x2[:, -1] += 1.0
    assert not torch.allclose(model(x), model(x2))


def test_at_lstm_attention_weights_sum_to_one_and_use_the_whole_window():
    torch.manual_seed(0)
    model = ATLSTM(in_channels=9, hidden=8).eval()
    x = torch.randn(2, 40, 9)
    weights = []
    h = model.attn_v.register_forward_hook(lambda m, i, o: weights.append(torch.softmax(o, dim=1)))
    y = model(x)
    h.remove()
    assert torch.allclose(weights[0].sum(1), torch.ones(2, 1))
    x2 = x.clone()
    x2[:, 0] += 1.0                                     # the oldest sample matters
    assert not torch.allclose(y, model(x2))


def test_transformer_twin_matches_bgfn_widths():
    kw = dict(dim=64, ffn_dim=64, depth=2, heads=4, time_steps=4)
    twin, bgfn = build_model("transformer", kw), build_model("bgfn", kw)
    # same Linear widths and depth: parameter counts within a few percent (LayerNorm vs BatchNorm, fused qkv)
    assert abs(count_parameters(twin) - count_parameters(bgfn)) / count_parameters(bgfn) < 0.05
    assert isinstance(twin, TransformerTwin)
    assert any(isinstance(m, torch.nn.LayerNorm) for m in twin.modules())
