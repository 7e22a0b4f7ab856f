"""Paper Fig. 7: speed of the 'rectangular centre' sphere against time for several Young's
moduli, (a) E <= 1e9 Pa and (b) E > 1e9 Pa, on the runs of Fig. 6 (V_belt = 0.1 m/s,
T = 2 s, A = 2 cm). The paper reports ~100 mm/s at E = 1e7 Pa and ~250 mm/s at 45 GPa after
~50 s; the script prints the mean, the peak, the time the sphere left and the mean / peak per
10 s window per E. `--E-duration E=SECONDS` gives one modulus its own simulated time.

Writes fig7_rectangular_centre_speed.png and fig7_findings.json.

Run:  python examples/fig7_rectangular_centre_speed.py [--duration 8] [--E 1e7,1e8,1e9,4.5e10]
                                                       [--stiff-duration 0.5] [--quick]
                                                       [--E-duration 1e7=60 ...]
"""
import sys

from demfem.cli import build_parser, durations_from_args, study_options_from_args
from demfem.studies.figures import fig7

if __name__ == "__main__":
    args = build_parser().parse_args(["fig7", *sys.argv[1:]])
    fig7(study_options_from_args(args), stiff_duration=args.stiff_duration,
         durations=durations_from_args(args))
