"""The reduced model's options shared by the routes of `cupcheck lifetime`: the critical gap
u_c(p/E) the surface options ask for (without any, the calibrated `pipeline.DEFAULT_SURFACE`, as in
`example` and the scenes; the ILLUSTRATIVE table only as ``--surface illustrative``), the run
options every route checks, and --relaxation."""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable

from validation.commands._surface import has_surface, spectrum_from_args

__all__ = ["build_uc", "check_run_options", "relaxation_law", "ILLUSTRATIVE"]

#: the --surface name of the ILLUSTRATIVE u_c table in reduced/data (a power law, not Persson theory)
ILLUSTRATIVE = "illustrative"


def build_uc(args: argparse.Namespace) -> Callable[[float], float]:
    """The critical gap u_c(p/E) [m] the options ask for (the one place that builds it)."""
    from reduced.critical_gap import ILLUSTRATIVE_UC_CSV, UcTable
    from validation.guards import check_spectrum, check_uc_table
    from validation.bridge.pipeline import DEFAULT_SURFACE
    if args.surface == ILLUSTRATIVE:                  # asked for by name only
        return UcTable.from_csv(ILLUSTRATIVE_UC_CSV)
    if not has_surface(args) and args.uc_table is None:
        args.surface = DEFAULT_SURFACE                # the one default surface of every command
    if has_surface(args):
        from reduced.roughness import uc_table
        from reduced.roughness.persson import check_gap_parameters, effective_modulus
        import numpy as np
        effective_modulus(1e6, args.nu)                                   # validates nu
        check_gap_parameters(np.array([1.0]), args.uc_method, args.gamma, args.a_c)
        spectrum = spectrum_from_args(args)
        check_spectrum(spectrum.h_rms_m(), "surface")
        return uc_table(spectrum, args.nu, method=args.uc_method, gamma=args.gamma, a_c=args.a_c)
    table = UcTable.from_csv(args.uc_table)
    check_uc_table(table.p_over_E, table.u_c_m, "uc-table: u_c_m")
    return table


def check_run_options(args: argparse.Namespace) -> None:
    """The options every route checks before its model: the forces, the integration's t_max and
    rtol, and kappa (ValueError naming the option)."""
    from validation.guards import check_forces
    check_forces(args.force_N, "--force")
    if not (args.t_max_s > 0 and 0 < args.rtol < 1e-2):
        raise ValueError("--t-max-s, --rtol: need t_max > 0 s and 0 < rtol < 0.01")
    if not (math.isfinite(args.kappa) and args.kappa > 0):
        raise ValueError(f"--kappa: stiffness factor must be > 0, got {args.kappa:g}")


def relaxation_law(value: str):
    """The `RelaxationModulus` of --relaxation: None (none), the default power law, or a CSV."""
    from reduced.viscoelastic import RelaxationModulus, default_relaxation

    if value == "none":
        return None
    return default_relaxation() if value == "default" else RelaxationModulus.from_csv(value)


def refuse_other_options(args, route: str, not_here, why: str) -> None:
    """Refuse, naming them, the options a route replaces or does not model (`not_here`: (option,
    attribute, default) triples) and the paper route's reference conventions; `why` says what the
    route does instead. ValueError."""
    if args.reference_mode:
        raise ValueError(f"--reference-mode: the reference conventions are the paper route's; "
                         f"drop it with --route {route}")
    given = [opt for opt, name, default in not_here if getattr(args, name) != default]
    if given:
        raise ValueError(f"--route: {route} {why}; drop {', '.join(given)}")
