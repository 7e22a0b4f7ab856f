"""The self-contained HTML report of an assessment: one file, figures embedded as base64
PNG, no external resources (no scripts, style sheets or fonts from elsewhere)."""
from __future__ import annotations

import base64
import html
import math
from typing import Any

__all__ = ["render_report"]

_CSS = ("body{font-family:sans-serif;max-width:980px;margin:2em auto;color:#222}"
        "table{border-collapse:collapse;margin:0.6em 0}td,th{border:1px solid #bbb;"
        "padding:3px 8px;text-align:left;font-size:0.92em}th{background:#eee}"
        ".warn{background:#fff3cd;border:1px solid #e0c36c;padding:0.5em}"
        "figure{margin:1em 0}figcaption{font-size:0.9em;color:#444}")


def _n(x: Any, digits: int = 3) -> str:
    if x is None:
        return "n/a"
    if isinstance(x, bool):
        return "yes" if x else "no"
    if isinstance(x, int):
        return str(x)
    if isinstance(x, float):
        if not math.isfinite(x):
            return "n/a"
        return f"{x:.{digits}g}"
    return html.escape(str(x))


def _table(rows: list[tuple[str, Any]], head: tuple[str, str] = ("quantity", "value"),
           cls: str = "") -> str:
    body = "".join(f"<tr><td>{html.escape(k)}</td><td>{_n(v)}</td></tr>" for k, v in rows)
    return (f"<table class='{cls}'><tr><th>{head[0]}</th><th>{head[1]}</th></tr>{body}"
            "</table>")


