"""Field export: displacement, Cauchy stress and contact pressure of a cup step through meshio.

The cells are the 9-node quadrilaterals (or 6-node triangles) of the reference mesh, so
ParaView's "Warp By Vector" with ``displacement`` shows the deformed cup. Point data:
``displacement`` [m] (3 components, u_theta = 0) and ``contact_pressure`` [Pa] (the projected
pressure of `fem.contact`, 0 off contact). Cell data: the element mean (over the 3x3 Gauss points,
weighted by dV) of the Cauchy stress ``sigma_rr, sigma_zz, sigma_tt, sigma_rz`` [Pa].
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING

import meshio
import numpy as np

from .forms import Mechanics
from .kinematics import Kinematics
from .material import cauchy_stress

if TYPE_CHECKING:
    from .cup import CupResponse

__all__ = ["write_fields", "element_cauchy_stress"]

# scikit-fem's Q2 (P2) node order per element equals VTK's biquadratic quad (quadratic triangle)
# order: corners, then edge midpoints starting with edge 0-1, then the centre


def element_cauchy_stress(mech: Mechanics, u: np.ndarray) -> np.ndarray:
    """dV-weighted element means of (s_rr, s_zz, s_tt, s_rz) [4, nel] in Pa."""
    f = mech.kin.deformation_gradient(u)
    s = cauchy_stress(f, mech.stress(f))
    dV = mech.kin.dV
    return np.sum(s * dV, axis=2) / dV.sum(axis=1)


def write_fields(resp: "CupResponse", path: str | Path, step: int = -1) -> Path:
    """Write one step of `resp` to `path` (format from the suffix: .vtu, or any other meshio
    format; meshio's XDMF writer needs h5py, which cupcheck does not depend on), atomically."""
    path = Path(path)
    n_steps = len(resp.u_m)
    if not -n_steps <= step < n_steps:
        raise ValueError(f"step: must be in [{-n_steps}, {n_steps - 1}], got {step}")
    kin = Kinematics.of(resp.mesh)
    mech = Mechanics(kin, resp.material)
    u = resp.displacements[step]
    cells = kin.dofs[0::2].T // 2            # node ids per element, in VTK's node order
    kind = "quad9" if cells.shape[1] == 9 else "triangle6"
    disp = np.zeros((kin.mesh.doflocs.shape[1], 3))
    disp[:, 0], disp[:, 1] = u[0::2], u[1::2]
    sig = element_cauchy_stress(mech, u)
    out = meshio.Mesh(
        points=np.column_stack([kin.mesh.doflocs.T, np.zeros(disp.shape[0])]),
        cells=[(kind, cells)],
        point_data={"displacement": disp, "contact_pressure": resp.nodal_pressure_Pa[step]},
        cell_data={name: [sig[k]] for k, name in
                   enumerate(("sigma_rr", "sigma_zz", "sigma_tt", "sigma_rz"))},
    )
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.stem}.", suffix=path.suffix)
    os.close(fd)
    try:
        out.write(tmp)
        os.replace(tmp, path)
    finally:
        Path(tmp).unlink(missing_ok=True)
    return path
