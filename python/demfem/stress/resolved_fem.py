"""A resolved FEM of one contact on the glass: the reference that verifies :mod:`demfem.stress`.

The superposition model of :mod:`demfem.stress` (Hertz / Hamilton contact field on top of the
shell's bending) is checked here against a static finite-element solution whose mesh is
graded toward the contact, never against the model itself (DESIGN.md, "Stress at a contact").

What is modelled:

* **Bodies** — :class:`HalfSpaceBlock`, a quarter of a block much larger than the contact (the
  sanity check of the FEM itself: the surface stresses of Hertz and Hamilton are known in
  closed form), and :class:`TubeSegment`, a quarter of the cartridge body (a straight glass
  tube, the default cartridge's radii) loaded at mid-length.
* **Load** — the Hertz pressure of the contact, :class:`HertzPatch` (elliptical/circular for
  crossed cylinders or a sphere on a flat, a line contact of finite length for parallel
  bodies), plus a sliding traction q = μ p along the tube's axis, applied as consistent nodal
  forces (the traction integrated against the element's shape functions, the edge of the
  contact where p has its square-root fall resolved by subdividing the triangles).
* **Symmetry** — the contact centre sits on the planes x = 0 and z = 0 (z: the tube axis,
  y: the load direction). The normal pressure is symmetric about both, the axial traction
  symmetric about x = 0 and antisymmetric about z = 0, so two solves of the quarter model (the
  normal part with u_z = 0 on z = 0, the traction part with u_x = u_y = 0 there) give the
  whole body by superposition: at the image point (x, y, −z) the stress is the mirror of
  σ_N − σ_T, whose principal values are those of σ_N − σ_T at (x, y, z).
* **Support** — the block is clamped at its base (≥ 20 a below the contact, which moves the
  contact stresses by O((a/depth)²)). The tube is free: the contact force is balanced by the
  d'Alembert force of its rigid-body acceleration (*inertia relief*, what holds a cartridge
  during an impact): the load's projection on the rigid-body modes the symmetry allows is
  removed by a body force −ρ(ä + α × r), and the remaining rigid modes are fixed at a few
  far-end dofs whose reactions are then zero (checked). Optionally an identical contact on the
  opposite side (a cartridge squeezed between two neighbours) instead.
* **Quasi-static** — a contact lasts 30–100 µs; the local shell mode under the contact
  (stiffness k_R = 4 E t² / (R √(3(1−ν²))), the mass of the wall within a bending length)
  has a period of ≈ 5 µs, so the local field follows the force. (The tube's global
  ovalising ring mode, ≈ 45 µs, does not: see docs/stress-verification.md.)

Stresses: linear tets (demfem's Tet4, :func:`demfem._core.fem_solve_static`). Their element
stresses cannot show the tension at the rim of a Hertz contact, which lives in a layer a few
hundredths of a deep; the surface stresses are recovered from the surface's displacements
instead (:func:`surface_fit_stresses`: local quadratic fits, one-sided across the rim, Hooke's
law with the known normal stress), evaluated on the rim itself (:func:`rim_points`) and
smoothed along it. The volume-averaged nodal stresses are reported beside them. A mesh study
multiplies every size and the growth rate of the grading by a level factor
(:meth:`Grading.scaled`; :func:`richardson` for the extrapolation). The peer computation is
CalculiX 2.20 with quadratic tets (C3D10) on a mesh of the same geometry and grading
(:func:`run_calculix_case`). docs/stress-verification.md has the study and its numbers.

Effective area: A_eff = ∫ ⟨σ1/σ1,max⟩^m dA over the whole surface (tensile part only; σ1 the
largest principal stress of the surface node, linearly — quadratically for C3D10 —
interpolated over each surface triangle; σ1 the largest in-plane principal stress), m² (ASTM
C1683 with the maximum-principal-stress criterion).

Modules, one concept each: :mod:`~demfem.stress.fem_patch` (the Hertz patches and their
closed forms), :mod:`~demfem.stress.fem_mesh` (bodies, grading, the gmsh mesh),
:mod:`~demfem.stress.fem_quadrature` (shape functions and quadrature),
:mod:`~demfem.stress.fem_load` (nodal loads, symmetry planes, inertia relief),
:mod:`~demfem.stress.fem_recovery` (surface-stress recovery, peaks, effective areas),
:mod:`~demfem.stress.calculix_deck` (the CalculiX deck and .frd); this module holds the solves
(:func:`solve_frictions`, :func:`solve_case`, :func:`run_calculix_case`), :func:`richardson`
and re-exports the public names of the others.

Units: SI (m, N, Pa). gmsh (PyPI ``gmsh``) is needed for meshing, ``ccx`` (Debian
``calculix-ccx``) for the CalculiX side; neither is imported until used.
"""
from __future__ import annotations

