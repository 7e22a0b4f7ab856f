"""The Python examples a user runs (examples/*.py): each runs as a script, as the user would
start it, and prints its key numbers finite and in a sane range. The three take about 40 s
together on a shared 2-core machine (not marked slow)."""
from __future__ import annotations

import math
import os
import re
import subprocess
import sys
from pathlib import Path

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
NUMBER = r"([-+0-9.eE]+|nan|inf)"


def run_example(name: str, *args: str, cwd: Path, timeout: float = 300.0) -> str:
    """Run ``examples/<name>`` with this interpreter in ``cwd``; its stdout (fails the test,
    showing the output, when it exits non-zero)."""
    env = {**os.environ, "MPLBACKEND": "Agg"}
    r = subprocess.run([sys.executable, str(EXAMPLES / name), *args], cwd=cwd, env=env,
                       capture_output=True, text=True, timeout=timeout)
    assert r.returncode == 0, (f"{name} exited {r.returncode}:\n{r.stdout[-3000:]}\n"
                               f"{r.stderr[-3000:]}")
    return r.stdout


def number(pattern: str, text: str) -> float:
    """The number that ``pattern`` (with ``{x}`` where the number stands) finds in ``text``."""
    m = re.search(pattern.replace("{x}", NUMBER), text)
    assert m, f"{pattern!r} not in the output:\n{text}"
    value = float(m.group(1))
    assert math.isfinite(value), f"{pattern!r}: {value}"
    return value


def test_scene_run_analysis(tmp_path):
    out = run_example("scene_run_analysis.py", cwd=tmp_path)
    z = number(r"mean coordination: {x} contacts per sphere", out)
    force = number(r"first-line force per sphere: mean {x} N", out)
    v50 = number(r"normal impact speed median / 90 % / 99 % {x} /", out)
    assert 0.5 < z < 6.0                # a packing on a belt, not a jammed crystal
    assert 1e-3 < force < 10.0          # N per sphere; m g = 0.048 N
    assert 0.1 < v50 < 300.0            # mm/s; the belt runs at 300 mm/s


def test_fem_collision(tmp_path):
    out = run_example("fem_collision.py", cwd=tmp_path)
    fem = number(r"FEM: .*\n  peak force {x} N", out)
    law = number(r"law \(Hertz-Reissner, equivalent spheres\): peak force {x} N", out)
    sigma_outer = number(r"peak sigma1 on the upright cartridge: outer {x} MPa", out)
    assert 15.0 < fem < 25.0            # N: 18.9 N at 2 layers (README)
    assert abs(law / fem - 1.0) < 0.1   # the calibrated law meets the FEM crossed at 45 GPa
    assert 0.1 < sigma_outer < 100.0    # MPa


def test_assess_from_python(tmp_path):
    out = run_example("assess_from_python.py", str(tmp_path / "assess"), cwd=tmp_path)
    rate = number(r"expected broken cartridges per hour: {x} \(95 % interval", out)
    lo = number(r"\(95 % interval {x} - ", out)
    hi = number(r"\(95 % interval [^ ]+ - {x},", out)
    assert 1e-9 < rate < 1.0 and lo <= rate <= hi
    # the hazard by place from the events table is risk.json's (both printed to 0.1 %)
    line = re.search(r"hazard by place on the cartridge: (.*) \(risk.json: (.*)\)", out)
    assert line is not None
    mine, theirs = (dict(re.findall(r"(\w+) ([0-9.]+)%", g)) for g in line.groups())
    assert mine == theirs and set(mine) == {"rim", "body", "shoulder"}
    shares = [float(x) for x in re.findall(r"^\S+\s+\d+\s+\S+\s+([0-9.]+)$", out, re.M)]
    assert shares and abs(sum(shares) - 1.0) < 1e-3
    assert number(r"(?m)^cartridge\s+\d+\s+\S+\s+{x}$", out.replace("\r", "")) > 0.5
