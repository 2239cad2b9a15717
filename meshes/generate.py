"""Regenerate the reference meshes in meshes/ (run from the repository: python meshes/generate.py).

Cups A and B (Table 1, Sec. 5.5) at the coarse and medium fidelity levels of `fem.mesh`, as Gmsh
2.2 ASCII files in millimetres with the boundary tags as physical curves. The example user
design `user_lip.msh` (quad9) and `user_lip_tri.msh` (triangle6) are meshed by Gmsh itself from
`user_lip.geo` when the `gmsh` Python module is installed (``pip install gmsh``; not a cupcheck dependency); otherwise the committed file is
kept.
"""

from __future__ import annotations

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent))

from fem.geometry import cup_geometry  # noqa: E402
from fem.mesh import cup_mesh  # noqa: E402
from fem.mesh_files import write_mesh  # noqa: E402

CUPS = ("A", "B")
LEVELS = ("coarse", "medium")


def cup_mesh_files(directory: Path = HERE) -> list[Path]:
    """Write cup{A,B}_{coarse,medium}.msh into `directory`; return the paths."""
    return [write_mesh(cup_mesh(cup_geometry(cup), level), directory / f"cup{cup}_{level}.msh", unit="mm")
            for cup in CUPS for level in LEVELS]


def user_design(directory: Path = HERE) -> list[Path]:
    """Mesh user_lip.geo with Gmsh (format 4.1): quad9 (user_lip.msh) and triangle6 (user_lip_tri.msh)."""
    try:
        import gmsh
    except ImportError:
        print("gmsh not installed: keeping the committed user_lip*.msh", file=sys.stderr)
        return []
    out = []
    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.open(str(HERE / "user_lip.geo"))
        for name, recombine in (("user_lip.msh", 1), ("user_lip_tri.msh", 0)):
            gmsh.option.setNumber("Mesh.RecombineAll", recombine)
            gmsh.model.mesh.clear()
            gmsh.model.mesh.generate(2)
            out.append(directory / name)
            gmsh.write(str(out[-1]))
    finally:
        gmsh.finalize()
    return out


if __name__ == "__main__":
    for path in cup_mesh_files() + user_design():
        print(f"wrote {path.relative_to(HERE.parent)} ({path.stat().st_size} bytes)")
