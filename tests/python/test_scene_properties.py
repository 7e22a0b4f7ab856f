"""Property-based checks of scene files (issue 43, hypothesis): random, garbled and mutated
TOML scenes of the accumulation table and of the mesh table, and the STL files a mesh table
names, are either loaded into a scene that makes physical sense or refused with one of
demfem's own errors (:class:`demfem.errors.DemfemError`) — never another exception (a
traceback), a hang (every load runs under a 5 s alarm, examples have a deadline) or a silent
result (an accepted mesh table is checked against the rules it must meet). Only the scenes
are loaded and validated; nothing is simulated.
"""
from __future__ import annotations

import math
import signal
import tempfile
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Iterator

import numpy as np
import pytest

hypothesis = pytest.importorskip("hypothesis")
from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from demfem.errors import DemfemError  # noqa: E402
from demfem.io.stl import write_stl  # noqa: E402
from demfem.scenes.mesh_table import (MAX_COORDINATE, MAX_REST_OVERLAP,  # noqa: E402
                                      POOL_BYTES_PER_SPHERE, MeshTable, memory_limit)
from demfem.scenes.table import AccumulationTable  # noqa: E402

SETTINGS = settings(max_examples=40, deadline=2000, derandomize=True, database=None,
                    suppress_health_check=[HealthCheck.too_slow])


class Hang(Exception):
    """A load that did not end within its alarm."""


@contextmanager
def alarm(seconds: float = 5.0) -> Iterator[None]:
    def ring(signum, frame):
        raise Hang(f"no answer within {seconds} s")

    old = signal.signal(signal.SIGALRM, ring)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0.0)
        signal.signal(signal.SIGALRM, old)


# ---- TOML text of a document (tomllib reads, it does not write) ------------------------------