import math
import os
import shutil
import subprocess
import tempfile
import time
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Optional, Sequence

import numpy as np

from demfem.errors import DemfemError, InvalidParameterError, NumericalError, check_range
from demfem.stress.calculix_deck import read_frd, read_frd_stresses, write_calculix_deck
from demfem.stress.fem_load import (
    Load,
    contact_loads,
    contact_side,
    support_with_inertia_relief,
    surface_pressure,
)
from demfem.stress.fem_mesh import (
    Body,
    Grading,
    HalfSpaceBlock,
    ResolvedMesh,
    TubeSegment,
    build_mesh,
    estimate_elements,
    surface_coordinates,
)
from demfem.stress.fem_patch import (
    HertzPatch,
    check_material,
    crossed_cylinders_patch,
    effective_modulus_same,
    elliptical_semi_axes,
    hamilton_max_tension,
    hertz_surface_radial_stress,
    parallel_cylinders_patch,
    sphere_on_flat_patch,
)
from demfem.stress.fem_recovery import (
    RIM_FOURIER_ORDER,
    SurfacePeak,
    in_plane_sigma1,
    nodal_average,
    rim_points,
    surface_fit_stresses,
    surface_peak,
)

__all__ = [
    "HalfSpaceBlock",
    "TubeSegment",
    "HertzPatch",
    "Grading",
    "ResolvedMesh",
    "SurfacePeak",
    "ResolvedResult",
    "sphere_on_flat_patch",
    "crossed_cylinders_patch",
    "parallel_cylinders_patch",
    "effective_modulus_same",
    "build_mesh",
    "solve_case",
    "solve_frictions",
    "richardson",
    "write_calculix_deck",
    "read_frd",
    "read_frd_stresses",
    "surface_fit_stresses",
    "rim_points",
    "in_plane_sigma1",
    "contact_loads",
    "run_calculix_case",
    "hertz_surface_radial_stress",
    "hamilton_max_tension",
    "elliptical_semi_axes",
    "estimate_elements",
    "surface_coordinates",
    "surface_pressure",
    "contact_side",
    "nodal_average",
    "surface_peak",
    "RIM_FOURIER_ORDER",
    "Body",
    "Load",
]


# --------------------------------------------------------------------------------------------
# solve
# --------------------------------------------------------------------------------------------


@dataclass
class ResolvedResult:
    """The resolved FEM of one case.

    ``outer``/``inner``: the surface peaks of the primary recovery (``inner`` None on a
    block): for demfem the surface fit (:func:`surface_fit_stresses`), for CalculiX its own
    nodal stresses; ``alternatives``: the same from the other recoveries by name ("nodal_average"
    for demfem, "surface_fit" for CalculiX); ``stress_*``: the primary in-plane surface
    stresses of the two load parts (N, 6; xx, yy, zz, yz, xz, xy, Pa); ``displacement_*``
    (N, 3) m; the mesh's stats and the wall times (s).
    """

    mesh: ResolvedMesh
    outer: SurfacePeak
    inner: Optional[SurfacePeak]
    alternatives: dict[str, tuple[SurfacePeak, Optional[SurfacePeak]]]
    stress_normal: np.ndarray
    stress_tangential: Optional[np.ndarray]
    displacement_normal: np.ndarray
    displacement_tangential: Optional[np.ndarray]
    times: dict[str, float]
    support: dict[str, float]

    def as_dict(self) -> dict[str, Any]:
        def d(x: Optional[SurfacePeak]) -> Optional[dict[str, Any]]:
            return None if x is None else x.as_dict()

        return {"outer": d(self.outer), "inner": d(self.inner),
                "alternatives": {k: {"outer": d(o), "inner": d(i)}
                                 for k, (o, i) in self.alternatives.items()},
                "mesh": self.mesh.stats, "times_s": self.times, "support": self.support}


def _fit_window(mesh: ResolvedMesh, outer: bool) -> float:
    """The smallest fit radius: a tenth of the contact radius on the loaded surface (the
    field's scale there), a tenth of the wall on the inner surface."""
    if outer:
        return 0.1 * mesh.patch.contact_radius
    return 0.1 * mesh.body.thickness if isinstance(mesh.body, TubeSegment) else 0.0