def render_report(risk: dict[str, Any], figures: dict[str, bytes],
                  captions: dict[str, str]) -> str:
    """The report's HTML text from the risk document (``risk.json``'s content), the figures
    ({file name: PNG bytes}) and their captions."""
    s = risk["summary"]
    st = risk["steady_state"]
    parts = ["<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>",
             "<title>demfem assess: breakage risk of the accumulation table</title>",
             f"<style>{_CSS}</style></head><body>",
             "<h1>Breakage risk of glass cartridges on the accumulation table</h1>",
             "<p>demfem assess: calibration &rarr; DEM of the table &rarr; collision events "
             "&rarr; stress model &rarr; Weibull risk. SI units throughout.</p>"]
    for w in risk["warnings"]:
        parts.append(f"<p class='warn'>{html.escape(w)}</p>")
    from demfem.assess.headline import fmt, headline, place_line

    parts.append(f"<p class='headline'><b>{html.escape(headline(s))}</b></p>")
    strength = risk.get("strength", {})
    parts.append("<p>Glass strength: " + html.escape(strength.get(
        "source", "planning assumptions of demfem.risk")) + ".</p>")
    parts.append("<h2>Summary</h2>")
    rows = [
        ("statistics window, s", f"{fmt(st['window_s'][0])} – {fmt(st['window_s'][1])}"),
        ("cartridges on the table (mean over the window)", fmt(s["mean_on_table"])),
        ("cartridges that left through the opening in the window", fmt(s["exits_window"])),
        ("the table's own discharge, cartridges/h", fmt(s["discharge_per_hour"])),
        ("residence time on the table (Little's law), s", fmt(s["residence_time_s"])),
        ("passages (cartridges from insertion to exit) on the table in the window",
         fmt(s["passages_in_window"])),
        ("impact events in the window", fmt(s["n_events_window"])),
        ("collision rate, events/s", fmt(s["event_rate_per_s"])),
        ("probability that one passage breaks", fmt(s["p_passage"])),
        ("largest P of one passage over its time in the window", fmt(s["p_window_max"])),
        ("expected broken per hour at the table's own discharge, 1/h",
         fmt(s["broken_per_hour_table"])),
    ]
    if s.get("throughput_source") == "user":
        rows.append(("expected broken per hour at the throughput given "
                     f"({fmt(s['throughput_per_hour'])}/h), 1/h",
                     fmt(s["broken_per_hour_at_throughput"])))
    rows += [
        ("share of the hazard from the inner surface", fmt(s["inner_share"])),
        *((("by place on the cartridge", place_line(s)),) if place_line(s) else ()),
        ("impacts on walls and gate in the window", fmt(s["n_wall_events_window"])),
        ("share of the hazard from wall and gate impacts", fmt(s["wall_share"])),
        *((f"share of the hazard from the {name.replace('_', ' ')}", fmt(v))
          for name, v in sorted(s.get("wall_share_by_wall", {}).items(), key=lambda kv: -kv[1])),
        ("largest peak contact force in the window, N", fmt(s["max_force_N"])),
        ("largest inner σ1 in the window, MPa", fmt((s["max_sigma_inner_Pa"] or 0) / 1e6)),
        ("largest outer σ1 in the window, MPa", fmt((s["max_sigma_outer_Pa"] or 0) / 1e6)),
    ]
    parts.append(_table(rows, cls="summary"))
    splits = (risk.get("interval") or {}).get("splits") or {}
    if splits:
        names = {"component": "by surface and mechanism", "with": "by place on the table",
                 "place": "by place on the cartridge",
                 "place_surface": "by place on the cartridge and surface"}
        what = {"outer": "outer surface: contact tension (with bending)",
                "inner": "inner surface: bending tension",
                "rim": "rim (the open end: the paper's fire-polish area)",
                "body": "body", "shoulder": "shoulder (the body-shoulder junction)"}
        for place in ("rim", "body", "shoulder"):
            for surf in ("outer", "inner"):
                what[f"{place} {surf}"] = f"{place}, {surf} surface"
        parts.append("<h3>Where the hazard comes from, with 95 % intervals</h3><p>Shares of "
                     "the hourly number from the same gate periods as its interval.</p>")
        for group in ("place", "place_surface", "component", "with"):
            rows_s = []
            for label, d in sorted((splits.get(group) or {}).items(),
                                   key=lambda kv: -(kv[1].get("share") or 0)):
                lo, hi = d.get("share_lower"), d.get("share_upper")
                rng = (f" ({fmt(100 * lo)} – {fmt(100 * hi)} %)" if lo is not None
                       and hi is not None else "")
                rows_s.append((what.get(label, label.replace("_", " ")),
                               f"{fmt(100 * (d.get('share') or 0))} %{rng}"))
            if rows_s:
                parts.append(_table(rows_s, (names[group], "share of the hazard")))
    check = risk.get("period_check") or {}
    if check.get("text") and not check.get("dominated"):
        parts.append("<h3>Rare periods</h3><p>" + html.escape(check["text"]) + "</p>")
    parts.append("<h2>Worst collisions</h2><p>An impact began at least at the minimum "
                 "speed; a contact pressed by the queue began slower but the DEM pressed it to "
                 "at least the force of an impact at that speed.</p>"
                 "<table><tr><th>event</th><th>cartridge – partner</th><th>kind</th>"
                 "<th>time, s</th><th>x, y, m</th><th>v_n, m/s</th><th>F, N</th>"
                 "<th>worst place</th>"
                 "<th>σ1 inner, MPa</th><th>σ1 outer, MPa</th><th>P_k</th></tr>")
    for r in risk["worst_events"]:
        parts.append(f"<tr><td>{r['event']}</td><td>{r['i']} – {html.escape(r['with'])}</td>"
                     f"<td>{html.escape(r.get('kind', 'impact'))}</td>"
                     f"<td>{r['time_s']:.4g}</td><td>{r['x_m']:.3f}, {r['y_m']:.3f}</td>"
                     f"<td>{r['normal_speed_m_per_s']:.3g}</td><td>{r['force_N']:.3g}</td>"
                     f"<td>{html.escape(r.get('place', 'body'))}</td>"
                     f"<td>{r['sigma_inner_Pa'] / 1e6:.3g}</td>"
                     f"<td>{r['sigma_outer_Pa'] / 1e6:.3g}</td><td>{r['p_event']:.3g}</td></tr>")
    parts.append("</table>")
    parts.append("<h2>Steady state</h2>")
    parts.append(f"<p>Statistics are taken over t = {st['window_s'][0]:.4g} – "
                 f"{st['window_s'][1]:.4g} s (the first {st['window_s'][0]:.4g} s are "
                 "discarded as the transient in which the pack forms). Collision rate in the "
                 f"first half of the window {_n(st['rate_first_half_per_s'])}/s, in the second "
                 f"{_n(st['rate_second_half_per_s'])}/s (ratio {_n(st['rate_ratio'])}, Poisson "
                 f"z = {_n(st['poisson_z'])}"
                 + (": for ~10^5 bursty events it flags deviations of a per cent; the "
                    "criterion is the gate periods below" if st.get("criterion") == "periods"
                    else ": " + ("no drift detectable" if st["steady"] else "the rate drifts: "
                                 "the window is not yet steady, lengthen the run"))
                 + "); hazard ratio second/first half "
                 f"{_n(st['hazard_ratio'])}."
                 + (f" Per gate period of {_n(st['period_s'])} s: events "
                    f"{', '.join(str(c) for c in st['period_events'])} (standard error of "
                    f"their mean {100 * st['relative_error']:.1f} %, tolerance "
                    f"{100 * st['tolerance']:.0f} %: "
                    + ("steady" if st["steady"] else "not steady")
                    + "); the hazard per period has a standard error of its mean of "
                    f"{100 * st['hazard_relative_error']:.0f} %: the statistical uncertainty "
                    "of the hourly risk from the window's length."
                    if st.get("criterion") == "periods" else "") + "</p>")
    parts.append("<h2>Figures</h2>")
    for name, png in figures.items():
        b64 = base64.b64encode(png).decode("ascii")
        parts.append(f"<figure><img src=\"data:image/png;base64,{b64}\" alt=\"{name}\" "
                     f"style='max-width:100%'><figcaption>{html.escape(captions.get(name, name))}"
                     "</figcaption></figure>")
    parts.append("<h2>What the numbers rest on</h2><ul>")
    for line in risk["basis"]:
        parts.append(f"<li>{html.escape(line)}</li>")
    parts.append("</ul><h2>Settings</h2>")
    parts.append(_table([(k, v if not isinstance(v, (dict, list)) else str(v))
                         for k, v in risk["settings_flat"].items()], ("setting", "value")))
    parts.append("<p>Files: risk.json (strict JSON: the summary, the steady state, the worst "
                 "collisions, the settings), events.parquet (one row per event) and "
                 "passages.parquet (one row per passage of a cartridge over the table), each "
                 "column named with its SI unit (demfem.assess.load_assessment reads them into "
                 "pandas; --csv writes them as CSV too), events.vtp, cartridges.vtp and "
                 "cartridge_places.vtp (the events at their places on one cartridge; "
                 "ParaView), stages.json (stage record), the figures as PNG.</p></body></html>")
    return "\n".join(parts)
