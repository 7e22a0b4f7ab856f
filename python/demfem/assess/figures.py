"""Figures of the assessment report, each returned as PNG bytes (to embed in the HTML) and
written as a PNG file. SI units on every axis."""
from __future__ import annotations

import io
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["FIGURES", "make_figures"]

#: File names of the figures, in report order, with their captions.
FIGURES = {
    "risk_map.png": "Where the risk comes from: breakage hazard Σ −ln(1 − P_k) of the window's "
                    "collisions by contact point on the table (both partners counted); belt "
                    "along +x, the opening at the right.",
    "impact_speeds.png": "Normal impact speed at contact onset: every recorded onset and the "
                         "events kept by the minimum-speed filter (dashed line).",
    "collision_rate.png": "Events per second against time; the statistics window is shaded, "
                          "with its two halves' mean rates (steadiness check).",
    "stress_model.png": "The stress model: peak σ1 on the inner and outer surface against "
                        "peak contact force, and the window's events on the inner line.",
    "cartridge_risk.png": "Breakage probability of each passage (a cartridge from insertion "
                          "to exit) over its time in the statistics window (log scale; "
                          "passages without any risk-bearing event are not drawn).",
}


def _png(fig) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110, bbox_inches="tight")
    return buf.getvalue()


def make_figures(out: Path, data: dict[str, Any]) -> dict[str, bytes]:
    """Draw every figure of :data:`FIGURES` from ``data`` (the risk stage's arrays: ``map``,
    ``onset_speeds``, ``events``, ``window``, ``min_speed``, ``stress``, ``model``,
    ``p_window``, ``steady``), write each PNG into ``out`` atomically and return
    {file name: PNG bytes}."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm

    from demfem.io.atomic import write_bytes_atomic

    ev = data["events"]
    t0, t1 = data["window"]
    figs: dict[str, bytes] = {}

    # risk map
    fig, ax = plt.subplots(figsize=(7, 3.8))
    m = data["map"]
    hz = np.where(m["hazard"] > 0, m["hazard"], np.nan).T
    if np.any(np.isfinite(hz)):
        im = ax.pcolormesh(m["x_edges"], m["y_edges"], hz, cmap="inferno_r",
                           norm=LogNorm(vmin=np.nanmin(hz), vmax=np.nanmax(hz)))
        fig.colorbar(im, ax=ax, label="hazard per bin (dimensionless)")
    ax.contour(0.5 * (m["x_edges"][1:] + m["x_edges"][:-1]),
               0.5 * (m["y_edges"][1:] + m["y_edges"][:-1]), m["count"].T,
               levels=3, colors="0.5", linewidths=0.6)
    ax.set_xlabel("x (belt direction), m")
    ax.set_ylabel("y, m")
    ax.set_aspect("equal")
    ax.set_title(f"hazard by position, window {t0:.3g}-{t1:.3g} s (grey: event counts)")
    figs["risk_map.png"] = _png(fig)
    plt.close(fig)

    # impact speeds
    fig, ax = plt.subplots(figsize=(6, 3.5))
    v_all = np.asarray(data["onset_speeds"], float)
    v_all = v_all[v_all > 0]
    if v_all.size:
        bins = np.geomspace(max(v_all.min(), 1e-6), max(v_all.max(), 2e-6), 50).tolist()
        ax.hist(v_all, bins=bins, color="0.7", label="all onsets")
        if len(ev):
            ax.hist(ev["normal_speed"], bins=bins, color="C3", alpha=0.7, label="events")
    ax.axvline(data["min_speed"], color="k", ls="--", lw=1)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("normal relative speed at onset, m/s")
    ax.set_ylabel("count")
    ax.legend()
    figs["impact_speeds.png"] = _png(fig)
    plt.close(fig)

    # collision rate over time
    fig, ax = plt.subplots(figsize=(6, 3.2))
    duration = float(data["duration"])
    nb = max(10, min(100, int(len(ev) ** 0.5) + 1))
    edges = np.linspace(0.0, duration, nb + 1)
    cnt, _ = np.histogram(ev["time"], bins=edges)
    ax.step(edges[:-1], cnt / np.diff(edges), where="post", color="C0")
    ax.axvspan(t0, t1, color="C2", alpha=0.12, label="statistics window")
    s = data["steady"]
    mid = 0.5 * (t0 + t1)
    ax.hlines([s["rate_first_half_per_s"], s["rate_second_half_per_s"]], [t0, mid], [mid, t1],
              colors="C3", lw=2, label="half-window means")
    ax.set_xlabel("time, s")
    ax.set_ylabel("events per second, 1/s")
    ax.legend(fontsize=8)
    figs["collision_rate.png"] = _png(fig)
    plt.close(fig)

    # stress model
    fig, ax = plt.subplots(figsize=(6, 3.5))
    model = data["model"]
    st = data["stress"]
    fmax = max(float(np.max(st["force_N"])) if len(st["force_N"]) else 1.0, 1e-3)
    f = np.linspace(0.0, 1.1 * fmax, 50)
    ax.plot(f, model.sigma_inner(f) / 1e6, color="C3", label=f"inner, β = {model.beta_inner:.3g}")
    ax.plot(f, model.sigma_outer(f) / 1e6, color="C0", label=f"outer, β = {model.beta_outer:.3g}")
    inside = (ev["time"] >= t0) & (ev["time"] <= t1)
    ax.plot(st["force_N"][inside], st["sigma_inner_Pa"][inside] / 1e6, ".", ms=2,
            color="C3", alpha=0.3)
    ax.set_xlabel("peak contact force F, N")
    ax.set_ylabel("peak σ1, MPa")
    ax.legend(fontsize=8)
    figs["stress_model.png"] = _png(fig)
    plt.close(fig)

    # per-cartridge risk
    fig, ax = plt.subplots(figsize=(6, 3.2))
    p = np.asarray(data["p_window"], float)
    pos = p[p > 0]
    if pos.size:
        lo = np.log10(pos)
        ax.hist(lo, bins=40, color="C1")
        ax.axvline(np.log10(max(np.mean(p), 1e-300)), color="k", ls="--", lw=1, label="mean")
        ax.legend(fontsize=8)
    ax.set_xlabel("log10 P of each passage over its time in the window (dimensionless)")
    ax.set_ylabel("passages")
    figs["cartridge_risk.png"] = _png(fig)
    plt.close(fig)

    for name, png in figs.items():
        write_bytes_atomic(Path(out) / name, png)
    return figs
