"""DEM through the Python API: physics through the binding, errors, records, checkpoints."""
from __future__ import annotations

import numpy as np
import pytest

from demfem import dem
from demfem.errors import EffectError, InvalidParameterError, ShapeError, UnstableTimeStepError

R = 0.008
GLASS = dem.material(45e9, 0.22, 2230.0, friction=0.2, restitution=0.5)
TABLE_EFFECTS = ["gravity", "belt", "friction", "rotation", "damping"]


def belt_sphere(**kw: object) -> dem.DemSimulation:
    belt = dem.plane((0, 0, 0), (0, 0, 1), surface_velocity=(0.2, 0, 0))
    return dem.DemSimulation(np.array([[0.0, 0.0, R]]), np.array([R]), [GLASS], [belt], TABLE_EFFECTS, **kw)


def test_sphere_on_belt_rolls_at_two_sevenths():
    # rolling without slip from rest: v = 2/7 V_belt (angular momentum about the contact point)
    sim = belt_sphere(dt_safety=0.5)
    seen = []
    dem.run(sim, 0.08, progress=seen.append, report_every=0.0)
    assert seen and seen[-1].time >= 0.08 and seen[-1].eta_seconds == 0.0
    v = sim.velocities()[0]
    assert v[0] == pytest.approx(2 / 7 * 0.2, rel=0.01)


def test_missing_effect_and_bad_shapes_raise():
    belt = dem.plane((0, 0, 0), (0, 0, 1), surface_velocity=(0.2, 0, 0))
    with pytest.raises(EffectError, match="belt"):
        dem.DemSimulation(np.array([[0.0, 0.0, R]]), np.array([R]), [GLASS], [belt],
                          ["gravity", "friction", "rotation", "damping"])
    with pytest.raises(ShapeError):
        dem.DemSimulation(np.zeros((2, 2)), np.array([R, R]), [GLASS], [], [])
    with pytest.raises(UnstableTimeStepError):
        belt_sphere(dt=1e-3)


def test_onsets_frames_and_contacts_are_arrays():
    sim = belt_sphere(record_every=50, record_onsets=True)
    sim.step(500)
    f = sim.frames()
    assert f["positions"].shape == (10, 1, 3) and f["coordination"].shape == (10, 1)
    o = sim.onsets()
    assert o["partner_is_wall"].all() and o["position"].shape[1] == 3
    c = sim.contacts()
    assert c["normal_force"][0] > 0 and c["partner_is_wall"][0]


def test_checkpoint_restart_is_bitwise_identical(tmp_path):
    a = belt_sphere()
    a.step(3000)
    path = tmp_path / "state.ck"
    a.save_checkpoint(path)
    a.step(3000)
    b = belt_sphere()
    b.load_checkpoint(str(path))
    b.step(3000)
    assert np.array_equal(a.positions(), b.positions())
    assert np.array_equal(a.angular_velocities(), b.angular_velocities())


def test_old_truncated_and_fem_checkpoints_are_refused_by_name(tmp_path):
    from demfem.errors import DemfemIOError

    a = belt_sphere()
    a.step(30)
    path = tmp_path / "state.ck"
    a.save_checkpoint(path)
    data = path.read_bytes()
    assert data[:8] == b"DEMFEMST"  # the one checkpoint format, kind "dem"
    b = belt_sphere()
    old = tmp_path / "old.ck"  # a checkpoint of an earlier demfem: DEMFEMCK, version 3
    old.write_bytes(b"DEMFEMCK" + (3).to_bytes(4, "little") + data[12:])
    with pytest.raises(DemfemIOError, match=r"old\.ck.*older demfem checkpoint format.*rerun"):
        b.load_checkpoint(old)
    cut = tmp_path / "cut.ck"
    cut.write_bytes(data[:-5])
    with pytest.raises(DemfemIOError, match=r"cut\.ck.*truncated"):
        b.load_checkpoint(cut)
    fem = tmp_path / "fem.ck"  # an FEM solver's state: the same format, kind "fem"
    fem.write_bytes(b"DEMFEMST" + (2).to_bytes(4, "little") + b"\x04kind"
                    + (3).to_bytes(8, "little") + b"fem")
    with pytest.raises(DemfemIOError, match="an FEM explicit-run state .*not a DEM checkpoint"):
        b.load_checkpoint(fem)
    assert b.time == 0.0
    b.load_checkpoint(path)
    assert b.time == a.time


def test_anchor_table_runs_and_reports_state():
    sim = dem.DemSimulation._anchor_table(1e8, start="packed", threads=2)
    assert len(sim) == 840 and sim.dt == pytest.approx(0.5 * R * (2230.0 / 1e8) ** 0.5)
    sim.step(3000)  # the belt closes the 0.1 % gaps of the packing within ~40 ms
    assert sim.positions().shape == (840, 3) and np.isfinite(sim.positions()).all()
    assert sim.coordination().mean() > 1.0
    assert sim.riding_up_count() == 0


