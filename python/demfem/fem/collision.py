"""The two-cartridge collision of the paper's Fig. 2b and Fig. 3: one cartridge upright,
the other tilted about the line of centres, closing at a given speed; the peak contact
force, the contact duration and the restitution from an explicit FEM run with contact.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any, Optional

import numpy as np

from demfem.cartridge import Cartridge
from demfem.contact import ContactBody, hertz_contact_duration
from demfem.errors import InvalidParameterError, check_positive, check_range
from demfem.fem.mesh import cartridge_shell_mesh, cartridge_tet_mesh, rotation_about
from demfem.fem.model import Body, ContactOptions, FemModel
from demfem.fem.result import FemResult, moving_average
from demfem.materials import Material


@dataclass(frozen=True)
class CollisionResult:
    """Outcome of :func:`collide_cartridges`.

    ``max_force`` (N): peak of the normal contact force after a centred moving average over
    1/20 of the contact (the raw peak, which carries the nodes' ringing, is ``raw_max_force``);
    ``contact_duration`` (s); ``restitution``: −(relative normal speed after)/(before);
    ``time`` (s) and ``force`` (N): the force history; ``wall_time`` (s); ``result``: the
    full :class:`FemResult`; ``n_elements``; ``dt`` (s).
    """

    max_force: float
    raw_max_force: float
    contact_duration: float
    restitution: float
    time: np.ndarray
    force: np.ndarray
    wall_time: float
    n_elements: int
    dt: float
    energy_balance_error: float
    result: FemResult
    peak_sigma1_inner: float = float("nan")
    peak_sigma1_outer: float = float("nan")


def _division_deg(mesh) -> float:
    """The angle between neighbouring node columns of a revolved mesh, degrees."""
    r = np.hypot(mesh.nodes[:, 0], mesh.nodes[:, 1])
    outer = mesh.nodes[r > r.max() * (1 - 1e-9)]
    th = np.unique(np.round(np.degrees(np.arctan2(outer[:, 1], outer[:, 0])) % 360.0, 9))
    return float(np.min(np.diff(th))) if th.size > 1 else 0.0


def collide_cartridges(a: Optional[Cartridge] = None, b: Optional[Cartridge] = None,
                       material: Optional[Material] = None, v_rel: float = 0.2,
                       tilt_deg: float = 90.0, layers: int = 2, elements: str = "tet",
                       target_size: Optional[float] = None, friction: float = 0.2,
                       penalty_scale: float = 1.0, progress: bool = False,
                       stress_samples: int = 0) -> CollisionResult:
    """Collide two cartridges and measure the contact.

    Cartridge ``a`` stands upright (axis z), centred on the middle of its cylindrical body
    at the origin. Cartridge ``b`` sits beside it along x, its axis turned by ``tilt_deg``
    degrees about the line of centres (x): 0 gives parallel tubes side by side (a line
    contact along the bodies), 90 crossed tubes (a point contact, the paper's Fig. 2b
    configuration). ``b`` closes on ``a`` at ``v_rel`` (m/s) along x; no gravity, no belt.
    ``material`` defaults to ``a``'s glass. ``layers``: elements through the wall.
    ``stress_samples``: how many times over the expected contact to sample σ1 on ``a``'s
    surfaces (0: not at all). ``elements``: "tet" (``layers`` through the wall) or "shell"
    (mid-surface triangles; contact on both faces, half the wall thickness off the
    mid-surface; σ1 on the inner and outer faces).
    """
    a = a or Cartridge()
    b = b or a
    mat = material or a.material
    v_rel = check_range("v_rel", v_rel, 1e-6, 100.0)
    tilt = check_range("tilt_deg", tilt_deg, 0.0, 90.0, lo_open=False, hi_open=False)
    if elements not in ("tet", "shell"):
        raise InvalidParameterError(f"invalid elements = {elements!r}: must be 'tet' or 'shell'")
    shell = elements == "shell"
    ma: Any
    mb: Any
    if shell:
        ma = cartridge_shell_mesh(a, target_size=target_size)
        mb = cartridge_shell_mesh(b, target_size=target_size)
    else:
        ma = cartridge_tet_mesh(a, layers=layers, target_size=target_size)
        mb = cartridge_tet_mesh(b, layers=layers, target_size=target_size)
    # Turn each tube about its own axis by half a division, so a face (not an edge of the
    # faceted surface) faces the other tube: node-to-surface contact does not see two
    # edges crossing (that needs edge-to-edge contact, which demfem does not have).
    ma = ma.placed(rotation_about((0.0, 0.0, 1.0), 0.5 * _division_deg(ma)))
    mb = mb.placed(rotation_about((0.0, 0.0, 1.0), 180.0 + 0.5 * _division_deg(mb)))
    za, zb = 0.5 * a.body_length, 0.5 * b.body_length
    if shell:
        # A shell has no nodes through the wall, only rings on the mid-surface: centre each
        # on its node ring nearest the body's middle, so that the crossed tubes meet with
        # nodes of each on the other's faces (face centres against face centres would be an
        # edge-to-edge crossing, which node-to-surface contact does not see).
        za, zb = (float(min(np.unique(m.nodes[:, 2]), key=lambda z: abs(z - zc)))
                  for m, zc in ((ma, za), (mb, zb)))
    ra, rb = 0.5 * a.body_outer_diameter, 0.5 * b.body_outer_diameter
    gap = 1e-3 * min(a.wall_thickness, b.wall_thickness)
    mesh_a = ma.placed(None, (0.0, 0.0, -za))
    rot = rotation_about((1.0, 0.0, 0.0), tilt)
    # b is centred on its body's middle, turned about x, then moved out along x.
    mesh_b = mb.placed(None, (0.0, 0.0, -zb)).placed(rot, (ra + rb + gap, 0.0, 0.0))
    # The faceted surfaces lie inside the circles: close the extra clearance so that the
    # meshes start `gap` apart along x (shells: their contact surfaces, half the wall
    # thickness off the mid-surface nodes).
    offset = 0.5 * (a.wall_thickness + b.wall_thickness) if shell else 0.0
    shift = float(mesh_b.nodes[:, 0].min() - mesh_a.nodes[:, 0].max()) - gap - offset
    mesh_b = mesh_b.placed(None, (-shift, 0.0, 0.0))
    model = FemModel(
        bodies=[Body(mesh_a, name="a"), Body(mesh_b, velocity=(-v_rel, 0.0, 0.0), name="b")],
        material=mat, contact=ContactOptions(penalty_scale=penalty_scale, friction=friction,
                                             output_interval=5))
    # Run about three Hertz contact times of the equivalent spheres (stopped earlier once
    # the bodies have separated).
    ca = ContactBody.from_cartridge(dataclasses.replace(a, material=mat))
    t_est = hertz_contact_duration(ca, ca, v_rel)
    dt = model.dt_step
    gap_time = gap / v_rel
    duration = gap_time + 4.0 * t_est
    seen = {"on": False, "last": 0.0}
    # a's surface nodes on its cylindrical body (away from the ends), inner and outer.
    r_a = np.hypot(mesh_a.nodes[:, 0], mesh_a.nodes[:, 1])
    body_a = np.abs(mesh_a.nodes[:, 2]) < 0.45 * a.body_length
    r_body = r_a[body_a]
    inner = np.nonzero(body_a & (r_a < r_body.min() * (1 + 1e-9)))[0]
    outer = np.nonzero(body_a & (r_a > r_body.max() * (1 - 1e-9)))[0]
    peaks = {"inner": 0.0, "outer": 0.0, "next": 0.0}
    every = t_est / stress_samples if stress_samples > 0 else math.inf
    if shell:
        # a's triangles on its cylindrical body, and which of their faces is the outer one.
        tri = mesh_a.triangles
        cen = mesh_a.nodes[tri].mean(axis=1)
        on_body = np.nonzero(np.abs(cen[:, 2]) < 0.45 * a.body_length)[0]
        normals = np.asarray(model.solver.triangle_normals())[on_body]
        radial = cen[on_body] * np.array([1.0, 1.0, 0.0])
        top_out = np.einsum("ij,ij->i", normals, radial) > 0

    def sample_stress(m: FemModel) -> None:
        if m.time < peaks["next"]:
            return
        peaks["next"] = m.time + every
        if shell:
            s = np.asarray(m.solver.surface_sigma1())[on_body]
            out_s = np.where(top_out, s[:, 2], s[:, 0])
            in_s = np.where(top_out, s[:, 0], s[:, 2])
            peaks["inner"] = max(peaks["inner"], float(in_s.max(initial=0.0)))
            peaks["outer"] = max(peaks["outer"], float(out_s.max(initial=0.0)))
            return
        from demfem import _core
        ns = np.asarray(m.solver.nodal_stresses())[: mesh_a.n_nodes]
        p, _ = _core.fem_stress_invariants(np.ascontiguousarray(ns[np.concatenate([inner, outer])]))
        s1 = np.asarray(p)[:, 0]
        peaks["inner"] = max(peaks["inner"], float(s1[: inner.size].max(initial=0.0)))
        peaks["outer"] = max(peaks["outer"], float(s1[inner.size:].max(initial=0.0)))

    def separated(m: FemModel) -> bool:
        if stress_samples > 0 and seen["on"]:
            sample_stress(m)
        # Apart: no contact for a fifth of the expected duration while opening (a contact
        # that chatters off for a few steps near the peak is not a separation).
        info = m.solver.contact_info() or {}
        if info.get("active_contacts", 0) > 0:
            seen["on"], seen["last"] = True, m.time
            return False
        if not seen["on"] or m.time - seen["last"] < 0.2 * t_est:
            return False
        rel = m.body_velocity(1)[0] - m.body_velocity(0)[0]
        return rel > 0.0

    import time as _time
    t_wall = _time.perf_counter()
    res = model.run(duration, progress=progress, stop_when=separated)
    wall = _time.perf_counter() - t_wall
    fn, _ = res.pair_force("a", "b")
    on = np.nonzero(fn > 0)[0]
    if on.size == 0:
        raise InvalidParameterError(
            f"the cartridges did not touch within {duration:g} s (v_rel = {v_rel} m/s)")
    t_c = float(res.time[on[-1]] - res.time[on[0]] + (res.time[1] - res.time[0]))
    w = max(1, int(round(t_c / 20.0 / (res.time[1] - res.time[0]))))
    smooth = moving_average(fn, w)
    rel_after = model.body_velocity(1)[0] - model.body_velocity(0)[0]
    return CollisionResult(
        max_force=float(smooth.max()), raw_max_force=float(fn.max()), contact_duration=t_c,
        restitution=float(rel_after / v_rel), time=res.time, force=fn, wall_time=wall,
        n_elements=model.mesh.n_elements, dt=dt, energy_balance_error=res.energy_balance_error(),
        result=res,
        peak_sigma1_inner=peaks["inner"] if stress_samples > 0 else float("nan"),
        peak_sigma1_outer=peaks["outer"] if stress_samples > 0 else float("nan"))
