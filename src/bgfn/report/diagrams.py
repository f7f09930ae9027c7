"""Diagrams and illustrations of the paper drawn from code (matplotlib patches and arrows, no graphviz).

Every function returns a :class:`matplotlib.figure.Figure` that notebook 10 saves and the book shows, drawn from the
real configuration so that it changes with the profile: :func:`plot_loosely_coupled` (paper Fig.
``ins-gps-loose``), :func:`plot_lif` on :func:`simulate_lif` (Fig. ``fig:LIF``, a real SpikingJelly ``LIFNode``),
:func:`plot_bgfn_architecture` on :func:`architecture_spec` (Fig. ``BGFN-arc``, read from a built BGFN) and
:func:`plot_hybrid_system` (Fig. ``BGFN``: online training with GPS and prediction during an outage). A diagram's
text is in ``ax.texts`` (the tests read it back).
"""

from __future__ import annotations

from typing import Any, Sequence

import matplotlib.pyplot as plt
import numpy as np
import torch
from matplotlib.lines import Line2D
from matplotlib.patches import FancyArrowPatch, FancyBboxPatch

from bgfn.models import count_parameters
from bgfn.models.lif import DEFAULT_TAU, DEFAULT_THRESHOLD, beta_from_tau, lif_modules, make_lif
from bgfn.nav.error_model import N_STATES

#: Colours of the diagrams: sensors, navigation, learning, prediction-mode path.
SENSOR_FC = "#e8f1fb"
NAV_FC = "#fdf3e1"
NET_FC = "#e9f6ea"
PRED_COLOR = "#c0392b"
FONT = 10


# ----------------------------------------------------------------------------------------------- drawing
def _canvas(width: float, height: float, figsize: tuple[float, float]):
    fig, ax = plt.subplots(figsize=figsize)
    ax.set_xlim(0, width)
    ax.set_ylim(0, height)
    ax.set_aspect("equal")
    ax.axis("off")
    return fig, ax


def _box(ax, x: float, y: float, w: float, h: float, text: str, fc: str = "white", ec: str = "black",
         ls: str = "-", fontsize: float = FONT, weight: str = "normal", lw: float = 1.2) -> dict:
    """Rounded box centred at (x, y); returns its anchor points (left, right, top, bottom)."""
    ax.add_patch(FancyBboxPatch((x - w / 2, y - h / 2), w, h, boxstyle="round,pad=0.02,rounding_size=0.12",
                                fc=fc, ec=ec, ls=ls, lw=lw))
    if text:
        ax.text(x, y, text, ha="center", va="center", fontsize=fontsize, fontweight=weight)
    return {"l": (x - w / 2, y), "r": (x + w / 2, y), "t": (x, y + h / 2), "b": (x, y - h / 2), "c": (x, y)}


def _arrow(ax, p0, p1, text: str | None = None, ls: str = "-", color: str = "black", rad: float = 0.0,
           text_xy=None, ha: str = "center", va: str = "center", fontsize: float = FONT - 1, lw: float = 1.3):
    """Arrow from p0 to p1 (straight, or an arc of curvature ``rad``) with an optional label."""
    ax.add_patch(FancyArrowPatch(p0, p1, arrowstyle="-|>", mutation_scale=14, lw=lw, ls=ls, color=color,
                                 shrinkA=0, shrinkB=0, connectionstyle=f"arc3,rad={rad}"))
    if text:
        if text_xy is None:
            text_xy = ((p0[0] + p1[0]) / 2, (p0[1] + p1[1]) / 2)
        ax.text(*text_xy, text, ha=ha, va=va, fontsize=fontsize, color=color,
                bbox=dict(fc="white", ec="none", pad=0.5, alpha=0.85))


def _path_arrow(ax, points: Sequence[tuple[float, float]], ls: str = "-", color: str = "black", lw: float = 1.3):
    """Polyline through ``points`` with an arrow head on the last segment."""
    xs, ys = zip(*points)
    if len(points) > 2:
        ax.plot(xs[:-1], ys[:-1], ls=ls, color=color, lw=lw, solid_capstyle="butt")
    _arrow(ax, points[-2], points[-1], ls=ls, color=color, lw=lw)


