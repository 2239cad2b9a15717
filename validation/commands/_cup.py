"""The cup options, one meaning in every command: which cup (`--cup`, `--geometry FILE`), for the
FEM the contact law (`--contact`, `--friction`) and, for the lifetime, where r(h), V(h), l(h) come
from (`--cup-laws`) and the reduced model's start.

`--cup` takes A or B in any case; `--geometry` is always a design file (.toml or .json, the keys of
`fem.design_file.load_design`, with an optional [contact] table). Shared by `stiffness`, `lifetime`,
`example` and `suction`. The flags, their types, choices and defaults are the study's fields
(`validation.study_schema.add_flags`); the help here says what each means on the command line.
`--contact`/`--friction` given on the command line win over the design
file's [contact] table, which wins over frictionless (`contact_choice`).
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import TYPE_CHECKING

if TYPE_CHECKING:                          # building the parser imports no fem
    from fem.design_file import Design
    from fem.interface import ContactChoice

from reduced.cup import CUPS
from validation.study_schema import add_flags, field_of


def cup_name(value: str) -> str:
    """argparse type: a Table 1 preset name, case-insensitive."""
    key = value.strip().upper()
    if key not in CUPS:
        raise argparse.ArgumentTypeError(f"invalid cup {value!r} (choose from {', '.join(CUPS)}, any case)")
    return key


def design_file(value: str) -> Path:
    """argparse type: a geometry file (the former cone|curve meaning moved to --cup-laws)."""
    if value in ("cone", "curve"):
        raise argparse.ArgumentTypeError(f"'{value}' is not a geometry file: the cone/curve choice "
                                         f"is --cup-laws {value}")
    return Path(value)


def add_cup_arguments(parser: argparse.ArgumentParser, role: str):
    """--cup, --geometry FILE, --allow-unusual-design in a group "cup" (returned for more options);
    `role` says what the cup is used for."""
    g = parser.add_argument_group("cup")
    add_flags(g, ("cup.preset", "cup.geometry", "cup.allow_unusual_design"), helps={
        "cup.preset": "Table 1 cup preset, any case (A: alpha 33 deg, d 2.5 -> 0.3 mm; B: 21 deg, "
                      f"1.5 -> 0.3 mm; r0 5 mm, r1 19 mm); {role} (default: A)",
        "cup.geometry": "your design (.toml or .json; keys cup, r0_mm, r1_mm, alpha_deg, "
                        "thickness_convention, thickness = {r_mm = [...], d_mm = [...]}, and "
                        "optionally contact = {law = ..., friction = MU}, the FEM's contact law "
                        "unless --contact is given), starting from --cup",
        "cup.allow_unusual_design": "accept a cone angle outside 5..80 deg or a wall more than 400x longer "
                                    "than thick (refused by default: the FEM meshes cannot resolve them)"},
        **{"--cup": {"type": cup_name, "metavar": "A|B"}, "--geometry": {"type": design_file}})
    return g




def add_cup_law_arguments(parser: argparse.ArgumentParser, default_route: str = "paper") -> None:
    """--route, --cup-laws, --r-start-mm, --l0-mm, --l1-mm: the reduced model's cup and seal."""
    g = parser.add_argument_group("reduced-model cup")
    add_flags(g, ("stiffness.route",), defaults={"stiffness.route": default_route}, helps={"stiffness.route":
                   "what the leak crosses: paper (eqs 3-7: one strip at the uniform pressure of "
                        "eq 6, beta = 0.8), or profile (the FEM curve's own contact-pressure profile "
                        "p(r) + beta (p_a - p_b), ring by ring, with its r_c and V; needs an FEM curve; "
                        "not mesh-converged where only the sharp rim corner touches, see docs/lifetime.md), "
                        "or coupled (lifetime and example: the cup's state from the FEM's (u, dp) suction table of "
                        "`cupcheck suction`, --suction-table; replaces eqs 3-7 and beta), or fem (lifetime and example: "
                        "the cup pressed, sealed and held at F1 along its FEM equilibrium branch while "
                        "the gas leaks in through each state's own profile; --contact, --fidelity) "
                        f"(default: {default_route})"})
    g.add_argument("--cup-laws", default=None, choices=("cone", "curve"),
                   help="r(h), V(h), l(h) from the rigid-cone laws eqs 3-5 with the cup's r0, r1, "
                        "alpha (cone), or from the stiffness curve's r_c_mm, V_mm3, l_mm columns "
                        "(curve; l = 0 is a line contact, sealed) (default: cone for the paper route, "
                        "curve for the profile route, which needs it)")
    add_flags(g, ("loads.r_start_mm", "cup.l0_mm", "cup.l1_mm"), helps={
        "loads.r_start_mm": "inner contact radius after pressing on, in (r0, r1) mm (default: 12 mm "
                            "for cups A and B (Table 1), (r0 + r1)/2 for other designs)",
        "cup.l0_mm": "eq (5)'s strip width at r0 in mm (default: Table 1 for cups A and B; for "
                     "other designs fitted to the FEM curve's l(r_c))",
        "cup.l1_mm": "eq (5)'s strip width at r1 in mm (with --l0-mm)"})


