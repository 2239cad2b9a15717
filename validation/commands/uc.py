"""Critical gap u_c(p) from a surface power spectrum (Persson contact mechanics, paper Sec. 5.1).

The surface is a calibrated preset (--surface, see --list-surfaces), a tabulated isotropic C(q)
(--psd FILE.csv, columns q_per_m,C_m4, Persson's convention <h^2> = 2 pi int q C dq) or a stylus
line scan (--line-scan FILE.csv, columns x_<unit>,z_<unit>, unit m|mm|um|nm). The elastic solid
(E, nu) is pressed against it at each nominal pressure p; the result is the gap u_c at the
critical constrictions (0 = sealed: the contact area percolates), the mean separation and the
contact area A/A0 at full magnification. Default method "emt": the Bruggeman effective-medium leak
rate expressed as the equivalent critical-junction gap, the route the paper used; the other is the
critical-junction theory. --out writes the p_over_E,u_c_m table that `cupcheck lifetime
--uc-table` reads.
"""

from __future__ import annotations

import argparse
import csv
import json
import sys

import numpy as np

from validation.commands._surface import add_surface_arguments, has_surface, spectrum_from_args

NAME = "uc"
HELP = "critical gap u_c(p) of a rough surface (Persson theory; presets, PSD or line scan)"

KPA = 1e3


def add_arguments(parser: argparse.ArgumentParser) -> None:
    add_surface_arguments(parser)
    parser.add_argument("--list-surfaces", action="store_true", help="list the presets and exit")
    parser.add_argument("--E-MPa", type=float, dest="E_MPa", help="Young's modulus of the cup [MPa]")
    parser.add_argument("--nu", type=float, default=0.5, help="Poisson ratio (default 0.5)")
    parser.add_argument("--p-kPa", type=float, nargs="+", dest="p_kPa", metavar="P",
                        help="nominal contact pressures [kPa] (1 atm = 101.325 kPa)")
    parser.add_argument("--p-range-kPa", type=float, nargs=3, dest="p_range", metavar=("MIN", "MAX", "N"),
                        help="N log-spaced pressures from MIN to MAX [kPa] (instead of --p-kPa)")
    parser.add_argument("--method", choices=("emt", "critical-junction"), default="emt",
                        help="u_c route (default emt, as in the paper)")
    parser.add_argument("--gamma", type=float, default=0.45,
                        help="Yang-Persson gamma of the separation formula [-] (default 0.45)")
    parser.add_argument("--a-c", type=float, default=0.42, dest="a_c",
                        help="percolation threshold A/A0 [-] (default 0.42, Dapp et al. 2012)")
    parser.add_argument("--json", action="store_true",
                        help="print a JSON list, one object per pressure (p_Pa, u_c_m, u_mean_m, "
                             "contact_area_ratio, sealed)")
    parser.add_argument("--out", metavar="FILE.csv",
                        help="write the p_over_E,u_c_m table (sorted by pressure) for --uc-table")


def _pressures_Pa(args) -> np.ndarray:
    if (args.p_kPa is None) == (args.p_range is None):
        raise ValueError("--p-kPa / --p-range-kPa: give exactly one of them")
    if args.p_kPa is not None:
        p = np.array(args.p_kPa, float)
    else:
        lo, hi, n = args.p_range
        if not (0 < lo < hi and n >= 2 and float(n).is_integer() and n <= 100000):
            raise ValueError(f"--p-range-kPa: need 0 < MIN < MAX and an integer N in [2, 100000], "
                             f"got {lo:g} {hi:g} {n:g}")
        p = np.geomspace(lo, hi, int(n))
    if not np.all(np.isfinite(p)) or np.any(p <= 0):
        raise ValueError(f"--p-kPa: pressures must be > 0 kPa, got {p.min():g}")
    return p * KPA


def _list_surfaces() -> int:
    from reduced.roughness.surfaces import load_presets

    for name, p in load_presets().items():
        c = p.calibration
        print(f"{name:10s} {p.description}; calibrated {c['free_parameter']} = "
              f"{p.params[c['free_parameter']]:.4g} so that u_c = {c['achieved_u_c_m'] * 1e6:.3f} um "
              f"(paper {c['target_u_c_m'] * 1e6:.2f} um) at {c['p_Pa'] / KPA:.3f} kPa, "
              f"E = {c['E_Pa'] / 1e6:g} MPa, nu = {c['nu']:g}, {c['method']}")
    return 0


def run(args) -> int:
    if args.list_surfaces:
        return _list_surfaces()
    from reduced.roughness.persson import check_gap_parameters, critical_gap_table, effective_modulus

    from validation.output import check_outputs, command_inputs
    check_outputs(files={"--out": args.out}, inputs=command_inputs(args))
    if not has_surface(args):
        raise ValueError("surface: give one of --surface NAME, --psd FILE, --line-scan FILE")
    if args.E_MPa is None:
        raise ValueError("--E-MPa: Young's modulus is required (e.g. --E-MPa 4)")
    E_Pa = args.E_MPa * 1e6
    effective_modulus(E_Pa, args.nu)                          # validates E and nu
    p_Pa = _pressures_Pa(args)
    check_gap_parameters(p_Pa / E_Pa, args.method, args.gamma, args.a_c)
    if args.out is not None and len(np.unique(p_Pa)) < 2:
        raise ValueError("--out: a u_c table needs at least 2 distinct pressures")
    spectrum = spectrum_from_args(args)

    table = critical_gap_table(spectrum, E_Pa, args.nu, p_Pa / E_Pa, method=args.method,
                               gamma=args.gamma, a_c=args.a_c)
    rows = [{"p_Pa": float(p), "p_over_E": float(t), "u_c_m": float(u), "u_mean_m": float(um),
             "contact_area_ratio": float(a), "sealed": bool(s)}
            for p, t, u, um, a, s in zip(p_Pa, table.p_over_E, table.u_c_m, table.u_mean_m,
                                         table.contact_area_ratio, table.sealed)]
    if args.out is not None:
        _write_table(args.out, table)
    if args.json:
        json.dump(rows, sys.stdout, indent=1)
        print()
    else:
        print(f"# {spectrum.provenance}; E = {args.E_MPa:g} MPa, nu = {args.nu:g}, "
              f"method {args.method}, gamma {args.gamma:g}, a_c {args.a_c:g}")
        print(f"{'p_kPa':>10s} {'p_over_E':>11s} {'u_c_um':>10s} {'u_mean_um':>10s} {'A/A0':>8s}  sealed")
        for r in rows:
            print(f"{r['p_Pa'] / KPA:10.4g} {r['p_over_E']:11.4e} {r['u_c_m'] * 1e6:10.4g} "
                  f"{r['u_mean_m'] * 1e6:10.4g} {r['contact_area_ratio']:8.4f}  {r['sealed']}")
    return 0


def _write_table(path: str, table) -> None:
    from validation.output import atomic_file

    order = np.argsort(table.p_over_E)
    p, keep = np.unique(table.p_over_E[order], return_index=True)
    u = table.u_c_m[order][keep]
    with atomic_file(path) as tmp:
        with open(tmp, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["p_over_E", "u_c_m"])
            for a, b in zip(p, u):
                w.writerow([f"{a:.10g}", f"{b:.10g}"])