def _rate(hz: float) -> str:
    return f"{hz:g} Hz"


def _rates_text(rates: dict[str, float] | float | None) -> str:
    if rates is None:
        return "GNSS rate of the drive"
    if isinstance(rates, (int, float)):
        return _rate(float(rates))
    uniq = sorted(set(float(v) for v in rates.values()), reverse=True)
    if len(uniq) == 1:
        return _rate(uniq[0])
    return "\n".join(f"{_rate(v)} ({k})" for k, v in rates.items())


# ----------------------------------------------------------------------------------------------- Fig. ins-gps-loose
def plot_loosely_coupled(imu_rate_hz: float = 100.0, gnss_rates_hz: dict[str, float] | float | None = None,
                         n_states: int | None = None, bias_model: str | None = None):
    """Block diagram of the loosely coupled GPS/INS integration (paper Fig. ``ins-gps-loose``).

    Parameters
    ----------
    imu_rate_hz : float
        IMU (and filter propagation) rate, Hz (profile ``data.imu_rate_hz``).
    gnss_rates_hz : dict or float, optional
        GNSS rate per dataset, Hz (profile ``data.<dataset>.gnss_rate_hz``).
    n_states : int, optional
        Error states of the filter (default :data:`bgfn.nav.error_model.N_STATES`).
    bias_model : str, optional
        Bias states' model (profile ``nav.bias_model``), shown in the KF box.
    """
    if n_states is None:

        n_states = N_STATES
    fig, ax = _canvas(13.0, 6.3, (10.0, 4.85))
    imu = _box(ax, 1.2, 3.6, 2.0, 1.3, f"IMU\ngyro, accel\n{_rate(imu_rate_hz)}", fc=SENSOR_FC)
    ins = _box(ax, 4.6, 3.6, 2.8, 1.3, "INS mechanization\nNED strapdown\n(bgfn.nav.strapdown)", fc=NAV_FC)
    kf_text = (f"{n_states}-state Kalman filter\nEq. (eq13), (eq3), (eq4)\nz = P$_{{INS}}$ - P$_{{GPS}}$"
               + (f"\nbiases: {bias_model.replace('_', ' ')}" if bias_model else ""))
    kf = _box(ax, 9.4, 3.6, 3.0, 1.6, kf_text, fc=NAV_FC)
    gps = _box(ax, 9.4, 0.8, 3.6, 1.2, "GPS receiver\n" + _rates_text(gnss_rates_hz), fc=SENSOR_FC,
               fontsize=FONT - 0.5)
    out = _box(ax, 9.4, 5.7, 3.6, 0.75, "integrated solution: P, V, A", fc="white")
    _arrow(ax, imu["r"], ins["l"], "f$^b$, $\\omega^b$", text_xy=(2.7, 4.0))
    _arrow(ax, ins["r"], kf["l"], "P, V, A\n(INS)", text_xy=(6.95, 4.1))
    _arrow(ax, gps["t"], kf["b"], "P$_{GPS}$", text_xy=(9.55, 2.1), ha="left")
    # corrections fed back to the INS (closed loop): below the forward path
    _path_arrow(ax, [(8.5, kf["b"][1]), (8.5, 2.0), (4.6, 2.0), (4.6, ins["b"][1])])
    ax.text(6.5, 2.1, "feedback: $\\delta$P, $\\delta$V, $\\delta$A,\naccel/gyro biases", ha="center", va="bottom",
            fontsize=FONT - 1)
    _path_arrow(ax, [ins["t"], (4.6, 5.7), out["l"]])
    ax.text(4.75, 5.0, "corrected", ha="left", va="center", fontsize=FONT - 1)
    ax.set_title("Loosely coupled GPS/INS integration (paper Fig. ins-gps-loose)", fontsize=FONT + 1)
    return fig