@dataclass
class _SurfaceFields:
    """In-plane surface stresses per load part (the tangential one for μ = 1): at the outer
    surface's nodes, at its rim points, at the inner surface's nodes (N, 6 / k, 6; Pa)."""

    outer: dict[str, np.ndarray]
    rim: dict[str, np.ndarray]
    inner: dict[str, np.ndarray]
    rim_points: np.ndarray


def _surface_fields(mesh: ResolvedMesh, E: float, nu: float,
                    u: dict[str, np.ndarray]) -> _SurfaceFields:
    snn = -surface_pressure(mesh, mesh.nodes)
    rim = rim_points(mesh)
    fo: dict[str, np.ndarray] = {}
    fr: dict[str, np.ndarray] = {}
    fi: dict[str, np.ndarray] = {}
    for part, up in u.items():
        # a line contact's strip (2b ≈ 40–60 µm) is narrower than the elements: no sides
        fo[part], fr[part] = surface_fit_stresses(
            mesh, up, mesh.outer_faces, E, nu, snn if part == "normal" else None,
            window=_fit_window(mesh, True), rim="outside" if part == "normal" else "inside",
            extra_points=rim, one_sided=mesh.patch.kind == "ellipse")
        if len(mesh.inner_faces):
            fi[part], _ = surface_fit_stresses(
                mesh, up, mesh.inner_faces, E, nu, None, window=_fit_window(mesh, False),
                one_sided=False)
    return _SurfaceFields(fo, fr, fi, rim)


def _peaks_at(mesh: ResolvedMesh, f: _SurfaceFields, mu: float, m_outer: float,
              m_inner: float, recovery: str
              ) -> tuple[SurfacePeak, Optional[SurfacePeak]]:
    """Surface peaks at friction ``mu`` (the tangential fields scale with μ)."""
    t_out = mu * f.outer["tangential"] if mu > 0 else None
    t_rim = mu * f.rim["tangential"] if mu > 0 else None
    outer = surface_peak(mesh, mesh.outer_faces, f.outer["normal"], t_out, m_outer, recovery,
                         f.rim_points, f.rim["normal"], t_rim)
    inner = None
    if len(mesh.inner_faces):
        t_in = mu * f.inner["tangential"] if mu > 0 else None
        inner = surface_peak(mesh, mesh.inner_faces, f.inner["normal"], t_in, m_inner,
                             recovery)
    return outer, inner


def _check_frictions(frictions: Optional[Sequence[float]], mesh: ResolvedMesh) -> list[float]:
    if frictions is None:
        return [float(mesh.patch.friction)]
    out = [check_range("friction", m, 0.0, 1.0, lo_open=False, hi_open=False)
           for m in frictions]
    if not out:
        raise InvalidParameterError("invalid frictions = []: give at least one coefficient")
    return out


def _unit_traction_mesh(mesh: ResolvedMesh) -> ResolvedMesh:
    return replace(mesh, patch=mesh.patch.with_friction(1.0))


