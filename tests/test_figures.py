"""bgfn.report.diagrams: the LIF illustration is a real LIF neuron, the diagrams read the configuration they are given."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402
import torch  # noqa: E402

from bgfn.report import diagrams as figures  # noqa: E402
from bgfn.models import build_model  # noqa: E402
from bgfn.models.lif import beta_from_tau, lif_reference  # noqa: E402

torch.set_num_threads(1)

SMALL = dict(dim=16, ffn_dim=16, depth=1, heads=2, time_steps=2, kernel_size=3)


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    plt.close("all")


def texts(fig) -> str:
    return "\n".join(figures.diagram_texts(fig))


# ----------------------------------------------------------------------------------------------- LIF
def test_simulate_lif_hand_computed():
    # tau = 2 -> beta = 0.5, U_thr = 1, V_reset = 0 (Eq. eq:LIF by hand):
    # U = 0.6, 0.9, 1.05 (spike, reset), 0.2, 0.1 + 1.2 = 1.3 (spike)
    tr = figures.simulate_lif([0.6, 0.6, 0.6, 0.2, 1.2], tau=2.0, v_threshold=1.0)
    np.testing.assert_allclose(tr["u"], [0.6, 0.9, 1.05, 0.2, 1.3], atol=1e-6)
    np.testing.assert_array_equal(tr["spikes"], [0, 0, 1, 0, 1])
    assert tr["beta"] == pytest.approx(0.5) and tr["v_reset"] == 0.0
    # SpikingJelly's stored potential after the reset: the paper's H(t) / beta
    np.testing.assert_allclose(tr["v"], [0.6, 0.9, 0.0, 0.2, 0.0], atol=1e-6)


@pytest.mark.parametrize("tau, thr", [(2.0, 1.0), (3.0, 0.7), (1.5, 1.2)])
def test_simulate_lif_matches_the_papers_equation(tau, thr):
    cur = figures.default_lif_current(80)
    tr = figures.simulate_lif(cur, tau=tau, v_threshold=thr)
    s_ref, u_ref = lif_reference(torch.tensor(cur, dtype=torch.float64).reshape(-1, 1), beta=beta_from_tau(tau),
                                 u_thr=thr)
    np.testing.assert_allclose(tr["u"], u_ref.reshape(-1).numpy(), atol=1e-5)
    np.testing.assert_array_equal(tr["spikes"], s_ref.reshape(-1).numpy())
    # fires exactly where U reaches the threshold, and after a spike U restarts from the input alone
    np.testing.assert_array_equal(tr["spikes"] > 0.5, tr["u"] >= thr - 1e-6)
    after = np.flatnonzero(tr["spikes"][:-1] > 0.5) + 1
    np.testing.assert_allclose(tr["u"][after], tr["current"][after], atol=1e-6)


def test_default_current_fires_only_on_the_wave():
    tr = figures.simulate_lif(figures.default_lif_current(80), tau=2.0, v_threshold=1.0)
    # plateau 0.3 with beta 0.5 settles at U = 0.3 / (1 - 0.5) = 0.6 < 1: silent
    assert tr["spikes"][:12].sum() == 0
    assert tr["u"][:12].max() < 0.6 + 1e-6
    assert 0 < tr["spikes"].sum() < len(tr["spikes"])


def test_lif_settings_read_from_the_model():
    model = build_model("bgfn", {**SMALL, "tau": 3.0, "v_threshold": 0.8})
    assert figures.lif_settings(model) == {"tau": 3.0, "v_threshold": pytest.approx(0.8)}
    with pytest.raises(ValueError):
        figures.lif_settings(build_model("mlp", {"n_recent": 1, "hidden": 8, "layers": 2}))


def test_plot_lif_shows_threshold_and_spike_count():
    tr = figures.simulate_lif(figures.default_lif_current(), tau=2.0, v_threshold=1.0)
    fig = figures.plot_lif(tr)
    t = texts(fig)
    assert f"{int(tr['spikes'].sum())} spikes in {len(tr['t'])} steps" in t
    assert "threshold" in t and "U$_{thr}$ = 1" in t


# ----------------------------------------------------------------------------------------------- diagrams
def test_architecture_spec_reads_the_built_model():
    spec = figures.architecture_spec(build_model("bgfn", SMALL), window=50)
    assert (spec["dim"], spec["ffn_dim"], spec["depth"], spec["heads"], spec["time_steps"]) == (16, 16, 1, 2, 2)
    assert spec["head_dim"] == 8 and spec["in_channels"] == 9 and spec["out_dim"] == 2 and spec["window"] == 50
    big = figures.architecture_spec(build_model("bgfn", dict(dim=32, ffn_dim=64, depth=3, heads=4, time_steps=5)),
                                    window=200)
    assert (big["dim"], big["ffn_dim"], big["depth"], big["heads"], big["time_steps"]) == (32, 64, 3, 4, 5)
    assert big["params"] > spec["params"]


def test_architecture_diagram_changes_with_the_configuration():
    a = texts(figures.plot_bgfn_architecture(figures.architecture_spec(build_model("bgfn", SMALL), 50)))
    b = texts(figures.plot_bgfn_architecture(figures.architecture_spec(
        build_model("bgfn", dict(dim=32, ffn_dim=64, depth=3, heads=4, time_steps=5)), 200)))
    assert "L = 1 x" in a and "L = 3 x" in b
    assert "D = 16" in a and "D = 32" in b
    assert "T$_s$ = 2" in a and "T$_s$ = 5" in b
    assert "2 heads" in a and "4 heads" in b
    assert "[B, 50, 9]" in a and "[B, 200, 9]" in b
    assert "[5, B, 200, 32]" in b          # tensor shape after the embedding: [T_s, B, N, D]
    assert "Linear(32 -> 64)" in b         # spiking MLP hidden width
    assert "Conv1d(9 -> C$\\cdot$T$_s$ = 45" in b


def test_hybrid_and_loose_diagrams_read_their_parameters():
    h = texts(figures.plot_hybrid_system(window=120, gnss_rates_hz={"a": 5.0, "b": 1.0}, fusion_rate_hz=2.0,
                                         pseudo_std_m=1.5))
    assert "window N = 120" in h and "2 Hz" in h and "$\\sigma$ = 1.5 m" in h
    assert "0.2 s / 1 s" in h                               # increment intervals of 5 Hz and 1 Hz GNSS
    assert "prediction mode (GPS outage)" in h and "pred-gps" in h
    loose = texts(figures.plot_loosely_coupled(imu_rate_hz=200.0, gnss_rates_hz=10.0, bias_model="gauss_markov"))
    from bgfn.nav.error_model import N_STATES

    assert f"{N_STATES}-state Kalman filter" in loose and "200 Hz" in loose and "10 Hz" in loose
    assert "gauss markov" in loose
