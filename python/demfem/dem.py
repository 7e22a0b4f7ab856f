"""Discrete element method: numpy in, numpy out, around the Rust engine ``DemSimulation``.

Build a simulation from arrays and plain dicts (helpers below), then advance it with
:func:`run`, which reports progress (simulated time, steps per second, ETA) and stops cleanly
on Ctrl-C at a step boundary (``SimulationInterrupted``). SI units: m, kg, s, N, Pa.

Example::

    from demfem import dem
    glass = dem.material(45e9, 0.22, 2230.0, friction=0.2, restitution=0.5)
    belt = dem.plane((0, 0, 0), (0, 0, 1), surface_velocity=(0.2, 0, 0))
    sim = dem.DemSimulation(positions, radii, [glass], [belt],
                            ["gravity", "belt", "friction", "rotation", "damping"])
    dem.run(sim, 1.0, progress=print)
"""
from __future__ import annotations

import time as _time
from dataclasses import dataclass
from typing import Any, Callable, Optional, Sequence

from demfem._core import DemSimulation

__all__ = [
    "DemSimulation",
    "Progress",
    "material",
    "plane",
    "polygon",
    "strip",
    "cuboid",
    "harmonic",
    "constant_velocity",
    "run",
]

Vector = Sequence[float]


def material(
    young_modulus: float,
    poisson_ratio: float,
    density: float,
    *,
    friction: float = 0.0,
    restitution: float = 1.0,
    rolling_friction: float = 0.0,
    shell_stiffness: float = float("inf"),
) -> dict[str, float]:
    """A material dict: E (Pa), ν, ρ (kg/m³), μ, e, μ_r, shell stiffness k_R (N/m, inf = none)."""
    return {
        "young_modulus": young_modulus,
        "poisson_ratio": poisson_ratio,
        "density": density,
        "friction": friction,
        "restitution": restitution,
        "rolling_friction": rolling_friction,
        "shell_stiffness": shell_stiffness,
    }


def _wall(kind: str, material: int, surface_velocity: Optional[Vector], motion: Optional[dict[str, Any]], **geo: Any) -> dict[str, Any]:
    w: dict[str, Any] = {"type": kind, "material": material, **geo}
    if surface_velocity is not None:
        w["surface_velocity"] = tuple(float(x) for x in surface_velocity)
    if motion is not None:
        w["motion"] = motion
    return w


def plane(point: Vector, normal: Vector, *, material: int = 0, surface_velocity: Optional[Vector] = None,
          motion: Optional[dict[str, Any]] = None) -> dict[str, Any]:
    """Infinite plane through ``point`` (m), ``normal`` towards the particles."""
    return _wall("plane", material, surface_velocity, motion, point=tuple(point), normal=tuple(normal))


def polygon(vertices: Sequence[Vector], *, material: int = 0, surface_velocity: Optional[Vector] = None,
            motion: Optional[dict[str, Any]] = None) -> dict[str, Any]:
    """Convex planar polygon (two-sided), vertices (m) in boundary order."""
    return _wall("polygon", material, surface_velocity, motion, vertices=[list(v) for v in vertices])


def strip(x0: float, y0: float, x1: float, y1: float, z_bottom: float, z_top: float, *, material: int = 0,
          motion: Optional[dict[str, Any]] = None) -> dict[str, Any]:
    """Vertical wall strip above the segment (x0, y0)–(x1, y1), from z_bottom to z_top (m)."""
    return _wall("strip", material, None, motion, x0=x0, y0=y0, x1=x1, y1=y1, z_bottom=z_bottom, z_top=z_top)


def cuboid(center: Vector, half_extents: Vector, *, material: int = 0,
           motion: Optional[dict[str, Any]] = None) -> dict[str, Any]:
    """Solid axis-aligned box: centre and half extents (m)."""
    return _wall("cuboid", material, None, motion, center=tuple(center), half_extents=tuple(half_extents))


def harmonic(direction: Vector, amplitude: float, period: float, phase: float = 0.0) -> dict[str, Any]:
    """Wall motion x(t) = x0 + A sin(2π t / T + φ) along ``direction``; A in m, T in s."""
    return {"type": "harmonic", "direction": tuple(direction), "amplitude": amplitude, "period": period, "phase": phase}


def constant_velocity(velocity: Vector) -> dict[str, Any]:
    """Wall motion x(t) = x0 + v t, v in m/s."""
    return {"type": "constant", "velocity": tuple(velocity)}


@dataclass(frozen=True)
class Progress:
    """Progress of a run: simulated time and target (s), speed (steps/s, simulated s per
    wall s) and the estimated wall time left (s)."""

    time: float
    t_end: float
    steps: int
    steps_per_second: float
    simulated_per_wall_second: float
    eta_seconds: float


def run(
    sim: DemSimulation,
    t_end: float,
    *,
    progress: Optional[Callable[[Progress], None]] = None,
    report_every: float = 1.0,
    chunk_steps: int = 2000,
) -> int:
    """Advance ``sim`` to simulated time ``t_end`` (s); call ``progress`` about every
    ``report_every`` wall seconds. Returns the steps taken. Ctrl-C raises
    ``SimulationInterrupted`` with the state consistent at a step boundary."""
    start_steps = sim.steps
    start_wall = _time.perf_counter()
    last_report = start_wall
    total = max(0, int(-(-(t_end - sim.time) // sim.dt)))
    done = 0
    while done < total:
        k = min(chunk_steps, total - done)
        sim.step(k, chunk=k)
        done += k
        now = _time.perf_counter()
        if progress is not None and (now - last_report >= report_every or done == total):
            last_report = now
            elapsed = max(now - start_wall, 1e-12)
            rate = done / elapsed
            progress(Progress(
                time=sim.time,
                t_end=t_end,
                steps=sim.steps,
                steps_per_second=rate,
                simulated_per_wall_second=rate * sim.dt,
                eta_seconds=(total - done) / rate if rate > 0 else float("inf"),
            ))
    return sim.steps - start_steps
