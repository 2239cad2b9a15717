"""The interface between the cup and the plane: the contact law and Coulomb's mu, as plain data.

A design is its shape (`fem.geometry.CupGeometry`) and its interface (`ContactLaw`), kept apart:
the same wall may be pressed on soapy glass (frictionless), on a dry plate (coulomb, mu) or held
where it lands (sticking). This module is the one place that checks a law and its mu, whoever
gives them: the Python API (`fem.laws.plane_law`, which turns it into the solver's law object),
a design file's ``[contact]`` table (`contact_from_mapping`), a scene's ``[contact]`` table and
the command line's ``--contact`` / ``--friction``. Each names its fields in its own words (`Spelling`), so every error is one line
that names the field as the user wrote it.

`choose_contact` says which law a run uses: the explicitly given one (command line, scene) wins
over a design file's, which wins over the default (frictionless), and it records where the law
came from for the run's provenance.

Numbers only (no mesh, no solver): importing it costs nothing.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

__all__ = ["ContactLaw", "ContactChoice", "Spelling", "CONTACT_LAWS", "MAX_FRICTION", "API", "FILE",
           "contact_law", "contact_from_mapping", "choose_contact"]

#: the laws of `fem.laws` (`fem.contact` re-exports this tuple; this module imports no FEM machinery)
CONTACT_LAWS = ("frictionless", "sticking", "coulomb")
#: largest Coulomb coefficient accepted: far beyond any real pair (mu = 2 already sticks, docs/stiffness.md)
MAX_FRICTION = 100.0
#: the keys of a design file's [contact] table
CONTACT_KEYS = ("law", "friction")


@dataclass(frozen=True)
class Spelling:
    """How an input names the contact law and Coulomb's mu in its error messages.

    law, friction: the fields' names (the first word of an error); law_is: a law as the input
    writes it (``{}`` is the law); mu_is: how the input gives mu.
    """

    law: str = "contact"
    friction: str = "friction"
    law_is: str = "contact={!r}"
    mu_is: str = "friction=MU"


#: the Python API (`fem.cup.compress_cup(contact=, friction=)`)
API = Spelling()
#: a design or scene file's [contact] table
FILE = Spelling("contact.law", "contact.friction", 'law = "{}"', "friction = MU")


@dataclass(frozen=True)
class ContactLaw:
    """The contact law with the plane and Coulomb's coefficient mu (0 unless law = "coulomb").

    law: "frictionless", "sticking" or "coulomb"; friction: mu in [0, MAX_FRICTION], with
    "coulomb" only. Invalid values raise ValueError (`contact_law` spells the fields otherwise).
    """

    law: str = "frictionless"
    friction: float = 0.0

    def __post_init__(self) -> None:
        _check(self.law, self.friction, API)
        object.__setattr__(self, "friction", float(self.friction))

    def describe(self) -> dict[str, Any]:
        """Plain data: ``{"law": ...}``, with ``"friction"`` for coulomb (the [contact] table's keys)."""
        return {"law": self.law, **({"friction": self.friction} if self.law == "coulomb" else {})}

    def label(self) -> str:
        """Short text: "sticking", "coulomb mu = 0.3"."""
        return f"coulomb mu = {self.friction:g}" if self.law == "coulomb" else self.law


@dataclass(frozen=True)
class ContactChoice:
    """The law a run uses and where it came from ("command line", "geometry file g.toml", ...)."""

    contact: ContactLaw
    source: str

    def describe(self) -> dict[str, Any]:
        """Plain data for provenance: law, friction (coulomb), source."""
        return {**self.contact.describe(), "source": self.source}


def contact_law(law: Any, friction: Any = None, spelling: Spelling = API) -> ContactLaw:
    """A checked `ContactLaw` from raw input: `friction` None means "not given" (coulomb needs it,
    the other laws refuse any value). ValueError names the fields as `spelling` writes them."""
    if friction is None:
        if law == "coulomb":
            raise ValueError(f"{spelling.friction}: {spelling.law_is.format('coulomb')} needs "
                             f"{spelling.mu_is}, in [0, {MAX_FRICTION:g}]")
        friction = 0.0
    elif law != "coulomb" and law in CONTACT_LAWS:
        _refuse_mu(law, friction, spelling)
    _check(law, friction, spelling)
    return ContactLaw(law, float(friction))


def contact_from_mapping(table: Any, source: str = "design") -> ContactLaw:
    """The `ContactLaw` of a file's ``[contact]`` table: ``law`` (required) and ``friction``
    (required with coulomb, refused otherwise). ValueError: one line naming ``contact.<key>``."""
    if not isinstance(table, Mapping):
        raise ValueError(f"{source}: contact must be a table with the keys {', '.join(CONTACT_KEYS)}")
    unknown = sorted(set(table) - set(CONTACT_KEYS))
    if unknown:
        raise ValueError(f"{source}: contact.{unknown[0]}: unknown key; allowed: {', '.join(CONTACT_KEYS)}")
    if "law" not in table:
        raise ValueError(f"{source}: contact.law: missing; one of {', '.join(CONTACT_LAWS)}")
    try:
        return contact_law(table["law"], table.get("friction"), FILE)
    except ValueError as exc:
        raise ValueError(f"{source}: {exc}") from None


def choose_contact(law: str | None, friction: float | None, given_by: str,
                   design: ContactLaw | None = None, design_by: str = "design file",
                   spelling: Spelling = API) -> ContactChoice:
    """The law a run uses: the one given explicitly (`law`, `friction`; None = not given) wins over
    the design's, which wins over frictionless. A `friction` given without a law sets the mu of a
    coulomb design (else it is refused as mu without coulomb). The source names who chose."""
    if law is not None:
        return ContactChoice(contact_law(law, friction, spelling), given_by)
    if design is None:
        return ContactChoice(contact_law("frictionless", friction, spelling), "default")
    if friction is None:
        return ContactChoice(design, design_by)
    if design.law != "coulomb":
        raise ValueError(f"{spelling.friction}: applies to {spelling.law_is.format('coulomb')} only, but "
                         f"the {design_by} has {FILE.law_is.format(design.law)}")
    return ContactChoice(contact_law("coulomb", friction, spelling),
                         f"{design_by} (law), {given_by} (friction)")


def _refuse_mu(law: str, friction: Any, spelling: Spelling) -> None:
    raise ValueError(f"{spelling.friction}: applies to {spelling.law_is.format('coulomb')} only, got "
                     f"{_show(friction)} with {spelling.law_is.format(law)}")


def _show(value: Any) -> str:
    return f"{value:g}" if _is_number(value) else repr(value)


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _check(law: Any, friction: Any, spelling: Spelling) -> None:
    """The law is one of CONTACT_LAWS; mu a number, 0 but with coulomb, in [0, MAX_FRICTION]."""
    if law not in CONTACT_LAWS:
        raise ValueError(f"{spelling.law}: must be one of {', '.join(CONTACT_LAWS)}, got {law!r}")
    if not _is_number(friction):
        raise ValueError(f"{spelling.friction}: Coulomb's friction coefficient must be a number in "
                         f"[0, {MAX_FRICTION:g}], got {friction!r}")
    if law != "coulomb" and friction != 0.0:
        _refuse_mu(law, friction, spelling)
    if not (math.isfinite(friction) and 0.0 <= friction <= MAX_FRICTION):
        raise ValueError(f"{spelling.friction}: Coulomb's friction coefficient must be in "
                         f"[0, {MAX_FRICTION:g}], got {friction:g}")
