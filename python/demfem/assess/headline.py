"""The headline of an assessment, one text for the console, the CLI and the report: the
expected broken cartridges per hour with its 95 % interval, a plain reading (one broken
cartridge every so many hours or days at this throughput), and where the throughput comes
from. Built from ``risk.json``'s summary only, so every place that shows it shows the same
digits."""
from __future__ import annotations

import math
from typing import Any

__all__ = ["headline", "plain_reading", "fmt", "place_line"]


def fmt(x: Any, digits: int = 3) -> str:
    """A number as people read it: plain digits between 0.01 and 10⁶, else a power of ten
    written out (2.4 × 10⁻⁸); ``n/a`` for None or non-finite."""
    if x is None or (isinstance(x, float) and not math.isfinite(x)):
        return "n/a"
    if isinstance(x, (bool,)):
        return "yes" if x else "no"
    if isinstance(x, int):
        return f"{x:,}".replace(",", " ")
    v = float(x)
    if v == 0:
        return "0"
    if 0.01 <= abs(v) < 1e6:
        text = f"{v:.{digits}g}"
        return text if "e" not in text else f"{v:.0f}"
    mant, exp = f"{v:.{digits - 1}e}".split("e")
    sup = str.maketrans("-0123456789", "⁻⁰¹²³⁴⁵⁶⁷⁸⁹")
    return f"{mant} × 10{str(int(exp)).translate(sup)}"


def plain_reading(per_hour: float) -> str:
    """"one broken cartridge every 3.4 days" for ``per_hour`` broken per hour."""
    if not (isinstance(per_hour, (int, float)) and math.isfinite(per_hour)):
        return "not known"
    if per_hour <= 0:
        return "no breakage expected in the simulated window"
    hours = 1.0 / per_hour
    for unit, size in (("years", 24 * 365.25), ("days", 24.0), ("hours", 1.0)):
        if hours >= size:
            return f"one broken cartridge every {fmt(hours / size)} {unit} of operation"
    return f"{fmt(per_hour)} broken cartridges per hour"


def headline(summary: dict[str, Any]) -> str:
    """The headline sentence from ``risk.json``'s summary."""
    s = summary
    value = s["broken_per_hour"]
    ci = s.get("broken_per_hour_ci95")
    interval = (f" (95 % interval {fmt(ci[0])} – {fmt(ci[1])})" if ci and ci[0] is not None
                else "")
    if s.get("throughput_source") == "table":
        at = (f"at {fmt(s['throughput_per_hour'])} cartridges/h (the table's own discharge "
              "in the simulation)" if s["throughput_per_hour"] else
              "on the simulated table (no cartridge left it in the window: its throughput is "
              "unknown)")
    else:
        at = (f"at {fmt(s['throughput_per_hour'])} cartridges/h (the throughput given; the "
              f"simulated table discharges {fmt(s.get('discharge_per_hour'))}/h)")
    return (f"Expected broken cartridges per hour: {fmt(value)}{interval} {at}: "
            f"{plain_reading(value)}. Probability that one cartridge breaks on its passage: "
            f"{fmt(s['p_passage'])}.")


def place_line(summary: dict[str, Any]) -> str:
    """Where on the cartridge the hazard comes from, one line from ``risk.json``'s summary
    (``place_share``): "rim 71 %, body 20 %, shoulder 9 %", largest first; empty without
    places."""
    shares = summary.get("place_share")
    if not shares:
        return ""
    parts = [f"{name} {fmt(100 * v, 3)} %" for name, v in
             sorted(shares.items(), key=lambda kv: -kv[1])]
    return "Where on the cartridge the hazard comes from: " + ", ".join(parts) + "."