# ----------------------------------------------------------------------------------------------- Fig. LIF
def default_lif_current(n_steps: int = 80) -> np.ndarray:
    """A deterministic input current for the LIF illustration: a sub-threshold plateau, then a slow wave.

    With ``beta = 0.5`` a constant current ``I`` settles at ``U = I / (1 - beta)``; the plateau at 0.3
    (``U -> 0.6``) never fires, the wave (0.1 ... 0.9) fires at a rate that follows it.
    """
    t = np.arange(n_steps, dtype=float)
    cur = 0.5 + 0.4 * np.sin(2.0 * np.pi * (t - 12.0) / 34.0)
    cur[t < 12] = 0.3
    return cur


def simulate_lif(current: Sequence[float], tau: float | None = None, v_threshold: float | None = None) -> dict:
    """Drive one SpikingJelly LIF neuron (:func:`bgfn.models.lif.make_lif`) with ``current``.

    Returns
    -------
    dict
        ``t`` (steps), ``current`` I(t), ``u`` the membrane potential U(t) of Eq. (eq:LIF) (before the reset,
        the value compared with the threshold), ``v`` SpikingJelly's stored potential after the reset,
        ``spikes`` S(t) in {0, 1} (the node's output), ``tau``, ``beta``, ``v_threshold``, ``v_reset``.
    """


    tau = DEFAULT_TAU if tau is None else float(tau)
    v_threshold = DEFAULT_THRESHOLD if v_threshold is None else float(v_threshold)
    node = make_lif(tau=tau, v_threshold=v_threshold)
    node.store_v_seq = True
    x = torch.as_tensor(np.asarray(current, dtype=np.float32)).reshape(-1, 1)   # [T, 1 neuron]
    with torch.no_grad():
        spikes = node(x)                                                          # [T, 1]
    v = node.v_seq.detach().reshape(-1).double().numpy()                         # V[t] after reset
    beta = beta_from_tau(tau)
    # SpikingJelly charges H[t] = V[t-1] - V[t-1]/tau + X[t] (decay_input=False, V_reset = 0): the paper's U(t)
    v_prev = np.concatenate([[0.0], v[:-1]])
    u = beta * v_prev + x.reshape(-1).double().numpy()
    return {"t": np.arange(len(u)), "current": x.reshape(-1).double().numpy(), "u": u, "v": v,
            "spikes": spikes.reshape(-1).double().numpy(), "tau": tau, "beta": beta,
            "v_threshold": v_threshold, "v_reset": float(node.v_reset)}


def plot_lif(trace: dict, title: str | None = None):
    """Input current, membrane potential with threshold and reset, output spikes (paper Fig. ``fig:LIF``)."""
    t, cur, u, s = trace["t"], trace["current"], trace["u"], trace["spikes"]
    fig, axes = plt.subplots(3, 1, figsize=(9.0, 5.6), sharex=True, gridspec_kw={"height_ratios": [1.0, 1.6, 0.7]})
    ax_i, ax_u, ax_s = axes
    ax_i.bar(t, cur, width=0.8, color="tab:gray")
    ax_i.set_ylabel("I(t)")
    ax_i.grid(alpha=0.3)
    ax_u.step(t, u, where="mid", color="tab:blue", lw=1.3, label="membrane potential U(t)")
    ax_u.axhline(trace["v_threshold"], color=PRED_COLOR, ls="--", lw=1.2,
                 label=f"threshold U$_{{thr}}$ = {trace['v_threshold']:g}")
    fired = s > 0.5
    ax_u.plot(t[fired], u[fired], "o", color=PRED_COLOR, ms=4, label="U $\\geq$ U$_{thr}$: spike, reset to "
              f"V$_{{reset}}$ = {trace['v_reset']:g}")
    ax_u.set_ylabel("U(t)")
    ax_u.grid(alpha=0.3)
    ax_u.legend(loc="lower left", bbox_to_anchor=(0.0, 1.0), fontsize=8, ncol=3, frameon=False,
                borderaxespad=0.1)
    ax_s.vlines(t[fired], 0, 1, color="black", lw=1.5)
    ax_s.set_ylim(0, 1.2)
    ax_s.set_yticks([0, 1])
    ax_s.set_ylabel("S(t)")
    ax_s.set_xlabel("SNN time step t (units of $\\Delta t$)")
    n = int(fired.sum())
    ax_s.text(0.99, 0.95, f"{n} spikes in {len(t)} steps", transform=ax_s.transAxes, ha="right", va="top",
              fontsize=8)
    fig.suptitle(title or ("SpikingJelly LIFNode (bgfn.models.lif.make_lif): "
                           f"$\\tau$ = {trace['tau']:g} ($\\beta$ = {trace['beta']:g}), "
                           f"U$_{{thr}}$ = {trace['v_threshold']:g}, hard reset"), fontsize=FONT + 1)
    fig.tight_layout()
    return fig