def test_phase_clock_reads_each_threads_blocks_and_changes_nothing():
    a = dem.DemSimulation._anchor_table(1e8, start="packed", threads=2)
    b = dem.DemSimulation._anchor_table(1e8, start="packed", threads=2)
    assert a.phase_times() == []
    a.set_phase_timing(True)
    a.step(500)
    b.step(500)
    times = a.phase_times()
    # one (force, particle) pair per block of the two threads, each a positive duration
    assert len(times) == 2
    assert all(f > 0.0 and p > 0.0 for f, p in times)
    a.set_phase_timing(False)
    assert np.array_equal(a.positions(), b.positions())


def test_block_cuts_name_where_each_threads_block_begins():
    two = dem.DemSimulation._anchor_table(1e8, start="packed", threads=2)
    one = dem.DemSimulation._anchor_table(1e8, start="packed", threads=1)
    assert one.block_cuts() == []
    two.step(400)
    one.step(400)
    cuts = two.block_cuts()
    # one cut for two threads, inside the particle range and at a multiple of 16 particles
    assert len(cuts) == 1 and 0 < cuts[0] < len(two.positions()) and cuts[0] % 16 == 0
    # the cuts follow measured times; the results never depend on them
    assert np.array_equal(two.positions(), one.positions())


def test_outlet_plane_removes_particles():
    belt = dem.plane((0, 0, 0), (0, 0, 1), surface_velocity=(0.2, 0, 0))
    sim = dem.DemSimulation(np.array([[0.0, 0.0, R]]), np.array([R]), [GLASS], [belt], TABLE_EFFECTS,
                            velocities=np.array([[0.2, 0.0, 0.0]]), removal_plane=((0.02, 0, 0), (-1, 0, 0)))
    sim.run_until(0.5)
    times, idx = sim.removals()
    assert list(idx) == [0] and not sim.alive()[0] and 0.1 < times[0] < 0.5


_CTRL_C_SCRIPT = """
import _thread, signal, sys, threading
import numpy as np
from demfem import dem
from demfem.errors import SimulationInterrupted
signal.signal(signal.SIGINT, signal.default_int_handler)
sim = dem.DemSimulation._anchor_table(1e8, start="square")
for _ in range(3):
    timer = threading.Timer(0.3, _thread.interrupt_main)  # what Ctrl-C does
    timer.start()
    try:
        sim.step(10_000_000, chunk=100)
    except SimulationInterrupted:
        break
    except KeyboardInterrupt:
        continue  # taken before the step began (a starved process): try again
    finally:
        timer.cancel()
else:
    sys.exit("never interrupted")
assert 0 < sim.steps < 10_000_000
assert abs(sim.time - sim.steps * sim.dt) <= 1e-9 * sim.time
assert np.isfinite(sim.positions()).all()
sim.step(100)  # and the simulation goes on
print("ok", sim.steps)
"""


def test_ctrl_c_stops_cleanly_at_a_step_boundary():
    """Ctrl-C (a simulated SIGINT) stops a long step at a step boundary with
    SimulationInterrupted, and the simulation goes on. In a fresh interpreter, so that no
    signal handler left by another test (or a starved process) decides the outcome."""
    import subprocess
    import sys

    r = subprocess.run([sys.executable, "-c", _CTRL_C_SCRIPT], capture_output=True, text=True,
                       timeout=300)
    assert r.returncode == 0 and r.stdout.startswith("ok"), r.stdout + r.stderr


def test_refeed_puts_removed_spheres_back_upstream():
    """A table that re-feeds keeps its population: spheres leaving through the opening are
    re-inserted at free upstream sites, never on top of another sphere."""
    from demfem.scenes import AccumulationTable

    table = AccumulationTable(young_modulus=1e7, refeed=True, n_spheres=300)
    scene = table.build()
    sim = dem.from_scene(scene)
    dem.run(sim, 3.0, refeed=scene.refeed)
    times, removed = sim.removals()
    assert len(removed) > 5  # spheres did leave
    alive = sim.alive()
    assert alive.sum() >= 300 - len(scene.refeed["sites"])  # and came back
    pos, r = sim.positions()[alive], sim.radii()[alive]
    d = np.linalg.norm(pos[:, None, :] - pos[None, :, :], axis=2) + np.eye(len(pos))
    assert (d / (r[:, None] + r[None, :])).min() > 0.98  # no sphere placed inside another
    with pytest.raises(InvalidParameterError, match="removed particle"):
        sim.reinsert_particle(int(np.flatnonzero(alive)[0]), (0.1, 0.1, 0.1), (0, 0, 0))
