"""The cluster's stress submodel: the contact geometry it picks, its values against direct
calls of the verified closed form on independently smoothed forces, and the numbers it
reports twice (cluster_submodel.csv and summary.json) being the same."""
from __future__ import annotations

import csv
import json
import math

import numpy as np
import pytest

from demfem.cartridge import Cartridge
from demfem.errors import DemfemIOError, InvalidParameterError
from demfem.fem.cluster_run import SMOOTH_S, run_cluster
from demfem.fem.cluster_submodel import (SUBMODEL_CSV, contact_geometry, evaluate_submodel,
                                         submodel_from_folder)
from demfem.materials import Material
from demfem.scenes import CartridgeCluster
from demfem.stress import contact_stresses

SOFT = Material(1e8, 0.22, 2230.0, name="soft glass")
TUBE = Cartridge.tube(11.6e-3, 1.1e-3, 10e-3, material=SOFT)


def test_geometry_upright_is_a_line_contact_over_the_facing_bodies():
    c = CartridgeCluster.load_case("max", elements="shell")
    g = contact_geometry(c)
    cart = c.cartridge
    for pair in ("2", "3"):
        bottom, top = g[f"1-{pair}_bottom"], g[f"1-{pair}_top"]
        assert bottom.geometry == top.geometry == "parallel"
        assert bottom.contact_length_m == pytest.approx(0.5 * cart.length)
        assert top.contact_length_m == pytest.approx(cart.body_length - 0.5 * cart.length)
        assert bottom.location == top.location == "body"
    # lifted by 10 mm (upright): its body faces 1's from 10 mm up only
    c = CartridgeCluster.load_case("max", elements="shell", offset_2_z=0.01)
    g = contact_geometry(c)
    assert g["1-2_bottom"].contact_length_m == pytest.approx(0.5 * cart.length - 0.01)
    assert g["1-2_top"].contact_length_m == pytest.approx(cart.body_length - 0.5 * cart.length)


@pytest.mark.parametrize("tilt, offset, lead, where", [
    (-2.0, 0.0, "bottom", "rim"), (2.0, 0.0, "top", "shoulder"), (-2.0, 0.01, "bottom", "body")])
def test_geometry_tilted_is_a_point_contact_at_the_leading_end(tilt, offset, lead, where):
    c = CartridgeCluster.load_case("max", elements="shell", tilt_2_deg=tilt, offset_2_z=offset)
    g = contact_geometry(c)
    k = g[f"1-2_{lead}"]
    assert (k.geometry, k.crossing_angle_deg, k.contact_length_m) == ("crossed", 90.0, None)
    assert k.location == where
    assert k.z_m == pytest.approx(c.first_contact()["2"]["z_m"])
    assert g["1-3_bottom"].geometry == "parallel"  # 3 stays upright


def _read_csv(path):
    with open(path, newline="") as fh:
        rows = list(csv.reader(fh))
    head = rows[0]
    vals = np.array([[float(v) for v in r] for r in rows[1:]])
    return {h: vals[:, i] for i, h in enumerate(head)}