def lif_settings(model) -> dict:
    """``tau`` and ``v_threshold`` of the first LIF layer of ``model`` (the settings BGFN's neurons use)."""

    mods = lif_modules(model)
    if not mods:
        raise ValueError(f"{type(model).__name__} has no LIF layer")
    return {"tau": float(mods[0].tau), "v_threshold": float(mods[0].v_threshold)}


# ----------------------------------------------------------------------------------------------- Fig. BGFN-arc
def architecture_spec(model, window: int) -> dict:
    """What the architecture diagram shows, read from a built :class:`bgfn.models.BGFN`.

    Returns
    -------
    dict
        ``window`` N, ``in_channels`` C, ``time_steps`` T_s, ``kernel_size``, ``dim`` D, ``ffn_dim``,
        ``depth`` L, ``heads``, ``head_dim``, ``attn_scale``, ``out_dim``, ``readout``, ``tau``,
        ``v_threshold``, ``attn_threshold``, ``params``.
    """

    enc = model.spike_encoder
    emb = model.embedding.layer.linear
    blocks = list(model.blocks)
    spec = {
        "window": int(window), "in_channels": int(enc.in_channels), "time_steps": int(enc.time_steps),
        "kernel_size": int(enc.conv.kernel_size[0]), "dim": int(emb.out_features), "depth": len(blocks),
        "out_dim": int(model.head.out_features), "readout": str(model.readout), "params": count_parameters(model),
        **lif_settings(model),
    }
    if blocks:
        attn = blocks[0].attn
        spec.update(heads=int(attn.heads), head_dim=int(spec["dim"] // attn.heads), attn_scale=float(attn.scale),
                    ffn_dim=int(blocks[0].mlp.fc1.linear.out_features),
                    attn_threshold=float(attn.attn_lif.v_threshold))
    else:
        spec.update(heads=None, head_dim=None, attn_scale=None, ffn_dim=None, attn_threshold=None)
    return spec


def plot_bgfn_architecture(spec: dict, title: str | None = None):
    """BGFN's layers top to bottom with tensor shapes (paper Fig. ``BGFN-arc``), from :func:`architecture_spec`."""
    N, C, T, D = spec["window"], spec["in_channels"], spec["time_steps"], spec["dim"]
    L = spec["depth"]
    fig, ax = _canvas(12.6, 14.2, (8.8, 9.9))
    x0, w = 5.15, 7.7
    fs = FONT - 0.5
    shape_x = x0 + w / 2 + 0.2

    def shape(y, text):
        ax.text(shape_x, y, text, ha="left", va="center", fontsize=FONT - 1, family="monospace", color="#333333")

    inp = _box(ax, x0, 13.2, w, 1.0, f"IMU window S$_k$: N = {N} samples x C = {C} channels\n"
               "$\\gamma$, $\\theta$, $\\psi$, f$^b_{x,y,z}$, $\\omega^b_{x,y,z}$  (Eq. eq21)", fc=SENSOR_FC,
               fontsize=fs)
    enc = _box(ax, x0, 11.3, w, 1.35,
               "Conv spike encoder, Eq. (eq:spike_input): S = SN(BN(Conv(S$_k$)))\n"
               f"Conv1d({C} -> C$\\cdot$T$_s$ = {C * T}, k = {spec['kernel_size']}, groups = {C}) + BN + LIF\n"
               f"T$_s$ = {T} SNN steps per IMU step", fc=NET_FC, fontsize=fs)
    emb = _box(ax, x0, 9.45, w, 1.05, "Spiking embedding, Eq. (eq:spiking_embedding)\n"
               f"S$_{{emb}}$ = SN(BN(Linear({C} -> D = {D})))", fc=NET_FC, fontsize=fs)
    _arrow(ax, inp["b"], enc["t"])
    shape((inp["b"][1] + enc["t"][1]) / 2, f"[B, {N}, {C}]")
    _arrow(ax, enc["b"], emb["t"])
    shape((enc["b"][1] + emb["t"][1]) / 2, f"[{T}, B, {N}, {C}] spikes")
    # the L x block frame
    top, bot = 8.45, 3.3
    ax.add_patch(FancyBboxPatch((x0 - w / 2 - 0.25, bot), w + 0.5, top - bot,
                                boxstyle="round,pad=0.02,rounding_size=0.15", fc="none", ec="#555555", ls="--", lw=1.2))
    ax.text(x0 - w / 2 - 0.45, (top + bot) / 2, f"L = {L} x", ha="right", va="center", fontsize=FONT + 2,
            fontweight="bold")
    if L:
        ssa_text = (f"Spiking self-attention: {spec['heads']} heads x d$_h$ = {spec['head_dim']}\n"
                    "Q, K, V = SN(BN(Linear(x)))\n"
                    f"SN(Q K$^T$ V $\\cdot$ s), s = {spec['attn_scale']:g}, no softmax, "
                    f"threshold {spec['attn_threshold']:g}\n"
                    f"then SN(BN(Linear({D} -> {D})))")
        mlp_text = (f"Spiking MLP: SN(BN(Linear({D} -> {spec['ffn_dim']})))\n"
                    f"-> SN(BN(Linear({spec['ffn_dim']} -> {D})))")
    else:
        ssa_text, mlp_text = "(no block: depth 0)", ""
    wi = w - 1.0
    ssa = _box(ax, x0 + 0.3, 7.05, wi, 1.6, ssa_text, fc=NET_FC, fontsize=fs)
    add1 = _box(ax, x0, 5.72, 0.55, 0.5, "+", fc="white", fontsize=FONT + 2)
    mlp = _box(ax, x0 + 0.3, 4.65, wi, 0.95, mlp_text, fc=NET_FC, fontsize=fs)
    add2 = _box(ax, x0, 3.62, 0.55, 0.5, "+", fc="white", fontsize=FONT + 2)
    _arrow(ax, emb["b"], (x0, ssa["t"][1]))
    shape((emb["b"][1] + top) / 2, f"[{T}, B, {N}, {D}]")
    _arrow(ax, (x0, ssa["b"][1]), add1["t"])
    _arrow(ax, add1["b"], (x0, mlp["t"][1]))
    _arrow(ax, (x0, mlp["b"][1]), add2["t"])
    # residual connections on the left lane
    xr1, xr2 = x0 - w / 2 + 0.2, x0 - w / 2 + 0.45
    _path_arrow(ax, [(x0, 8.15), (xr1, 8.15), (xr1, 5.72), add1["l"]], color="#555555", lw=1.1)
    _path_arrow(ax, [(x0, 5.3), (xr2, 5.3), (xr2, 3.62), add2["l"]], color="#555555", lw=1.1)
    ax.text(xr1 - 0.08, 6.9, "residual", rotation=90, ha="right", va="center", fontsize=FONT - 2.5, color="#555555")
    readout = ("mean over T$_s$ and the N tokens" if spec["readout"] == "mean" else "last token, mean over T$_s$")
    read = _box(ax, x0, 2.2, w, 0.95, f"{readout}  ->  [B, {D}]\nLinear({D} -> {spec['out_dim']})", fc=NET_FC,
                fontsize=fs)
    out = _box(ax, x0, 0.65, w, 0.85, f"$\\Delta$P$_{{GPS}}$ = ($\\Delta$P$^n$, $\\Delta$P$^e$)  [B, {spec['out_dim']}]"
               "   Eq. (eq:bgfn_net)", fc=SENSOR_FC, fontsize=fs)
    _arrow(ax, add2["b"], read["t"])
    shape((add2["b"][1] + read["t"][1]) / 2, f"[{T}, B, {N}, {D}]")
    _arrow(ax, read["b"], out["t"])
    ax.set_title(title or (f"BGFN as built: D = {D}, FFN {spec['ffn_dim']}, L = {L}, heads {spec['heads']}, "
                           f"T$_s$ = {T}, N = {N}; {spec['params']:,} parameters\n"
                           f"LIF $\\tau$ = {spec['tau']:g}, U$_{{thr}}$ = {spec['v_threshold']:g}"
                           " (paper Fig. BGFN-arc)"), fontsize=FONT + 0.5)
    return fig


# ----------------------------------------------------------------------------------------------- Fig. BGFN
def plot_hybrid_system(window: int, gnss_rates_hz: dict[str, float] | float | None = None,
                       fusion_rate_hz: float = 1.0, pseudo_std_m: Any = None, imu_rate_hz: float = 100.0):
    """The GPS/INS system based on BGFN (paper Fig. ``BGFN``): training mode (solid) and prediction mode
    during GPS outages (dashed), with the pseudo-GPS position of Eq. (pred-gps).

    Parameters
    ----------
    window : int
        N, IMU samples per network input (profile ``train.window``).
    gnss_rates_hz : dict or float, optional
        GNSS rate per dataset (the increments' interval is its inverse).
    fusion_rate_hz : float
        Pseudo-GPS fixes per second (profile ``evaluate.pseudo_gps.fusion_rate_hz``).
    pseudo_std_m : float, str or None
        Standard deviation of a pseudo fix (``evaluate.pseudo_gps.std_m``; None: the drive's median GNSS std).
    imu_rate_hz : float
        IMU rate, Hz.
    """
    if pseudo_std_m is None:
        std_text = "$\\sigma$ = median GNSS std"
    elif isinstance(pseudo_std_m, str):
        std_text = f"$\\sigma$: {pseudo_std_m}"
    else:
        std_text = f"$\\sigma$ = {float(pseudo_std_m):g} m"
    if isinstance(gnss_rates_hz, dict):
        intervals = " / ".join(f"{1.0 / float(v):g} s" for v in dict.fromkeys(gnss_rates_hz.values()))
    elif gnss_rates_hz:
        intervals = f"{1.0 / float(gnss_rates_hz):g} s"
    else:
        intervals = "GNSS interval"
    fig, ax = _canvas(14.0, 9.0, (10.8, 6.95))
    fs = FONT - 1.5
    imu = _box(ax, 1.6, 4.6, 1.9, 1.2, f"IMU\n{_rate(imu_rate_hz)}", fc=SENSOR_FC)
    ins = _box(ax, 4.8, 4.6, 2.5, 1.2, "INS\nmechanization", fc=NAV_FC)
    kf = _box(ax, 9.0, 4.6, 2.6, 1.2, "Kalman filter\n(15 states)", fc=NAV_FC)
    out = _box(ax, 12.5, 4.6, 2.2, 1.2, "navigation\nsolution\nP, V, A", fc="white")
    gps = _box(ax, 9.0, 7.6, 3.2, 1.15, "GPS\n" + _rates_text(gnss_rates_hz), fc=SENSOR_FC, fontsize=FONT - 1)
    log = _box(ax, 4.8, 7.6, 3.4, 1.15, "logged pairs\n(IMU window, $\\Delta$P$_{GPS}$)\ntrain BGFN", fc=NET_FC,
               fontsize=FONT - 1)
    net = _box(ax, 4.8, 1.5, 2.8, 1.3, f"trained BGFN\nwindow N = {window}\n[1, {window}, 9] -> [1, 2]", fc=NET_FC,
               ec=PRED_COLOR, ls="--")
    acc = _box(ax, 9.0, 1.5, 3.6, 1.3, "pseudo-GPS, Eq. (pred-gps)\nP$_{GPS}$(k) = P$_{GPS_0}$ + "
               "$\\sum_{i=0}^{k}$ $\\Delta$P$_{GPS_i}$", fc="white", ec=PRED_COLOR, ls="--", fontsize=FONT - 1)
    # online-training mode (GPS available): solid
    _arrow(ax, imu["r"], ins["l"], "f$^b$, $\\omega^b$", text_xy=(3.1, 5.0), fontsize=fs)
    _arrow(ax, ins["r"], kf["l"], "P$_{INS}$, V$_{INS}$, A$_{INS}$", text_xy=(6.85, 5.0), fontsize=fs)
    _arrow(ax, kf["r"], out["l"])
    _arrow(ax, gps["b"], kf["t"], "P$_{GPS}$", text_xy=(9.15, 6.1), ha="left", fontsize=fs)
    _arrow(ax, gps["l"], log["r"], "$\\Delta$P$_{GPS}$\ntargets", text_xy=(6.95, 8.5), fontsize=fs)
    _arrow(ax, ins["t"], log["b"], "$\\gamma$ $\\theta$ $\\psi$, f$^b$, $\\omega^b$", text_xy=(4.95, 6.1),
           ha="left", fontsize=fs)
    _path_arrow(ax, [(8.3, 4.0), (8.3, 3.3), (5.4, 3.3), (5.4, 4.0)])
    ax.text(6.85, 3.2, "$\\delta$P, $\\delta$V, $\\delta$A, biases", ha="center", va="top", fontsize=fs)
    # weights: logger -> network, routed round the IMU on the left
    _path_arrow(ax, [log["l"], (0.25, 7.6), (0.25, 1.5), net["l"]], color="#2e7d32")
    ax.text(0.4, 2.7, "weights", rotation=90, ha="left", va="center", fontsize=fs, color="#2e7d32")
    # prediction mode (GPS outage): dashed
    _arrow(ax, (4.2, ins["b"][1]), (4.2, net["t"][1]), ls="--", color=PRED_COLOR)
    ax.text(4.05, 3.0, f"IMU window\nN = {window}", ha="right", va="center", fontsize=fs, color=PRED_COLOR)
    _arrow(ax, net["r"], acc["l"], ls="--", color=PRED_COLOR)
    ax.text(6.7, 2.35, f"$\\Delta$P$_{{GPS}}$ every\n{intervals}", ha="center", va="bottom", fontsize=fs,
            color=PRED_COLOR)
    _arrow(ax, acc["t"], kf["b"], f"pseudo fixes\n{fusion_rate_hz:g} Hz, {std_text}", ls="--", color=PRED_COLOR,
           text_xy=(9.15, 3.05), ha="left", fontsize=fs)
    handles = [Line2D([], [], color="black", lw=1.3, label="online-training mode (GPS available)"),
               Line2D([], [], color=PRED_COLOR, lw=1.3, ls="--", label="prediction mode (GPS outage)")]
    ax.legend(handles=handles, loc="upper right", fontsize=FONT - 1.5, frameon=True)
    ax.set_title("GPS/INS navigation based on BGFN (paper Fig. BGFN)", fontsize=FONT + 1)
    return fig


def diagram_texts(fig) -> list[str]:
    """All text of a figure (axes texts, titles, legends), for tests and checks."""
    out = [t.get_text() for t in fig.texts]
    for ax in fig.axes:
        out += [t.get_text() for t in ax.texts] + [ax.get_title()]
        leg = ax.get_legend()
        if leg is not None:
            out += [t.get_text() for t in leg.get_texts()]
    return [s for s in out if s]


__all__ = ["plot_loosely_coupled", "default_lif_current", "simulate_lif", "plot_lif", "lif_settings",
           "architecture_spec", "plot_bgfn_architecture", "plot_hybrid_system", "diagram_texts"]
