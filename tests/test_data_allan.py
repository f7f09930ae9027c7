"""Allan deviation against its analytic cases (IEEE Std 952 Annex C): white noise falls as 1/sqrt(tau), a
Gauss-Markov bias peaks at 0.62 sigma near 1.9 T, gaps never join two pieces, and the bias-change law."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import lfilter

from bgfn.data import allan as A


def test_white_noise_reads_its_density_at_every_tau():
    rate, density = 100.0, 2e-3                         # u/sqrt(Hz): std density/sqrt(dt) per sample
    x = np.random.default_rng(0).normal(0.0, density * np.sqrt(rate), 400_000)
    taus = [0.01, 0.1, 1.0, 10.0]
    adev, pairs = A.allan_deviation(x, rate, taus)
    assert adev == pytest.approx(density / np.sqrt(taus), rel=0.1)
    assert np.sqrt(A.white_avar(taus, density)) == pytest.approx(density / np.sqrt(taus))
    assert pairs[0] == x.size - 1


def test_the_gauss_markov_formula_peaks_where_the_standard_says_and_matches_a_simulated_bias():
    sigma, corr = 1e-3, 20.0
    tau = np.logspace(-1, 3, 2000)
    curve = np.sqrt(A.gauss_markov_avar(tau, sigma, corr))
    k = int(np.argmax(curve))
    assert tau[k] / corr == pytest.approx(1.89, rel=0.03) and curve[k] / sigma == pytest.approx(0.618, rel=0.01)
    # a simulated first-order Gauss-Markov process at 10 Hz, 20 000 correlation times
    rate, n = 10.0, 4_000_000
    a = np.exp(-1.0 / (rate * corr))
    w = np.random.default_rng(1).normal(0.0, sigma * np.sqrt(1 - a * a), n)
    x = lfilter([1.0], [1.0, -a], w)
    taus = [2.0, 20.0, 40.0]
    adev, _ = A.allan_deviation(x, rate, taus)
    assert adev == pytest.approx(np.sqrt(A.gauss_markov_avar(taus, sigma, corr)), rel=0.1)


def test_a_gap_keeps_two_pieces_apart():
    rate = 10.0
    x = np.concatenate([np.zeros(50), [1e6], np.ones(50)])   # two flat pieces at different levels, one bad sample
    valid = np.ones(x.size, bool)
    valid[50] = False
    adev, pairs = A.allan_deviation(x, rate, [0.1, 1.0], valid)
    assert adev[0] == 0.0 and pairs[0] == 98            # no pair straddles the gap: both pieces are constant
    joined, _ = A.allan_deviation(np.concatenate([np.zeros(50), np.ones(50)]), rate, [0.1])
    assert joined[0] > 0.0                              # without the gap the step shows
    assert np.isnan(A.allan_deviation(x, rate, [6.0], valid)[0][0])   # clusters longer than a piece: none valid


def test_the_bias_change_of_a_gauss_markov_process():
    sigma, corr = 2.0, 50.0
    assert A.bias_change_var(1e6, sigma, corr) == pytest.approx(2 * sigma ** 2)          # independent draws
    assert A.bias_change_var(0.5, sigma, corr) == pytest.approx(2 * sigma ** 2 * 0.5 / corr, rel=0.01)   # a walk
