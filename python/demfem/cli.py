"""Command line: ``demfem <command>``. Run ``demfem --help`` for the list."""
from __future__ import annotations

import argparse
import os
import sys
from typing import Optional, Sequence

import numpy as np

from demfem.errors import DemfemError, InvalidParameterError

__all__ = ["main", "build_parser", "study_options_from_args"]


def _cmd_calibrate(args: argparse.Namespace) -> int:
    from demfem.calibration import calibration_report, force_vs_modulus, write_calibration
    from demfem.cartridge import Cartridge

    print(calibration_report(args.v_rel))
    E = np.logspace(np.log10(args.e_min), np.log10(args.e_max), args.n)
    table = force_vs_modulus(Cartridge(), E, args.v_rel)
    print(f"\nMaximum contact force, two cartridges at v_rel = {args.v_rel:g} m/s (Fig. 3 analogue):")
    print(table.format())
    csv, png = write_calibration(args.out, table)
    print(f"\nwrote {csv}\nwrote {png}")
    return 0


def _cmd_run(args: argparse.Namespace) -> int:
    from demfem.pipeline import run_pipeline

    duration = args.duration if args.duration is not None else (0.1 if args.quick else 1.0)
    sample = args.sample_interval if args.sample_interval is not None else min(
        0.01 if args.quick else 0.02, duration)
    run_pipeline(args.out, duration=duration, young_modulus=args.young_modulus,
                 sample_interval=sample, threads=args.threads, progress=True,
                 log=lambda line: print(line, flush=True))
    return 0


def _cmd_sweep(args: argparse.Namespace) -> int:
    from demfem.sweep import parse_grid_option, sweep

    grid = parse_grid_option(args.grid)

    def progress(done: int, total: int) -> None:
        print(f"\r  runs finished: {done}/{total}", end="", flush=True)

    res = sweep(grid, args.runner, args.out, scheduler=args.scheduler, n_workers=args.workers,
                progress=progress)
    print(f"\nran {res.ran}, skipped {res.skipped} already finished; table: {res.table_path}")
    print(res.table_path.read_text(), end="")
    return 0


#: Defaults of the figure studies: (duration s, moduli Pa) for a full run and for --quick.
_STUDY_DEFAULTS = {
    "fig5": ((10.0, "1e7"), (0.3, "1e7")),
    "fig6": ((8.0, "1e7,1e8,1e9"), (0.3, "1e7,1e8")),
    "fig7": ((8.0, "1e7,1e8,1e9"), (0.3, "1e7,1e8")),
    "fig8": ((10.0, "1e7"), (0.3, "1e7")),
}


def study_options_from_args(args: argparse.Namespace):
    """The :class:`demfem.studies.figures.StudyOptions` of a parsed `demfem figN` command line
    (used by the scripts in examples/ too)."""
    from pathlib import Path

    from demfem.studies.figures import StudyOptions

    (duration, moduli), (q_duration, q_moduli) = _STUDY_DEFAULTS[args.command]
    if args.quick:
        duration, moduli = q_duration, q_moduli
    duration = args.duration if args.duration is not None else duration
    text = args.E if args.E is not None else moduli
    try:
        values = tuple(float(x) for x in text.split(","))
    except ValueError:
        raise ValueError(f"invalid --E {text!r}: must be Young's moduli in Pa, comma "
                         "separated, e.g. 1e7,1e8") from None
    sample = args.sample_interval if args.sample_interval is not None else (
        0.02 if args.quick else 0.05)
    return StudyOptions(out=Path(args.out), duration=duration, moduli=values,
                        sample_interval=sample, scheduler=args.scheduler,
                        workers=args.workers)


def durations_from_args(args: argparse.Namespace) -> dict[float, float]:
    """Per-modulus durations of `demfem fig6|fig7 --E-duration E=SECONDS ...` as
    {E (Pa): simulated time (s)}."""
    out: dict[float, float] = {}
    for item in getattr(args, "E_duration", None) or []:
        e_text, sep, d_text = item.partition("=")
        try:
            if not sep:
                raise ValueError
            e, d = float(e_text), float(d_text)
        except ValueError:
            raise InvalidParameterError(
                f"invalid --E-duration {item!r}: must be E=SECONDS, Young's modulus in Pa and "
                "simulated time in s, e.g. 1e7=60") from None
        out[e] = d
    return out


def _cmd_study(args: argparse.Namespace) -> int:
    from demfem.studies import figures

    opts = study_options_from_args(args)
    if args.command == "fig5":
        result = figures.fig5(opts, discard_before=args.discard_before)
        print(f"gentlest set-up: {result['gentlest']} (paper: A=2cm T=2s V=0.2m/s)")
    elif args.command == "fig6":
        figures.fig6(opts, stiff_duration=args.stiff_duration,
                     durations=durations_from_args(args))
    elif args.command == "fig7":
        figures.fig7(opts, stiff_duration=args.stiff_duration,
                     durations=durations_from_args(args))
    else:
        figures.fig8_9(opts, snapshot_times=tuple(float(x) for x in args.snapshots.split(",")))
    print(f"figures in {opts.out}")
    return 0


def _add_study(sub, name: str, help_text: str) -> argparse.ArgumentParser:
    (duration, moduli), (q_duration, _) = _STUDY_DEFAULTS[name]
    s = sub.add_parser(name, help=help_text)
    s.add_argument("--duration", type=float, default=None,
                   help=f"simulated time per run, s ({duration:g}; --quick: {q_duration:g})")
    s.add_argument("--E", default=None, metavar="E1,E2,...",
                   help=f"Young's modulus/moduli, Pa ({moduli})")
    s.add_argument("--quick", action="store_true",
                   help="a smoke run (0.3 s simulated per run) with the same outputs")
    s.add_argument("--sample-interval", type=float, default=None,
                   help="time between recorded samples, s (0.05; --quick: 0.02)")
    s.add_argument("--out", default="demfem_out/studies",
                   help="output folder; runs are kept in <out>/runs and reused")
    s.add_argument("--scheduler", default=None,
                   help="Dask scheduler address, or 'serial'; default: a LocalCluster")
    s.add_argument("--workers", type=int, default=None, help="LocalCluster worker processes")
    s.set_defaults(func=_cmd_study)
    return s


