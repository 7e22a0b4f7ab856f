"""Whole-contact events measured in the DEM (``record_events``): a binary impact of two
equivalent cartridges against the calibrated Hertz–Reissner law (peak force, duration and the
impulse momentum fixes), a table run's events against its onsets, their exact resume from a
checkpoint, and their use in the assessment (the minimum-speed rescue by force, the measured
force and half-sine duration in the stress stage)."""
import math
from types import SimpleNamespace

import numpy as np
import pytest

from demfem.analysis.contact_events import CONTACT_EVENT_DTYPE, events_per_partner
from demfem.assess.events import impact_events
from demfem.assess.impact import ImpactLaw, cartridge_body
from demfem.stress.stress_model import StressModel
from demfem.stress.stage import collision_stresses
from demfem.dem import DemSimulation, material
from demfem.scenes import AccumulationTable
from demfem.dem.table_run import run_table

TINY = dict(width=0.1, length=0.1, tilted_wall_length=0.08, opening_width=0.03,
            gate_amplitude=0.01, gate_period=0.2, belt_velocity=0.5, young_modulus=1e7,
            n_spheres=30)


def _binary_impact(v: float, restitution: float = 1.0):
    """Two default equivalent cartridges (45 GPa, Hertz in series with their Reissner
    shells) closing head-on at ``v`` m/s; returns the engine after they parted, and the
    body."""
    body = cartridge_body(45e9)
    r = body.radius
    rho = body.mass / (4.0 / 3.0 * math.pi * r**3)
    mat = material(45e9, body.nu, rho, restitution=restitution,
                   shell_stiffness=body.k_reissner)
    x = r + 1e-7
    sim = DemSimulation(np.array([[-x, 0.0, 0.0], [x, 0.0, 0.0]]), np.array([r, r]), [mat], [],
                        ["damping"] if restitution < 1 else [],
                        velocities=np.array([[v / 2, 0.0, 0.0], [-v / 2, 0.0, 0.0]]),
                        gravity=(0.0, 0.0, 0.0), model="hertz_reissner_mindlin",
                        record_events=True, dt_safety=0.05)
    for _ in range(10_000):
        sim.step(200)
        if len(sim.events()["time"]):
            return sim, body
    raise AssertionError("the contact did not end")


@pytest.mark.parametrize("v", [0.02, 0.2])
def test_a_binary_impact_is_measured_as_the_calibrated_law_says(v):
    sim, body = _binary_impact(v)
    ev = sim.events()
    assert len(ev["time"]) == 1 and bool(ev["complete"][0]) and not ev["partner_is_wall"][0]
    law = ImpactLaw(body, body)
    f, j = float(ev["peak_normal_force"][0]), float(ev["normal_impulse"][0])
    assert f == pytest.approx(float(law.force(np.array([v]))[0]), rel=2e-3)
    assert float(ev["duration"][0]) == pytest.approx(float(law.duration(np.array([v]))[0]),
                                                     rel=5e-3)
    # elastic: the impulse reverses the relative momentum, m* (1 + e) v with m* = m/2
    assert j == pytest.approx(body.mass * v, rel=1e-3)
    # the stress stage's measured path: the measured peak, and the half-sine of the same
    # peak and impulse, which lasts between 0.854 (pure Hertz: pi / (2.94 x 5/4)) and 1 (a
    # linear spring's half-sine) of the series law's pulse
    st = collision_stresses(np.array([v]), np.array([0]), 45e9, model=StressModel.default(),
                            measured_force=np.array([f]), measured_impulse=np.array([j]))
    assert st["force_N"][0] == f and st["law_force_N"][0] == pytest.approx(f, rel=2e-3)
    assert st["duration_s"][0] == pytest.approx(0.5 * math.pi * j / f)
    ratio = st["duration_s"][0] / float(law.duration(np.array([v]))[0])
    assert 0.85 < ratio < 1.0


def test_a_damped_impact_carries_the_momentum_its_restitution_says():
    sim, body = _binary_impact(0.1, restitution=0.5)
    j = float(sim.events()["normal_impulse"][0])
    v_after = float(sim.velocities()[1][0] - sim.velocities()[0][0])
    assert j == pytest.approx(0.5 * body.mass * (0.1 + v_after), rel=2e-3)
    assert v_after == pytest.approx(0.05, rel=0.02)


@pytest.fixture(scope="module")
def tiny_events():
    return run_table(AccumulationTable(**TINY), 0.4, sample_interval=0.02, record_events=True)


