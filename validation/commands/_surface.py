"""The rough surface a command works on: a calibrated preset, a tabulated C(q) or a line scan.

Shared by `cupcheck uc` and `cupcheck lifetime`, so both read a surface the same way.
"""

from __future__ import annotations

import argparse
import os
import sys
import warnings


def add_surface_arguments(parser: argparse.ArgumentParser, group=None, preset: bool = True) -> None:
    """--surface | --psd | --line-scan (mutually exclusive), --psd-convention, --tip-radius-um;
    `preset` False: the caller adds --surface itself (`lifetime`, from the study's field)."""
    src = group if group is not None else parser.add_mutually_exclusive_group()
    if preset:
        src.add_argument("--surface", metavar="NAME",
                         help="calibrated preset (see `cupcheck uc --list-surfaces`); for `lifetime`, "
                              "pmma-1.89 when no surface or table is given, and `illustrative` the "
                              "power-law u_c table of reduced/data (not a rough-contact result)")
    src.add_argument("--psd", metavar="FILE", help="isotropic C(q) CSV, columns q_per_m,C_m4 [1/m, m^4]")
    src.add_argument("--line-scan", metavar="FILE",
                     help="line scan CSV, header x_<unit>,z_<unit> (unit m, mm, um or nm)")
    parser.add_argument("--psd-convention", default="persson-2d",
                        choices=("persson-2d", "surfacetopography-2d"),
                        help="normalisation of --psd: persson-2d or surfacetopography-2d (default: persson-2d)")
    parser.add_argument("--tip-radius-um", type=float, default=1.0,
                        help="stylus tip radius for --line-scan [um] (default 1, the paper's)")


def has_surface(args: argparse.Namespace) -> bool:
    return any(getattr(args, k, None) is not None for k in ("surface", "psd", "line_scan"))


def spectrum_from_args(args: argparse.Namespace):
    """The `PowerSpectrum` the surface options name (ValueError naming the option if unusable)."""
    from reduced.roughness.line_scan import read_line_scan, spectrum_from_line_scan
    from reduced.roughness.spectrum import read_psd_csv
    from reduced.roughness.surfaces import preset

    for opt, path in (("--psd", args.psd), ("--line-scan", args.line_scan)):
        if path is not None and not os.path.isfile(path):
            raise ValueError(f"{opt}: no such file {path!r}")
    if args.surface is not None:
        return preset(args.surface).spectrum()
    if args.psd is not None:
        return read_psd_csv(args.psd, args.psd_convention)
    if not args.tip_radius_um > 0:
        raise ValueError(f"--tip-radius-um: must be > 0, got {args.tip_radius_um:g}")
    x, z = read_line_scan(args.line_scan)
    with warnings.catch_warnings(record=True) as caught:         # a spectrum that clips: one line
        warnings.simplefilter("always")
        spectrum = spectrum_from_line_scan(x, z, args.tip_radius_um * 1e-6)
    for w in caught:
        print(f"note: {w.message}", file=sys.stderr)
    return spectrum
