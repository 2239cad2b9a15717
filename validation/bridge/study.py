"""A study: one suction-cup case end to end, as one typed value.

    design -> material -> contact law -> fidelity --> FEM path --> stiffness curve --+
    surface ------------------------------------------> u_c table -----------------+--> lifetimes (route, loads)
    design (Appendix A) ------------------------------> stiffness curve -----------+

`Study` names everything a case depends on (the cup design, the wall's material, the contact law
and who chose it, the mesh level, where the stiffness comes from, the surface, the lifetime route,
the loads) and the outputs asked of it. It is plain frozen data: the command line (`cupcheck
example`), scene files (`cupcheck run`) and sweep files (`cupcheck sweep`) are three spellings of
it. Its products (curve, u_c table, suction table, lifetimes, figures) are computed lazily and
cached by content by `validation.bridge.products.Products`.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import asdict, dataclass, field, replace
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:                          # a study of the reduced model alone imports no fem
    from fem.interface import ContactLaw

__all__ = ["CupDesign", "Material", "Contact", "Surface", "Loads", "Sweep", "Study"]


@dataclass(frozen=True)
class CupDesign:
    """The cup: a Table 1 preset, or a design file (.toml/.json, on top of the preset), or a
    parametric `fem.geometry.CupGeometry` (a sweep's design); eq (5)'s strip widths l0, l1 [mm]
    where given (None: Table 1's for the presets, else fitted to the FEM curve)."""

    preset: str = "A"
    file: str | None = None
    geometry: Any = None
    l0_mm: float | None = None
    l1_mm: float | None = None

    def cup_geometry(self):
        """The `fem.geometry.CupGeometry` of the design."""
        if self.geometry is not None:
            return self.geometry
        from fem.design_file import load_geometry
        from fem.geometry import cup_geometry
        return load_geometry(self.file, cup=self.preset) if self.file else cup_geometry(self.preset)

    @property
    def label(self) -> str:
        if self.geometry is not None:
            return self.geometry.name
        from pathlib import Path
        return Path(self.file).name if self.file else f"cup {self.preset}"


@dataclass(frozen=True)
class Material:
    """The wall's compressible neo-Hookean material (the formulation by nu: `validation.bridge.pipeline`)."""

    E_MPa: float = 4.0
    nu: float = 0.49


@dataclass(frozen=True)
class Contact:
    """The FEM's contact law with the plane (Coulomb's mu with "coulomb" only) and who chose it."""

    law: str = "frictionless"
    friction: float | None = None
    source: str = "default"

    def contact_law(self) -> ContactLaw:
        """The `fem.interface.ContactLaw` the solver receives."""
        from fem.interface import ContactLaw
        return ContactLaw(self.law, float(self.friction or 0.0) if self.law == "coulomb" else 0.0)

    def label(self) -> str:
        return f"coulomb mu = {self.friction:g}" if self.law == "coulomb" else self.law


@dataclass(frozen=True)
class Surface:
    """The rough surface: a calibrated preset (Persson theory, EMT, nu = 0.5) or a u_c table file."""

    preset: str | None = "pmma-1.89"
    uc_table: str | None = None

    @property
    def label(self) -> str:
        if self.uc_table:
            from pathlib import Path
            return Path(self.uc_table).name
        return self.preset


@dataclass(frozen=True)
class Loads:
    """The pull forces F1 [N], the stiffness factor kappa, the contact radius after pressing on
    (None: Table 1's 12 mm for the presets), the relaxation ("none" | "default") and what fills
    the cavity ("air" | "water"). The fem route presses the cup to r_start_mm, or instead to a
    plate displacement press_u_mm [mm] or a pressing force press_force_N [N] (at most one of the
    three given), and follows its branch in plate steps of du_mm [mm]."""

    forces_N: tuple[float, ...] = (5.0, 10.0, 20.0, 40.0, 80.0)
    kappa: float = 1.0
    r_start_mm: float | None = None
    relaxation: str = "none"
    fluid: str = "air"
    press_u_mm: float | None = None
    press_force_N: float | None = None
    du_mm: float = 0.25

    def press(self) -> tuple[str, float] | None:
        """How the fem route presses the cup, as (`validation.bridge.fem_route.Press` kind, value in
        SI), or None: to the cup's r_start (Table 1's or r_start_mm, through the study's cup)."""
        if self.press_u_mm is not None:
            return ("u_m", 1e-3 * self.press_u_mm)
        if self.press_force_N is not None:
            return ("force_N", float(self.press_force_N))
        return None


@dataclass(frozen=True)
class Sweep:
    """One parameter varied for a figure: its key as the scene file writes it and the values."""

    key: str
    values: tuple[Any, ...]


@dataclass(frozen=True)
class Study:
    """One case end to end (module docstring). stiffness: "fem" or "appendix-a" (d0 = 2 mm);
    route: a lifetime route (`validation.bridge.lifetimes.ROUTES`; "fem" keeps the cup in the FEM
    for its whole life, from the design, material, contact law, fidelity and the loads' press); cup_laws: the paper route's r, V, l
    ("cone" or "curve", `validation.bridge.lifetimes.route_laws`; None: the route's own); refine: output points per integration
    step of the lifetimes; suction_table: the coupled route's table file (None: built from the
    design at `fidelity`); stiffness_file: a stiffness curve file (`cupcheck stiffness`) used as
    the FEM curve instead of running the FEM (its design, law, mesh level and material are then
    the study's: `cupcheck example --stiffness`); u_max_mm: the FEM curve's end, the plate
    displacement [mm] (None: 0.9 h1); outputs: what to write (the scene's [[outputs]])."""

    design: CupDesign = CupDesign()
    material: Material = Material()
    contact: Contact = Contact()
    fidelity: str = "coarse"
    stiffness: str = "fem"
    surface: Surface = Surface()
    route: str = "paper"
    cup_laws: str | None = None
    loads: Loads = Loads()
    refine: int = 2
    suction_table: str | None = None
    stiffness_file: str | None = None
    u_max_mm: float | None = None
    outputs: tuple[Mapping[str, Any], ...] = field(default=(), compare=False)
    sweep: Sweep | None = None

    def with_value(self, key: str, value: Any) -> Study:
        """The study with one parameter, named as in a scene file ("loads.kappa", "cup.preset",
        "surface.preset", "loads.r_start_mm", "contact.friction"), set to `value`, and no sweep."""
        part, name = key.split(".")
        if part == "cup":
            return replace(self, design=replace(self.design, preset=value), sweep=None)
        if part == "contact":
            source = f"{self.contact.source} (law), sweep (friction)"
            return replace(self, contact=replace(self.contact, friction=value, source=source), sweep=None)
        attr = {"loads": "loads", "surface": "surface", "material": "material"}[part]
        return replace(self, **{attr: replace(getattr(self, attr), **{name: value})}, sweep=None)

    def variants(self) -> list[tuple[Any, Study]]:
        """(value, the study with that value) for each value of the sweep ([] without one)."""
        if self.sweep is None:
            return []
        return [(v, self.with_value(self.sweep.key, v)) for v in self.sweep.values]

    def record(self) -> dict[str, str]:
        """What a table's rows were computed for, as its leading columns: design, contact (the
        FEM's law; '' for Appendix A), mesh (the FEM's level; '' for Appendix A), route, surface."""
        fem = self.stiffness == "fem"
        return {"design": self.design.label, "contact": self.contact.label() if fem else "",
                "mesh": self.fidelity if fem else "", "route": self.route, "surface": self.surface.label}

    def describe(self) -> dict[str, Any]:
        """Plain data (the manifest's record): every part with its values."""
        data = asdict(replace(self, outputs=(), design=replace(self.design, geometry=None)))
        data.pop("outputs")
        if self.design.geometry is not None:
            data["design"]["geometry"] = self.design.geometry.describe()
        return data