def test_a_table_run_logs_every_contact_it_saw(tiny_events):
    run = tiny_events
    e = run.contact_events
    assert run.info["events_recorded"] and e.dtype == CONTACT_EVENT_DTYPE
    # every onset, sphere-sphere and sphere-wall, is one contact event
    assert len(e) == len(run.onsets) + len(run.wall_onsets) > 50
    sphere = e[~e["partner_is_wall"]]
    np.testing.assert_array_equal(np.sort(sphere["time"]), np.sort(run.onsets["time"]))
    done = e[e["complete"]]
    assert np.all(done["duration"] > 0) and np.all(done["peak_normal_force"] > 0)
    # Σ F dt over the steps in contact is at most F_max times the duration
    assert np.all(done["normal_impulse"] <= done["peak_normal_force"] * done["duration"] * 1.000001)
    # the contacts still open at the end reach it
    open_ = e[~e["complete"]]
    assert len(open_) > 0
    end = run.info["steps"] * run.info["dt"]
    assert np.all(np.abs(open_["time"] + open_["duration"] - end) < 1.5 * run.info["dt"]) or \
        np.any(np.isfinite(run.removal_times))
    per = events_per_partner(e, run.info["wall_names"])
    assert per["sphere"]["n_events"] == len(sphere)
    assert sum(v["n_events"] for v in per.values()) == len(e)


def test_events_resume_exactly_from_a_checkpoint(tiny_events, tmp_path):
    class Stop(Exception):
        pass

    def stop(sim_time, steps):
        if sim_time > 0.15:
            raise Stop

    ck = tmp_path / "run.ck"
    with pytest.raises(Stop):
        run_table(AccumulationTable(**TINY), 0.4, sample_interval=0.02, checkpoint=ck,
                  checkpoint_every=1e-9, progress=stop, record_events=True)
    resumed = run_table(AccumulationTable(**TINY), 0.4, sample_interval=0.02, checkpoint=ck,
                        record_events=True)
    assert np.array_equal(resumed.contact_events, tiny_events.contact_events)
    back = type(resumed).load(resumed.save(tmp_path / "run.npz"))
    assert np.array_equal(back.contact_events, tiny_events.contact_events)


def _run_with(events: np.ndarray):
    return SimpleNamespace(contact_events=events, onsets=None, wall_onsets=None,
                           info={"events_recorded": True,
                                 "wall_names": ["belt", "back", "lower_side", "upper_side",
                                                "tilted", "gate"]})


def test_measured_events_keep_hard_pressed_slow_contacts_and_drop_the_belt():
    c = np.zeros(5, CONTACT_EVENT_DTYPE)
    c["i"], c["j"] = [0, 1, 2, 3, 4], [1, 2, 0, 5, 3]
    c["partner_is_wall"] = [False, False, True, True, False]
    c["time"] = [0.1, 0.2, 0.3, 0.4, 0.5]
    c["normal_speed"] = [0.1, 0.001, 0.5, 0.001, 0.001]
    c["peak_normal_force"] = [5.0, 2.0, 9.0, 3.0, 0.01]
    c["normal_impulse"] = [1e-4, 1e-3, 2e-4, 1e-3, 1e-6]
    c["duration"] = [1e-4, 0.1, 1e-4, 0.2, 0.01]
    ev, summary = impact_events(_run_with(c), min_speed=5e-3, min_force=0.27)
    # kept: the fast sphere impact, the slow one pressed to 2 N, the gate (slow, 3 N); the
    # belt (wall 0) is not an event; the slow light touch is dropped
    assert list(ev["i"]) == [0, 1, 3] and list(ev["partner"]) == [0, 0, 1]
    assert list(ev["wall"]) == [-1, -1, 5] and list(ev["j"]) == [1, 2, -1]
    assert np.all(ev["measured"]) and list(ev["peak_force"]) == [5.0, 2.0, 3.0]
    assert summary["measured"] and summary["n_belt_contacts"] == 1
    assert summary["n_dropped"] == 1 and summary["wall_events"]["gate"] == 1
    st = collision_stresses(ev["normal_speed"], ev["partner"], 45e9, model=StressModel.default(),
                            measured_force=ev["peak_force"], measured_impulse=ev["impulse"])
    np.testing.assert_allclose(st["force_N"], [5.0, 2.0, 3.0])
    np.testing.assert_allclose(st["duration_s"], 0.5 * np.pi * ev["impulse"] / ev["peak_force"])
    assert st["law_force_N"][1] < 0.1  # the law at 1 mm/s: the queue's push is not an impact
    with pytest.raises(Exception, match="min_force"):
        impact_events(_run_with(c), min_force=float("nan"))
