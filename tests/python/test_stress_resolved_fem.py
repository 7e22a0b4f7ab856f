"""The resolved contact FEM (demfem.stress.resolved_fem): its convergence on the Hertz
half-space (issue 39), its loads and its refusals.

The convergence study is the small case of docs/stress-verification.md: the Hertz pressure on
a quarter block (20 a wide and deep), three mesh levels; the surface's peak tension must
approach (1 − 2ν)/3 p0 (Johnson 1985 eq. 3.45) and the radial stress at the centre
−(1 + 2ν)/2 p0. About 30–60 s on 2 cores.
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

gmsh = pytest.importorskip("gmsh", reason="the resolved FEM meshes with gmsh (pip install gmsh)")

from demfem.errors import InvalidParameterError  # noqa: E402
from demfem.stress import resolved_fem as rf  # noqa: E402

E, NU = 45e9, 0.22


@pytest.fixture(scope="module")
def block_case():
    patch = rf.sphere_on_flat_patch(45.0, 5.8e-3, E, NU)
    a = patch.contact_radius
    return patch, rf.HalfSpaceBlock(20 * a, 20 * a)


def test_hertz_patch_closed_forms():
    p = rf.crossed_cylinders_patch(45.0, 5.8e-3, E, NU)
    # two equal cylinders crossed at 90°: a sphere of the same radius on a flat
    s = rf.sphere_on_flat_patch(45.0, 5.8e-3, E, NU)
    assert p.contact_radius == pytest.approx(s.contact_radius, rel=1e-12)
    e_star = E / (2 * (1 - NU ** 2))
    assert p.contact_radius ** 3 == pytest.approx(3 * 45.0 * 5.8e-3 / (4 * e_star), rel=1e-12)
    assert p.peak_pressure == pytest.approx(3 * 45.0 / (2 * math.pi * p.contact_radius ** 2))
    # the elliptical solution tends to the circle
    a, b, p0 = rf.elliptical_semi_axes(45.0, 1 / (2 * 5.8e-3), 1 / (2 * 5.8e-3), e_star)
    assert a == pytest.approx(p.contact_radius) and b == pytest.approx(a)
    line = rf.parallel_cylinders_patch(45.0, 20e-3, 5.8e-3, E, NU)
    assert line.peak_pressure == pytest.approx(2 * (45.0 / 20e-3) / (math.pi * line.semi_axis_s))
    assert rf.hertz_surface_radial_stress(np.array([1.0 + 1e-12]), NU)[0] == pytest.approx(
        (1 - 2 * NU) / 3)
    assert rf.hamilton_max_tension(NU, 0.2) == pytest.approx(
        (1 - 2 * NU) / 3 + (4 + NU) * math.pi * 0.2 / 8)


def test_bad_input_names_the_field(block_case):
    patch, body = block_case
    with pytest.raises(InvalidParameterError, match="normal_force"):
        rf.sphere_on_flat_patch(-1.0, 5.8e-3, E, NU)
    with pytest.raises(InvalidParameterError, match="normal_force"):
        rf.sphere_on_flat_patch(float("nan"), 5.8e-3, E, NU)
    with pytest.raises(InvalidParameterError, match="crossing_angle_deg"):
        rf.crossed_cylinders_patch(45.0, 5.8e-3, E, NU, crossing_angle_deg=60.0)
    with pytest.raises(InvalidParameterError, match="grading.growth"):
        rf.Grading(1e-5, 1e-5, 1e-4, growth=3.0)
    with pytest.raises(InvalidParameterError, match="grading.contact_size"):
        rf.Grading(1e-3, 1e-5, 1e-4)  # finer far away than at the contact
    # a grading the mesher cannot make: far too many elements for the limit
    fine = rf.Grading.for_patch(patch, body).scaled(0.05)
    with pytest.raises(InvalidParameterError, match="grading.contact_size.*max_elements"):
        rf.build_mesh(body, patch, fine, max_elements=1e5)
    with pytest.raises(InvalidParameterError, match="grading.contact_size"):
        rf.build_mesh(body, patch, rf.Grading(1e-12, 1e-12, body.depth / 4))


def test_consistent_loads_carry_the_force(block_case):
    patch, body = block_case
    mesh = rf.build_mesh(body, patch, rf.Grading.for_patch(patch, body).scaled(2.0))
    f = rf.contact_loads(mesh, "normal")
    assert f.sum(axis=0) == pytest.approx([0.0, -patch.normal_force / 4, 0.0], abs=1e-9)
    ft = rf.contact_loads(dataclasses.replace(mesh, patch=patch.with_friction(0.2)),
                          "tangential")
    # ∫ μ p dA over the quarter patch
    assert ft[:, 2].sum() == pytest.approx(0.2 * patch.normal_force / 4, rel=2e-3)


def test_half_space_converges_to_hertz(block_case):
    """Three mesh levels (every size and the growth ×1, ×0.7, ×0.5): the surface radial
    stress outside the contact (1.05 a < r < 3 a) converges to (1 − 2ν)/3 p0 (a/r)² (its rms
    error falls at each level, to below 2.5 % of the peak), the peak tension (read on the rim
    of the contact) ends within 5 % of (1 − 2ν)/3 p0 and the radial stress at the centre
    within 3 % of −(1 + 2ν)/2 p0."""
    patch, body = block_case
    a, p0 = patch.contact_radius, patch.peak_pressure
    c = (1 - 2 * NU) / 3
    exact_centre = -(1 + 2 * NU) / 2
    base = rf.Grading.for_patch(patch, body)
    rms, peak, centre, tets = [], [], [], []
    for level in (1.0, 0.7, 0.5):
        mesh = rf.build_mesh(body, patch, base.scaled(level))
        assert mesh.stats["contact_radius_per_edge"] >= 5.0  # elements ≤ a/5 under the load
        res = rf.solve_case(mesh, E, NU)
        nodes = np.unique(mesh.outer_faces)
        X, S = mesh.nodes[nodes], res.stress_normal[nodes]
        r = np.hypot(X[:, 0], X[:, 2])
        ring = (r > 1.05 * a) & (r < 3 * a)
        cx, cz = X[ring, 0] / r[ring], X[ring, 2] / r[ring]
        s_rr = S[ring, 0] * cx * cx + S[ring, 2] * cz * cz + 2 * S[ring, 4] * cx * cz
        rms.append(float(np.sqrt(np.mean((s_rr / p0 - c * (a / r[ring]) ** 2) ** 2))) / c)
        peak.append(res.outer.sigma1_max / p0)
        centre.append(S[int(np.argmin(r)), 0] / p0)  # in-plane radial stress at the centre
        tets.append(len(mesh.tets))
        # the peak sits on the rim of the contact
        assert math.hypot(res.outer.surface_s, res.outer.surface_z) / a == pytest.approx(
            1.0, abs=0.03)
    assert tets[0] < tets[1] < tets[2]
    assert rms[0] > rms[1] > rms[2], rms
    assert rms[2] < 0.025, rms
    assert abs(peak[-1] / c - 1) < 0.05, (peak, c)
    assert abs(centre[-1] / exact_centre - 1) < 0.03, (centre, exact_centre)


def test_richardson():
    h = [1.0, 0.5, 0.25]
    f = [1.0 + 0.4 * x ** 2 for x in h]
    r = rf.richardson(h, f)
    assert r["monotone"] == 1.0
    assert r["order"] == pytest.approx(2.0)
    assert r["extrapolated"] == pytest.approx(1.0)
    assert rf.richardson(h, [1.0, 1.2, 1.1])["monotone"] == 0.0