def _cmd_equivalence(args: argparse.Namespace) -> int:
    from demfem.equivalence import StudyConfig, run_study

    config = StudyConfig(n_spheres=args.n, young_modulus=args.young_modulus, t_end=args.t_end)
    result = run_study(config, args.out, progress=lambda msg: print("  " + msg, flush=True))
    print(result["markdown"], end="")
    print(f"written: {args.out}/equivalence.csv, .md, .png")
    return 0


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``demfem`` command."""
    p = argparse.ArgumentParser(prog="demfem", description="DEM-FEM breakage of glass cartridges "
                                "on a conveyor-belt accumulation table (SI units).")
    sub = p.add_subparsers(dest="command", required=True)
    c = sub.add_parser("calibrate", help="equivalent sphere and Fig. 3: max force vs E per law")
    c.add_argument("--v-rel", type=float, default=0.2, help="relative impact speed, m/s (0.2)")
    c.add_argument("--e-min", type=float, default=1e7, help="smallest Young's modulus, Pa (1e7)")
    c.add_argument("--e-max", type=float, default=1e11, help="largest Young's modulus, Pa (1e11)")
    c.add_argument("--n", type=int, default=9, help="number of moduli, log-spaced (9)")
    c.add_argument("--out", default="demfem_out", help="output directory (demfem_out)")
    c.set_defaults(func=_cmd_calibrate)
    r = sub.add_parser("run", help="the main job: calibration, DEM of the default table, analysis")
    r.add_argument("--duration", type=float, default=None,
                   help="simulated time of the table, s (1.0; --quick: 0.1)")
    r.add_argument("--E", dest="young_modulus", type=float, default=None,
                   help="Young's modulus of the glass, Pa (the paper's 4.5e10)")
    r.add_argument("--sample-interval", type=float, default=None,
                   help="time between recorded samples, s (0.02; --quick: 0.01)")
    r.add_argument("--threads", type=int, default=min(2, os.cpu_count() or 1),
                   help="DEM engine threads (2 where the machine has 2 cores or more; results "
                        "are bitwise the same on any number)")
    r.add_argument("--quick", action="store_true", help="a smoke run with the same outputs")
    r.add_argument("--out", default="demfem_out/run", help="output directory (demfem_out/run); "
                   "an interrupted run resumes from its checkpoint there")
    r.set_defaults(func=_cmd_run)
    s = sub.add_parser("sweep", help="run a parameter grid on Dask (LocalCluster by default)")
    s.add_argument("--runner", required=True,
                   help="'module:function' run per point, e.g. demfem.calibration:sweep_point")
    s.add_argument("--grid", action="append", required=True, metavar="NAME=v1,v2,...",
                   help="one parameter and its values; repeat for more (Cartesian product)")
    s.add_argument("--out", default="demfem_out/sweep", help="output directory")
    s.add_argument("--scheduler", default=None,
                   help="Dask scheduler address (tcp://host:8786), or 'serial'; "
                        "default: a LocalCluster on this machine")
    s.add_argument("--workers", type=int, default=None, help="LocalCluster worker processes")
    s.set_defaults(func=_cmd_sweep)
    f5 = _add_study(sub, "fig5", "Fig. 5: first-line force for A, T, V_belt and the gentlest "
                    "set-up")
    f5.add_argument("--discard-before", type=float, default=1.0,
                    help="start of the force statistics used for the ranking, s (1)")
    for name, text in (("fig6", "Fig. 6: coordination number against time for several E"),
                       ("fig7", "Fig. 7: rectangular-centre speed against time for several E")):
        f = _add_study(sub, name, text)
        f.add_argument("--stiff-duration", type=float, default=None,
                       help="simulated time for the runs with E > 1e9 Pa, s (default: "
                            "--duration)")
        f.add_argument("--E-duration", action="append", default=None, metavar="E=SECONDS",
                       help="simulated time for the run at E (Pa), s, over --duration and "
                            "--stiff-duration; repeat for more, e.g. --E-duration 1e7=60")
    f8 = _add_study(sub, "fig8", "Figs. 8-9: triangular centre and first line, snapshots, GIF "
                    "and ParaView series")
    f8.add_argument("--snapshots", default="9.3,12.2", metavar="T1,T2,...",
                    help="times of the table snapshots, s (9.3,12.2; clipped to the run)")
    e = sub.add_parser("equivalence", help="spheres vs clumped vs exact cartridges on one table")
    e.add_argument("--n", type=int, default=40, help="bodies on the reduced table (40)")
    e.add_argument("--young-modulus", type=float, default=45e7, help="Young's modulus, Pa (4.5e8)")
    e.add_argument("--t-end", type=float, default=2.0, help="simulated time, s (2.0)")
    e.add_argument("--out", default="demfem_out/equivalence", help="output directory")
    e.set_defaults(func=_cmd_equivalence)
    return p


def main(argv: Optional[Sequence[str]] = None) -> int:
    """Entry point of the ``demfem`` command; returns the exit code."""
    args = build_parser().parse_args(argv)
    try:
        return int(args.func(args))
    except (DemfemError, ValueError) as exc:
        print(f"demfem {args.command}: error: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