def _value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf") if math.isinf(v) \
            else repr(v)
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{k} = {_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(type(v))


def toml_text(doc: dict) -> str:
    """TOML for a document of scalars, arrays, tables and arrays of tables (one level)."""
    lines, tables = [], []
    for key, v in doc.items():
        if isinstance(v, dict):
            tables.append(f"[{key}]")
            tables += [f"{k} = {_value(x)}" for k, x in v.items()]
        elif isinstance(v, list) and v and all(isinstance(x, dict) for x in v):
            for item in v:
                tables.append(f"[[{key}]]")
                tables += [f"{k} = {_value(x)}" for k, x in item.items()]
        else:
            lines.append(f"{key} = {_value(v)}")
    return "\n".join(lines + tables) + "\n"


# ---- values -----------------------------------------------------------------------------------

AWKWARD = st.one_of(
    st.sampled_from([0, -1, 1, 2**63 - 1, 2**64, 1e300, -1e300, 5e-324, math.nan, math.inf,
                     -math.inf, 0.0, -0.0, 1e-300, True, False, "", "x", "nan", [], [1, 2],
                     [[0, 0], [1, 0]], {"kind": "harmonic"}, {}, [{"a": 1}]]),
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(min_value=-10**12, max_value=10**12),
    st.text(max_size=8),
    st.lists(st.floats(-2.0, 2.0), max_size=4),
)


def near(value: Any) -> st.SearchStrategy:
    """A value like ``value`` (a number scaled or negated, one entry of a list changed), or
    an awkward one."""
    if isinstance(value, bool) or value is None:
        return AWKWARD
    if isinstance(value, (int, float)):
        scaled = st.floats(-3.0, 3.0).map(lambda e: float(value) * 10.0 ** e)
        return st.one_of(scaled, scaled.map(lambda x: -x), AWKWARD)
    if isinstance(value, list) and value and not isinstance(value[0], dict):
        return st.integers(0, len(value) - 1).flatmap(
            lambda k: near(value[k]).map(lambda x: value[:k] + [x] + value[k + 1:]))
    return AWKWARD


def check_loads(load, path: Path) -> Any:
    """Load ``path``: a scene, or None if refused by a DemfemError; anything else fails."""
    with alarm():
        try:
            return load(path)
        except DemfemError:
            return None


# ---- the accumulation table -------------------------------------------------------------------

FIELDS = [line.split(" = ")[0] for line in AccumulationTable().toml_text().splitlines()
          if " = " in line and not line.startswith("#") and not line.startswith("scene")]
FIELDS = FIELDS[:FIELDS.index("contact_model") + 1]  # the flat keys, not [cartridge]'s


def _known_table_failure(values: dict) -> bool:
    """No scene is left out any more (the table bounds its site loop)."""
    return False


@SETTINGS
@given(values=st.dictionaries(st.sampled_from(FIELDS + ["unknown_key", "scene"]), AWKWARD,
                              max_size=4))
def test_random_table_scenes_load_or_are_refused(values):
    hypothesis.assume(not _known_table_failure(values))
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "table.toml"
        try:
            text = toml_text(values)
        except TypeError:
            return
        path.write_text(text, encoding="utf-8")
        table = check_loads(AccumulationTable.from_toml, path)
        if table is not None:
            with alarm():
                try:
                    table.build()
                except DemfemError:
                    pass


def _mutate(text: str, data: st.DataObject) -> bytes:
    """One of: a line dropped or doubled, a value replaced, bytes flipped, the text cut."""
    lines = text.splitlines()
    kind = data.draw(st.sampled_from(["drop", "double", "value", "flip", "cut", "junk"]))
    k = data.draw(st.integers(0, len(lines) - 1))
    if kind == "drop":
        del lines[k]
    elif kind == "double":
        lines.insert(k, lines[k])
    elif kind == "value" and " = " in lines[k]:
        key, _, old = lines[k].partition(" = ")
        try:
            import tomllib

            was = tomllib.loads(f"v = {old.split('#')[0]}")["v"]
        except Exception:  # noqa: BLE001 - a line the mutation made unreadable
            was = None
        lines[k] = f"{key} = {_value(data.draw(near(was)))}"
    raw = ("\n".join(lines) + "\n").encode("utf-8")
    if kind == "flip" and raw:
        i = data.draw(st.integers(0, len(raw) - 1))
        raw = raw[:i] + bytes([raw[i] ^ data.draw(st.integers(1, 255))]) + raw[i + 1:]
    elif kind == "cut":
        raw = raw[: data.draw(st.integers(0, len(raw)))]
    elif kind == "junk":
        raw = data.draw(st.binary(max_size=64)) + raw
    return raw


@SETTINGS
@given(data=st.data())
def test_mutated_table_scenes_load_or_are_refused(data):
    import tomllib

    raw = _mutate(AccumulationTable().toml_text(), data)
    try:
        hypothesis.assume(not _known_table_failure(tomllib.loads(raw.decode("utf-8"))))
    except (UnicodeDecodeError, tomllib.TOMLDecodeError):
        pass
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "table.toml"
        path.write_bytes(raw)
        check_loads(AccumulationTable.from_toml, path)


@settings(max_examples=30, deadline=2000, derandomize=True, database=None)
@given(raw=st.binary(max_size=512))
def test_garbage_scene_files_are_refused(raw):
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "scene.toml"
        path.write_bytes(raw)
        for load in (AccumulationTable.from_toml, MeshTable.from_toml):
            check_loads(load, path)


# ---- the mesh table ---------------------------------------------------------------------------

def mesh_table_doc() -> dict:
    return {"scene": "mesh_table", "duration": 1.0,
            "particles": {"radius": 0.008, "pool": 50},
            "meshes": [{"file": "rail.stl", "scale": 1.0}],
            "belts": [{"polygon": [[0, 0], [1, 0], [1, 0.3], [0, 0.3]], "velocity": [0.2, 0]}],
            "infeed": {"rate": 60, "region": [[0, 0], [0.1, 0.3]], "velocity": [0.2, 0]},
            "outlet": {"point": [0.9, 0, 0], "normal": [1, 0, 0]}}


def write_rail(folder: Path, how: str, data: st.DataObject) -> None:
    """A side rail along the belt as STL: clean, twice over, garbled, far away or absent."""
    v = np.array([[0, 0.3, 0], [1, 0.3, 0], [1, 0.3, 0.05], [0, 0.3, 0.05]], float)
    t = np.array([[0, 1, 2], [0, 2, 3]])
    path = folder / "rail.stl"
    if how == "missing":
        return
    if how == "far":
        v = v * 1e300
    if how == "degenerate":
        v[2] = v[1]
    with np.errstate(all="ignore"):
        write_stl(path, v, np.vstack([t, t]) if how == "twice" else t,
                  binary=data.draw(st.booleans()))
    if how == "garbled":
        raw = bytearray(path.read_bytes())
        for _ in range(data.draw(st.integers(1, 8))):
            raw[data.draw(st.integers(0, len(raw) - 1))] = data.draw(st.integers(0, 255))
        path.write_bytes(bytes(raw))


def _leaves(doc: Any, prefix: tuple = ()) -> list[tuple]:
    if isinstance(doc, dict):
        return [p for k, v in doc.items() for p in _leaves(v, prefix + (k,))] + [prefix]
    if isinstance(doc, list) and doc and all(isinstance(x, dict) for x in doc):
        return [p for i, v in enumerate(doc) for p in _leaves(v, prefix + (i,))] + [prefix]
    return [prefix]


def _set(doc: Any, path: tuple, value: Any, delete: bool) -> None:
    for key in path[:-1]:
        doc = doc[key]
    if delete and isinstance(doc, dict):
        doc.pop(path[-1], None)
    else:
        doc[path[-1]] = value


def assert_sensible(table: MeshTable) -> None:
    """What an accepted mesh table must satisfy (else it would run to a meaningless
    result)."""
    r = table.sphere_radius
    assert table.lost_below < 0
    assert table.pool * POOL_BYTES_PER_SPHERE <= memory_limit()
    sites = table.infeed.sites(r, table.packing_gap)
    assert len(sites) > 0
    assert float(np.max((sites - table.outlet["point"]) @ table.outlet["normal"])) <= -r
    for m in table.meshes:
        assert np.all(np.abs(m.vertices) <= MAX_COORDINATE)
        assert len(np.unique(np.sort(m.triangles, axis=1), axis=0)) == len(m.triangles)
    for b in table.belts:
        assert np.all(np.abs(b.polygon) <= MAX_COORDINATE)
    glass = table.materials[table.particle_material]
    e_star = 1.0 / sum((1 - m["poisson_ratio"] ** 2) / m["young_modulus"]
                       for m in (glass, table.materials[table.belts[0].material]))
    rest = (3 * table.sphere_mass * 9.81 / (4 * e_star * math.sqrt(r))) ** (2 / 3)
    assert rest <= MAX_REST_OVERLAP * r
    assert table.duration / table.window <= 1e5 + 1e-6


@SETTINGS
@given(data=st.data())
def test_mutated_mesh_tables_load_sensibly_or_are_refused(data):
    doc = mesh_table_doc()
    for _ in range(data.draw(st.integers(0, 2))):
        path = data.draw(st.sampled_from([p for p in _leaves(doc) if p]))
        was = doc
        for key in path:
            was = was[key]
        _set(doc, path, data.draw(near(was)), delete=data.draw(st.integers(0, 5)) == 0)
    how = data.draw(st.sampled_from(["clean"] * 5 + ["twice", "garbled", "missing", "far",
                                                     "degenerate"]))
    with tempfile.TemporaryDirectory() as d:
        folder = Path(d)
        write_rail(folder, how, data)
        try:
            text = toml_text(doc)
        except TypeError:
            return
        raw = text.encode("utf-8")
        if data.draw(st.integers(0, 3)) == 0:
            raw = _mutate(text, data)
        (folder / "scene.toml").write_bytes(raw)
        with np.errstate(all="ignore"), _quiet():
            table = check_loads(MeshTable.from_toml, folder / "scene.toml")
        if table is not None:
            assert_sensible(table)
            with alarm():
                try:
                    table.description()
                except DemfemError:
                    pass


@contextmanager
def _quiet() -> Iterator[None]:
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        yield


def test_the_unmutated_mesh_table_is_accepted(tmp_path):
    class Draw:
        def draw(self, strategy):
            return False

    write_rail(tmp_path, "clean", Draw())
    (tmp_path / "scene.toml").write_text(toml_text(mesh_table_doc()))
    table = MeshTable.from_toml(tmp_path / "scene.toml")
    assert_sensible(table)


# ---- absurd sizes of the accumulation table ---------------------------------------------------

def test_a_table_1_km_wide_is_refused_at_once():
    with alarm(5.0):
        with pytest.raises(DemfemError, match="width"):
            AccumulationTable(width=1e3)


def test_a_table_100_km_long_builds():
    with alarm(20.0):
        scene = AccumulationTable(length=1e5).build()
    assert len(scene.positions) == 840
