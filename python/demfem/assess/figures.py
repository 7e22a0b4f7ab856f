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
    "risk_map.png": "Where on the table the risk comes from: each bin's share of the "
                    "window's breakage hazard Σ −ln(1 − P_k) (both partners counted), by "
                    "contact point, on the table's outline (walls black, gate red, the "
                    "opening dotted); beside it each wall's share of the hazard of its impacts; "
                    "belt along +x.",
    "impact_speeds.png": "Normal impact speed at contact onset: every impact onset (not the "
                         "belt) and the events kept by the minimum-speed filter (dashed line).",
    "collision_rate.png": "Events per second against time; the statistics window is shaded, "
                          "with its two halves' mean rates (steadiness check).",
    "stress_model.png": "The stresses: peak σ1 on the outer (blue) and inner (red) surface of "
                        "each event of the window against its peak force (dots: two "
                        "cartridges, crosses: walls and gate; the outer stress of an event "
                        "rises with its friction force), over the model's curves for two "
                        "cartridges without friction and sliding.",
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
    ``p_window``, ``steady``; optional ``walls`` (the table's walls with their ``top_view``
    segments), ``wall_shares`` {wall name: share of the hazard} and ``opening`` (x_end,
    w_min, w_max), m), write each PNG into ``out`` atomically and return
    {file name: PNG bytes}."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.colors import LogNorm

    from demfem.io.atomic import write_bytes_atomic

    ev = data["events"]
    t0, t1 = data["window"]
    figs: dict[str, bytes] = {}

    # risk map: on the table's outline, the share of the window's hazard per bin
    fig, ax = plt.subplots(figsize=(7.5, 4.2))
    m = data["map"]
    total = float(np.sum(m["hazard"]))
    if total > 0:
        share = np.where(m["hazard"] > 0, 100.0 * m["hazard"] / total, np.nan).T
        top = float(np.nanmax(share))
        im = ax.pcolormesh(m["x_edges"], m["y_edges"], share, cmap="viridis",
                           norm=LogNorm(vmin=top / 1e3, vmax=top), shading="flat")
        fig.colorbar(im, ax=ax, label="share of the hazard per bin, % (3 decades)",
                     extend="min")
    for wall in data.get("walls", []):
        seg = wall.get("top_view")
        if seg is None:
            continue
        seg = np.asarray(seg, float)
        gate = wall["name"] == "gate"
        ax.plot(seg[:, 0], seg[:, 1], color="C3" if gate else "k", lw=3 if gate else 2,
                solid_capstyle="butt")

    shares = data.get("wall_shares") or {}
    if shares:
        text = "share of the hazard by wall:\n" + "\n".join(
            f"  {name.replace('_', ' ')}: {100 * v:.2g} %"
            for name, v in sorted(shares.items(), key=lambda kv: -kv[1]))
        ax.text(1.35, 0.0, text, transform=ax.transAxes, fontsize=8, va="bottom",
                ha="left")
    if data.get("opening") is not None:
        x_end, w_min, w_max = data["opening"]
        ax.plot([x_end, x_end], [0.0, w_max], color="C3", ls=":", lw=1.5)
        ax.annotate("opening", (x_end, 0.5 * w_max), xytext=(6, 0), textcoords="offset points",
                    fontsize=8, color="C3", va="center")
    ax.set_xlabel("x (belt direction →), m")
    ax.set_ylabel("y, m")
    ax.set_aspect("equal")
    ax.set_title(f"where the hazard comes from, window {t0:.3g}–{t1:.3g} s", fontsize=10)
    figs["risk_map.png"] = _png(fig)
    plt.close(fig)

    # impact speeds
    fig, ax = plt.subplots(figsize=(6, 3.5))
    onsets = data["onset_speeds"]
    if isinstance(onsets, dict):  # the digest an assessment keeps: a histogram
        bins = np.asarray(onsets["speed_bins_m_per_s"], float)
        counts = np.asarray(onsets["speed_counts"], float)
    else:
        v_all = np.asarray(onsets, float)
        v_all = v_all[v_all > 0]
        bins = np.geomspace(max(v_all.min(), 1e-6), max(v_all.max(), 2e-6), 50) if v_all.size \
            else np.geomspace(1e-6, 10.0, 50)
        counts, _ = np.histogram(v_all, bins=bins)
    if counts.sum():
        ax.stairs(counts, bins, fill=True, color="0.7", label="impact onsets (not the belt)")
        if len(ev):
            ax.hist(ev["normal_speed"], bins=list(bins), color="C3", alpha=0.7,
                    label="events (pressed ones at their slow onset)")
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

    # stress model: the window's events on top of the model's curves for two cartridges
    fig, ax = plt.subplots(figsize=(6.4, 3.8))
    st = data["stress"]
    inside = (ev["time"] >= t0) & (ev["time"] <= t1)
    curves = data.get("stress_curves")
    if curves is not None:
        fc = np.asarray(curves["force_N"], float)
        at = f" at the {curves['place']}" if curves.get("place") else ""
        ax.plot(fc, np.asarray(curves["sigma_outer_sliding_Pa"]) / 1e6, color="C0", lw=1,
                label=f"outer{at}, two cartridges sliding at μ = {curves['friction']:g}",
                zorder=1)
        ax.plot(fc, np.asarray(curves["sigma_outer_Pa"]) / 1e6, color="C0", lw=1, ls="--",
                label="outer, no friction", zorder=1)
        ax.plot(fc, np.asarray(curves["sigma_inner_Pa"]) / 1e6, color="C3", lw=1,
                label="inner (bending)", zorder=1)
    wall = inside & (ev["partner"] == 1)
    pair = inside & (ev["partner"] == 0)
    worst = " (worst place)" if "place_index" in st else ""
    for sel, marker, who in ((pair, ".", "cartridges"), (wall, "x", "walls, gate")):
        ax.scatter(st["force_N"][sel], st["sigma_outer_Pa"][sel] / 1e6, s=4, marker=marker,
                   color="C0", alpha=0.5, zorder=3, label=f"events with {who}: outer{worst}")
        ax.scatter(st["force_N"][sel], st["sigma_inner_Pa"][sel] / 1e6, s=4, marker=marker,
                   color="C3", alpha=0.5, zorder=3, label=f"events with {who}: inner")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("peak contact force F, N")
    ax.set_ylabel("peak σ1, MPa")
    ax.legend(fontsize=7, loc="upper left")
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