def solve_frictions(mesh: ResolvedMesh, E: float, nu: float,
                    frictions: Optional[Sequence[float]] = None, *, m_outer: float = 6.0,
                    m_inner: float = 10.0) -> dict[float, ResolvedResult]:
    """Static demfem solves (Tet4, :func:`demfem._core.fem_solve_static`) of the normal part
    and, when some μ > 0, of the tangential part for μ = 1 (scaled by each μ: linear
    elasticity); per friction coefficient (default: the patch's) the σ1 peaks and effective
    areas on the outer (loaded) and inner surface from the surface-fit recovery
    (:func:`surface_fit_stresses`), and for comparison from volume-averaged nodal stresses."""
    from demfem._core import fem_element_stresses, fem_solve_static

    E, nu = check_material(E, nu)
    if mesh.order != 1:
        raise InvalidParameterError(f"invalid mesh.order = {mesh.order!r}: demfem's static "
                                    "solve takes linear tets (order 1)")
    mus = _check_frictions(frictions, mesh)
    times: dict[str, float] = {}
    parts: list[Load] = ["normal", "tangential"] if max(mus) > 0 else ["normal"]
    averaged: dict[str, np.ndarray] = {}
    disp: dict[str, np.ndarray] = {}
    support: dict[str, float] = {}
    F = mesh.patch.normal_force
    unit = _unit_traction_mesh(mesh)
    for part in parts:
        t0 = time.perf_counter()
        f = contact_loads(unit, part)
        fixed, values, f2, info = support_with_inertia_relief(mesh, part, f)
        times[f"loads_{part}"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        u, reac = fem_solve_static(mesh.nodes, mesh.tets, E, nu, f2,
                                   fixed.astype(np.int64), values)
        times[f"solve_{part}"] = time.perf_counter() - t0
        if "relief_dofs" in info:
            k = int(info["relief_dofs"])
            r_relief = np.abs(np.asarray(reac)[fixed[-k:, 0], fixed[-k:, 1]]).max()
            info["relief_reaction_N"] = float(r_relief)
            if r_relief > 1e-6 * F:
                raise NumericalError(f"inertia relief left a reaction of {r_relief:.3g} N "
                                     f"(force {F:g} N) at the far-end dofs")
        support.update({f"{part}_{k}": v for k, v in info.items()})
        disp[part] = np.asarray(u)
        t0 = time.perf_counter()
        se = np.asarray(fem_element_stresses(mesh.nodes, mesh.tets, E, nu, u))
        averaged[part] = nodal_average(mesh.nodes, mesh.tets, se)
        times[f"stress_{part}"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    fields = _surface_fields(mesh, E, nu, disp)
    times["surface_fit"] = time.perf_counter() - t0
    avg = _SurfaceFields(averaged, {}, averaged, np.zeros((0, 3)))
    times["mesh"] = mesh.stats.get("mesh_time_s", math.nan)
    times["total"] = sum(times.values())
    out: dict[float, ResolvedResult] = {}
    for mu in mus:
        mesh_mu = replace(mesh, patch=mesh.patch.with_friction(mu))
        outer, inner = _peaks_at(mesh_mu, fields, mu, m_outer, m_inner, "surface_fit")
        avg_mu = _SurfaceFields(avg.outer, {"normal": np.zeros((0, 6)),
                                            "tangential": np.zeros((0, 6))},
                                avg.inner, avg.rim_points)
        on, inn = _peaks_at(mesh_mu, avg_mu, mu, m_outer, m_inner, "nodal_average")
        st = mu * (fields.outer["tangential"] + fields.inner.get("tangential", 0.0)) \
            if mu > 0 else None
        sn = fields.outer["normal"] + fields.inner.get("normal", 0.0)
        out[mu] = ResolvedResult(mesh_mu, outer, inner, {"nodal_average": (on, inn)}, sn, st,
                                 disp["normal"], mu * disp["tangential"] if mu > 0 else None,
                                 dict(times), dict(support))
    return out


def solve_case(mesh: ResolvedMesh, E: float, nu: float, *, m_outer: float = 6.0,
               m_inner: float = 10.0) -> ResolvedResult:
    """:func:`solve_frictions` at the patch's own friction coefficient."""
    return solve_frictions(mesh, E, nu, None, m_outer=m_outer, m_inner=m_inner)[
        float(mesh.patch.friction)]


def richardson(h: Sequence[float], f: Sequence[float]) -> dict[str, float]:
    """Richardson extrapolation of three values ``f`` on meshes of sizes ``h`` (any
    consistent measure, coarse to fine; constant ratio assumed from the first pair): the
    observed order p, the extrapolated value and whether the sequence converges monotonically
    (when not, ``extrapolated`` is the finest value and ``monotone`` 0)."""
    if len(h) != 3 or len(f) != 3:
        raise InvalidParameterError("invalid h, f: Richardson extrapolation takes three levels")
    h1, h2, h3 = map(float, h)
    f1, f2, f3 = map(float, f)
    d1, d2 = f1 - f2, f2 - f3
    r = h1 / h2
    r2 = h2 / h3
    if d1 == 0 or d2 == 0 or d1 * d2 < 0 or abs(d2) >= abs(d1):
        return {"order": math.nan, "extrapolated": f3, "monotone": 0.0,
                "change_last_pct": 100.0 * abs(d2) / abs(f3) if f3 else math.nan}
    # solve d1/d2 = (r^p - 1)/(1 - r2^-p) · r2^p ... for a constant ratio: (d1/d2) = r^p
    p = math.log(d1 / d2) / math.log(math.sqrt(r * r2))
    ext = f3 - d2 / (r2 ** p - 1.0)
    return {"order": p, "extrapolated": ext, "monotone": 1.0,
            "change_last_pct": 100.0 * abs(d2) / abs(f3) if f3 else math.nan}


# --------------------------------------------------------------------------------------------
# CalculiX
# --------------------------------------------------------------------------------------------


def run_calculix_case(mesh: ResolvedMesh, E: float, nu: float,
                      frictions: Optional[Sequence[float]] = None, *, m_outer: float = 6.0,
                      m_inner: float = 10.0, threads: int = 2,
                      workdir: Optional[str | os.PathLike[str]] = None,
                      ccx: str = "ccx", timeout: float = 1800.0) -> dict[float, ResolvedResult]:
    """The same case in CalculiX (``mesh`` of order 2: C3D10): the same consistent nodal
    loads, symmetry planes and inertia relief as :func:`solve_frictions`, one ccx run per
    load part (the tangential one at μ = 1, scaled). Per friction coefficient: primary result
    CalculiX's own nodal stresses (their in-plane part at the surface); alternative
    "surface_fit": :func:`surface_fit_stresses` on CalculiX's displacements."""
    exe = shutil.which(ccx)
    if exe is None:
        raise DemfemError(f"CalculiX not found ({ccx!r}): apt-get install calculix-ccx")
    E, nu = check_material(E, nu)
    mus = _check_frictions(frictions, mesh)
    parts: list[Load] = ["normal", "tangential"] if max(mus) > 0 else ["normal"]
    tmp = None
    if workdir is None:
        tmp = tempfile.TemporaryDirectory(prefix="resolved_ccx_")
        workdir = tmp.name
    wd = Path(workdir)
    wd.mkdir(parents=True, exist_ok=True)
    times: dict[str, float] = {}
    stresses: dict[str, np.ndarray] = {}
    disp: dict[str, np.ndarray] = {}
    support: dict[str, float] = {}
    unit = _unit_traction_mesh(mesh)
    try:
        for part in parts:
            t0 = time.perf_counter()
            f = contact_loads(unit, part)
            fixed, _, f2, info = support_with_inertia_relief(mesh, part, f)
            support.update({f"{part}_{k}": v for k, v in info.items()})
            deck = write_calculix_deck(mesh, E, nu, f2, fixed, f"resolved contact, {part}")
            (wd / f"{part}.inp").write_text(deck)
            times[f"deck_{part}"] = time.perf_counter() - t0
            env = dict(os.environ, OMP_NUM_THREADS=str(threads),
                       NUMBER_OF_CPUS=str(threads))
            t0 = time.perf_counter()
            proc = subprocess.run([exe, "-i", part], cwd=wd, env=env, capture_output=True,
                                  text=True, timeout=timeout)
            times[f"ccx_{part}"] = time.perf_counter() - t0
            if proc.returncode != 0 or not (wd / f"{part}.frd").exists():
                raise DemfemError(f"ccx failed on {wd / (part + '.inp')}: "
                                  f"{proc.stdout[-2000:]}{proc.stderr[-2000:]}")
            t0 = time.perf_counter()
            res = read_frd(wd / f"{part}.frd", len(mesh.nodes))
            stresses[part], disp[part] = res["S"], res["U"]
            times[f"read_{part}"] = time.perf_counter() - t0
    finally:
        if tmp is not None:
            tmp.cleanup()
    t0 = time.perf_counter()
    fields = _surface_fields(mesh, E, nu, disp)
    times["surface_fit"] = time.perf_counter() - t0
    times["mesh"] = mesh.stats.get("mesh_time_s", math.nan)
    times["total"] = sum(times.values())
    own = _SurfaceFields(stresses, {"normal": np.zeros((0, 6)), "tangential": np.zeros((0, 6))},
                         stresses, np.zeros((0, 3)))
    out: dict[float, ResolvedResult] = {}
    for mu in mus:
        mesh_mu = replace(mesh, patch=mesh.patch.with_friction(mu))
        outer, inner = _peaks_at(mesh_mu, own, mu, m_outer, m_inner, "calculix")
        of, inf_ = _peaks_at(mesh_mu, fields, mu, m_outer, m_inner, "surface_fit")
        out[mu] = ResolvedResult(mesh_mu, outer, inner, {"surface_fit": (of, inf_)},
                                 stresses["normal"],
                                 mu * stresses["tangential"] if mu > 0 else None,
                                 disp["normal"], mu * disp["tangential"] if mu > 0 else None,
                                 dict(times), dict(support))
    return out