def cup_laws(args: argparse.Namespace, coupled: bool = False, fem: bool = False) -> str:
    """Where r(h), V(h), l(h) come from for the --route and --cup-laws given
    (`validation.bridge.lifetimes.route_laws`: the route's default, or --cup-laws checked against it).
    `coupled`, `fem`: the command runs that route itself (else it is refused here)."""
    from validation.bridge.lifetimes import route_laws

    if args.route == "coupled" and not coupled:
        raise ValueError("--route: coupled is a route of `cupcheck lifetime` (with --suction-table)")
    if args.route == "fem" and not fem:
        raise ValueError("--route: fem is a route of `cupcheck lifetime` and `cupcheck example`")
    return route_laws(args.route, args.cup_laws)


#: `fem.interface.CONTACT_LAWS`, spelled out so that building the parser imports no fem (a test pins them equal)
CONTACT_CHOICES = field_of("contact.law").choices


def add_contact_arguments(group: argparse._ArgumentGroup, default: str) -> None:
    """--contact and --friction (None when not given: the design file's [contact] table, else
    frictionless); `default` says why frictionless is the default for this command."""
    add_flags(group, ("contact.law", "contact.friction"), helps={
        "contact.law": "contact with the plane: frictionless, sticking (a touching point stops "
                       "sliding), or coulomb (stick while |t| <= mu p, slide otherwise; give "
                       "--friction) (default: the --geometry file's [contact] law, else "
                       f"frictionless: {default})",
        "contact.friction": "Coulomb's friction coefficient mu, in [0, 100] (with --contact coulomb, "
                            "or alone to change the mu of a coulomb design file)"},
        **{"--friction": {"metavar": "MU"}})


def contact_choice(args: argparse.Namespace, design: Design | None = None) -> ContactChoice:
    """The FEM's contact law and where it came from (`fem.interface.choose_contact`): --contact,
    --friction over the design file's (``args.geometry``) [contact] table over frictionless."""
    from fem.interface import Spelling, choose_contact

    cli = Spelling("contact", "friction", "--contact {}", "--friction MU")
    file_label = f"geometry file {Path(args.geometry).name}" if args.geometry is not None else "design"
    return choose_contact(args.contact, args.friction, "command line",
                          None if design is None else design.contact, file_label, cli)


def load_cup_design(args: argparse.Namespace) -> Design:
    """The design of --geometry FILE (on top of --cup), or the --cup preset (cup A) without a file."""
    from fem.design_file import Design
    from fem.geometry import cup_geometry
    from validation.guards import load_design as guarded_design

    if args.geometry is not None:
        return guarded_design(args.geometry, cup=args.cup or "A", allow_unusual=args.allow_unusual_design)
    return Design(cup_geometry(args.cup or "A"))