def test_run_writes_the_submodel_and_reports_it_twice_alike(tmp_path):
    """A tiny soft-tube run (2 tilted back so its bottom edge leads, 3 upright): the CSV's
    columns are the closed form at the smoothed forces of forces.csv (smoothed here
    independently), the summary's peaks are the CSV's maxima to the bit, and the peak force
    is the summary's force peak; the folder reader gives the same."""
    c = CartridgeCluster.load_case("max", cartridge=TUBE, elements="shell", springs=True,
                                   tilt_2_deg=-5.0)
    out = tmp_path / "run"
    s = run_cluster(c, duration=3e-4, out=out, progress=False, n_snapshots=2)
    sub = s["submodel"]
    assert json.loads((out / "summary.json").read_text())["submodel"] == sub
    cols = _read_csv(out / SUBMODEL_CSV)
    forces = _read_csv(out / "forces.csv")
    t = cols["time_s"]
    assert np.allclose(t, forces["time_s"], rtol=1e-8, atol=0)  # forces.csv: 9 digits
    w = max(1, int(round(SMOOTH_S / float(np.median(np.diff(t))))))
    for key, entry in sub["pairs"].items():
        pair, region = key[2], key.split("_")[1]
        f = cols[f"normal_force_{key}_N"]
        q = cols[f"tangential_force_{key}_N"]
        # smoothing: a centred moving average over 2 (w // 2) + 1 samples (shorter at the
        # ends); forces.csv has 6 significant digits
        raw = forces[f"fn_1{pair}_{region}_N"]
        ref = np.array([raw[max(0, i - w // 2): i + w // 2 + 1].mean()
                        for i in range(len(raw))])
        assert np.allclose(f, ref, rtol=1e-5, atol=1e-6 * max(1.0, raw.max()))
        # reported twice: the same floats
        for side in ("outer", "inner"):
            col = cols[f"{side}_sigma1_{key}_Pa"]
            assert entry[f"{side}_sigma1_Pa"] == col.max()
            if col.max() > 0:
                k = int(np.argmax(col))
                assert entry[f"{side}_sigma1_time_s"] == t[k]
                assert entry[f"{side}_effective_area_m2"] == cols[f"{side}_effective_area_{key}_m2"][k]
        assert entry["normal_force_N"] == f.max()
        assert entry["normal_force_N"] == pytest.approx(s["force_peaks"][key]["normal_N"],
                                                        rel=1e-12, abs=1e-15)
        # the values are the closed form at those forces, with the chosen geometry
        on = f > 0
        if not np.any(on):
            assert entry["outer_sigma1_Pa"] == 0.0
            continue
        kw = ({"contact_length": entry["contact_length_m"], "ring_support": "opposite"}
              if entry["geometry"] == "parallel" else
              {"crossing_angle_deg": entry["crossing_angle_deg"]})
        direct = contact_stresses(f[on], q[on], geometry=entry["geometry"], cartridge=TUBE,
                                  friction_coefficient=c.friction,
                                  location=entry["model_location"], **kw)
        assert np.array_equal(direct.outer_sigma1_max, cols[f"outer_sigma1_{key}_Pa"][on])
        assert np.array_equal(direct.inner_sigma1_max, cols[f"inner_sigma1_{key}_Pa"][on])
        assert np.all(cols[f"outer_sigma1_{key}_Pa"][~on] == 0.0)
    # 2's bottom edge led: a point contact there, 3 upright: line contacts
    assert sub["pairs"]["1-2_bottom"]["geometry"] == "crossed"
    assert sub["pairs"]["1-2_bottom"]["normal_force_N"] > 0
    assert sub["pairs"]["1-2_top"]["normal_force_N"] == 0.0
    assert sub["pairs"]["1-3_bottom"]["geometry"] == "parallel"
    # its contact is at 1's rim: the rim model where the stress model has one, else the
    # mid-body one and the entry says it is out of its range
    e = sub["pairs"]["1-2_bottom"]
    assert e["location"] == "rim"
    assert (e["model_location"], e["in_model_range"]) in (("rim", True), ("body", False))
    assert sub["inner_sigma1_max_Pa"] == max(e["inner_sigma1_Pa"] for e in sub["pairs"].values())
    # FEM zone values stand beside it
    assert all(math.isfinite(e["fem_zone_inner_sigma1_Pa"]) for e in sub["pairs"].values())
    # the folder reader: the same histories
    again = submodel_from_folder(out)
    assert again.csv_text() == (out / SUBMODEL_CSV).read_text()


def test_bad_input(tmp_path):
    c = CartridgeCluster.load_case("max", elements="shell")
    with pytest.raises(InvalidParameterError, match="time"):
        evaluate_submodel(c, {})
    with pytest.raises(InvalidParameterError, match="fn_12_bottom"):
        evaluate_submodel(c, {"time": np.linspace(0, 1e-4, 5)})
    with pytest.raises(InvalidParameterError, match="CartridgeCluster"):
        evaluate_submodel("max", {"time": np.zeros(3)})  # type: ignore[arg-type]
    with pytest.raises(DemfemIOError, match="run.npz"):
        submodel_from_folder(tmp_path)
    # no contact at all: zeros, not garbage
    t = np.linspace(0, 1e-4, 50)
    zero = {f"{k}_1{p}_{r}": np.zeros_like(t) for k in ("fn", "ft") for p in "23"
            for r in ("bottom", "top")}
    s = evaluate_submodel(c, {"time": t, **zero}).summary()
    assert s["outer_sigma1_max_Pa"] == 0.0 and s["inner_sigma1_max_Pa"] == 0.0


def test_synthetic_pulse_is_smoothed_then_evaluated():
    """A half-sine pulse of 20 N on 1-2 bottom (an upright cluster of the paper's
    cartridges), sampled every 0.5 us: the submodel smooths it over 10 us (21 samples,
    centred) and its peak is the closed form (line contact over half the length, held
    opposite) at the smoothed peak force; the ringing does not reach the stress."""
    c = CartridgeCluster.load_case("max", elements="shell")
    t = np.arange(0, 2e-4, 5e-7)
    pulse = np.where((t > 2e-5) & (t < 1e-4), 20.0 * np.sin(np.pi * (t - 2e-5) / 8e-5), 0.0)
    ringing = np.where(pulse > 0, 5.0 * np.sin(2 * np.pi * t / 1e-6), 0.0)  # node-to-node
    fn = np.maximum(pulse + ringing, 0.0)
    data = {f"{k}_1{p}_{r}": np.zeros_like(t) for k in ("fn", "ft") for p in "23"
            for r in ("bottom", "top")}
    data.update({"time": t, "fn_12_bottom": fn, "ft_12_bottom": 0.1 * fn})
    sub = evaluate_submodel(c, data)
    h = sub.histories["1-2_bottom"]
    ref = np.array([fn[max(0, i - 10): i + 11].mean() for i in range(len(fn))])
    assert np.allclose(h.normal_force, ref, rtol=1e-12, atol=1e-12)
    assert np.allclose(h.tangential_force, 0.1 * ref, rtol=1e-12, atol=1e-12)
    k = int(np.argmax(h.normal_force))
    assert h.normal_force[k] == pytest.approx(20.0, rel=0.05)  # the ringing averaged out
    on = h.normal_force > 0
    direct = contact_stresses(h.normal_force[on], h.tangential_force[on], geometry="parallel",
                              contact_length=0.5 * c.cartridge.length, ring_support="opposite",
                              cartridge=c.cartridge, friction_coefficient=c.friction)
    peaks = sub.summary()["pairs"]["1-2_bottom"]
    # the inner (bending) tension grows with the force: its peak is at the force peak; the
    # outer one (contact tension less the bending compression) need not be
    assert peaks["inner_sigma1_time_s"] == peaks["normal_force_time_s"] == t[k]
    assert peaks["inner_sigma1_Pa"] == pytest.approx(float(direct.inner_sigma1_max.max()),
                                                     rel=1e-12)
    assert peaks["outer_sigma1_Pa"] == pytest.approx(float(direct.outer_sigma1_max.max()),
                                                     rel=1e-12)
    assert sub.summary()["pairs"]["1-3_top"]["inner_sigma1_Pa"] == 0.0


def test_tangential_force_above_coulomb_is_clipped_and_counted():
    """Q above μ F (the run's Coulomb limit, 0.2) is clipped to μ F: by roundoff silently
    (it is the limit), beyond roundoff counted; the closed form never sees Q > μ F."""
    c = CartridgeCluster.load_case("max", elements="shell")
    t = np.arange(0, 5e-4, 2.5e-5)  # samples 25 us apart: no smoothing
    f = np.linspace(1.0, 10.0, len(t))
    q = 0.2 * f * (1 + 1e-13)
    q[::4] = 0.3 * f[::4]
    data = {f"{k}_1{p}_{r}": np.zeros_like(t) for k in ("fn", "ft") for p in "23"
            for r in ("bottom", "top")}
    data.update({"time": t, "fn_13_top": f, "ft_13_top": q})
    h = evaluate_submodel(c, data).histories["1-3_top"]
    assert h.clipped_tangential == len(t[::4])
    assert h.max_friction_ratio == pytest.approx(0.3)
    assert np.all(h.tangential_force <= 0.2 * h.normal_force)
    assert np.all(h.inner_sigma1 > 0)
