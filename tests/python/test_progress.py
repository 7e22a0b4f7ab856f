"""The progress line reports fraction, simulated time, steps/s and ETA."""
import io
import re
import time

import pytest

from demfem.errors import InvalidParameterError
from demfem.progress import ProgressBar, format_duration


def test_format_duration():
    assert format_duration(3.44) == "3.4s"
    assert format_duration(123) == "2m03s"
    assert format_duration(3723) == "1h02m03s"
    assert format_duration(float("nan")) == "--"


def test_progress_line_reports_rate_and_eta():
    out = io.StringIO()
    bar = ProgressBar(2.0, label="dem", stream=out, log_interval=0.0)
    bar(0.0, 0)
    time.sleep(0.05)
    bar(1.0, 1000)
    line = out.getvalue().strip().splitlines()[-1]
    assert "50.0%" in line and "t = 1/2 s" in line
    rate = float(re.search(r"([\d,]+) steps/s", line).group(1).replace(",", ""))
    assert 1000 / 1.0 < rate < 1000 / 0.04  # 1000 steps in >= 0.05 s of wall time
    # half done after ~0.05 s: about 0.05 s to go
    eta = float(re.search(r"ETA ([\d.]+)s", line).group(1))
    assert 0.0 < eta < 1.0


def test_rate_and_eta_count_from_the_first_call():
    """Set-up before the first call and the steps of a resumed run's first part do not count:
    the first line has no rate yet, the next ones count from it."""
    out = io.StringIO()
    bar = ProgressBar(2.0, label="dem", stream=out, log_interval=0.0)
    time.sleep(0.2)  # set-up, e.g. building the scene
    bar(1.0, 50_000)  # a resumed run: half done already
    first = out.getvalue().strip().splitlines()[-1]
    assert "-- steps/s" in first and "ETA --" in first
    time.sleep(0.05)
    bar(1.5, 51_000)
    line = out.getvalue().strip().splitlines()[-1]
    rate = float(re.search(r"([\d,]+) steps/s", line).group(1).replace(",", ""))
    assert 1000 / 1.0 < rate < 1000 / 0.04
    # 0.5 s simulated in ~0.05 s of wall time, 0.5 s to go: about 0.05 s (not 0.25 s)
    eta = float(re.search(r"ETA ([\d.]+)s", line).group(1))
    assert 0.0 < eta < 0.2


def test_progress_rejects_bad_duration():
    with pytest.raises(InvalidParameterError, match="duration"):
        ProgressBar(0.0)
