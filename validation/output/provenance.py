"""The versions every output's provenance records."""

from __future__ import annotations

import platform

#: the packages whose versions every output's provenance records
_PACKAGES = ("cupcheck", "numpy", "scipy", "scikit-fem", "meshio")


def software_versions() -> dict[str, str]:
    """Versions of Python and of the packages the FEM result depends on."""
    from importlib import metadata      # slow to import: only when a provenance is written

    versions = {"python": platform.python_version()}
    for name in _PACKAGES:
        try:
            versions[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            versions[name] = "not installed"
    return versions
