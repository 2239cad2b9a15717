"""Calibrated surface presets: the paper's sandblasted PMMA and table surfaces (Sec. 5.1).

The measured spectra of the paper are not available, so each preset is a *calibrated* parametric
spectrum (`spectrum.self_affine`): the paper's rms roughness, the stylus scan length as the
largest wavelength (q0 = 2 pi / 25 mm), a shared Hurst exponent and cutoff, and one free shape
parameter, the roll-off wavevector q_r, chosen so that u_c at p = 1 atm, E = 4 MPa, nu = 0.5
(default method, gamma and a_c) matches the paper's value (1.17, 0.68, 0.40, 0.21 um for rms 2.51,
1.89, 1.08, 0.77 um; table ~0.85 um).

Why this family: at fixed rms, u_c at fixed pressure is set mainly by the rms slope, i.e. by where
the roughness power sits; the roll-off q_r moves it monotonically (larger q_r, more slope, larger
u_c), so one scalar per surface reproduces each target and a root-finder can find it. The
four PMMA targets are not consistent with one shared (H, q_r): u_c/h_rms is 0.27, 0.37, 0.36, 0.47,
not monotone in h_rms, so q_r has to differ from surface to surface (see the stored values). H = 0.8
is typical of sandblasted surfaces; q1 = 1e7 1/m (wavelength 0.6 um) sits just beyond the 1 um
stylus tip, the shortest scale the paper measured. The table surface has a log-normal hump at
q_h = 1e5 1/m (wavelength ~0.06 mm, Fig. 1logq.2logC1D.BoTable) carrying a fixed share of the
mean-square height; there the roll-off is fixed at q_r = 1e3 1/m and the calibrated scalar is
the hump's share of <h^2> (with the hump carrying most of the rms, u_c comes out near 10 um, far
above 0.85 um, for every roll-off: the bump is a feature on top of long-wavelength roughness).

The calibration (parameters, target, achieved value, conditions) is stored in
``data/presets.json``; ``python -m reduced.roughness.surfaces`` recomputes and rewrites it, and the
presets' u_c tables (`reduced.roughness.stored`; ``--tables``: only these).
"""

from __future__ import annotations

import json
import sys
from dataclasses import dataclass
from importlib import resources

import numpy as np

from . import stored
from .persson import UC_TABLE_P_OVER_E, critical_gap_table, uc_table
from .spectrum import PowerSpectrum, self_affine

ATM_PA = 101325.0
#: calibration conditions (the paper, Sec. 5.1)
CAL_P_PA, CAL_E_PA, CAL_NU = ATM_PA, 4e6, 0.5
Q0_SCAN = 2 * np.pi / 25e-3          # 25 mm stylus scans
SHARED = {"H": 0.8, "q0_per_m": Q0_SCAN, "q1_per_m": 1e7}

#: name -> (description, rms [m], target u_c at 1 atm [m], fixed shape parameters, free parameter)
TARGETS: dict[str, tuple[str, float, float, dict, str]] = {
    "pmma-0.77": ("sandblasted PMMA, rms 0.77 um (60 s)", 0.77e-6, 0.21e-6, {}, "qr_per_m"),
    "pmma-1.08": ("sandblasted PMMA, rms 1.08 um", 1.08e-6, 0.40e-6, {}, "qr_per_m"),
    "pmma-1.89": ("sandblasted PMMA, rms 1.89 um", 1.89e-6, 0.68e-6, {}, "qr_per_m"),
    "pmma-2.51": ("sandblasted PMMA, rms 2.51 um (180 s)", 2.51e-6, 1.17e-6, {}, "qr_per_m"),
    "table": ("table surface, rms 7.7 um, quasi-periodic hump near q = 1e5 1/m", 7.7e-6, 0.85e-6,
              {"qr_per_m": 1e3, "hump_q_per_m": 1e5, "hump_width": 0.35}, "hump_fraction"),
}
#: bracket (in log) of each free parameter for the root-finder
BRACKETS = {"qr_per_m": (SHARED["q0_per_m"] * 1.01, SHARED["q1_per_m"] / 1.5),
            "hump_fraction": (1e-4, 0.5)}


def spectrum_of(params: dict, n: int = 2000) -> PowerSpectrum:
    """`self_affine` from a flat parameter dict (hump given as hump_fraction/_q_per_m/_width)."""
    p = dict(params)
    hump = None
    if "hump_fraction" in p:
        hump = (p.pop("hump_fraction"), p.pop("hump_q_per_m"), p.pop("hump_width"))
    return self_affine(**p, hump=hump, n=n)


@dataclass(frozen=True)
class Preset:
    """A calibrated parametric surface (parameters of `self_affine` plus its calibration record)."""

    name: str
    description: str
    params: dict
    calibration: dict

    def spectrum(self, n: int = 2000) -> PowerSpectrum:
        spec = spectrum_of(self.params, n)
        return PowerSpectrum(spec.q_per_m, spec.C_m4, provenance=f"preset:{self.name} ({spec.provenance})")


def _uc_at_calibration(params: dict, method: str = "emt") -> float:
    table = critical_gap_table(spectrum_of(params), CAL_E_PA, CAL_NU, [CAL_P_PA / CAL_E_PA],
                               method=method)
    return float(table.u_c_m[0])


def calibrate(name: str, method: str = "emt") -> Preset:
    """Solve u_c(1 atm, 4 MPa, 0.5) = the paper's value for the free parameter of preset `name`."""
    desc, h_rms, target, fixed, free = TARGETS[name]
    base = dict(SHARED, h_rms_m=h_rms, **fixed)

    def miss(ln_x: float) -> float:
        u_c = _uc_at_calibration(dict(base, **{free: float(np.exp(ln_x))}), method)
        return np.log(max(u_c, 1e-15) / target)

    from scipy.optimize import brentq     # here: calibration only

    lo, hi = np.log(BRACKETS[free])
    params = dict(base, **{free: float(np.exp(brentq(miss, lo, hi, xtol=1e-6)))})
    achieved = _uc_at_calibration(params, method)
    record = {"p_Pa": CAL_P_PA, "E_Pa": CAL_E_PA, "nu": CAL_NU, "method": method,
              "gamma": 0.45, "a_c": 0.42, "target_u_c_m": target, "achieved_u_c_m": achieved,
              "free_parameter": free, "reproduce": "python -m reduced.roughness.surfaces"}
    return Preset(name, desc, params, record)


def load_presets() -> dict[str, Preset]:
    """The stored presets, by name."""
    text = resources.files("reduced.roughness").joinpath("data/presets.json").read_text()
    return {d["name"]: Preset(d["name"], d["description"], d["params"], d["calibration"])
            for d in json.loads(text)}


def preset(name: str) -> Preset:
    presets = load_presets()
    if name not in presets:
        raise ValueError(f"surface: unknown preset {name!r}; choose one of {sorted(presets)}")
    return presets[name]


def store_tables() -> None:
    """Compute every preset's u_c table at `uc_table`'s defaults (nu = `stored.STORED_NU`) and
    store them (data/uc_tables.json)."""
    tables = {}
    for name, p in load_presets().items():
        spectrum = p.spectrum()
        key = stored.request_key(spectrum, stored.STORED_NU, "emt", 0.45, 0.42, UC_TABLE_P_OVER_E, True)
        tables[key] = stored.entry(name, uc_table(spectrum, stored.STORED_NU, stored=False))
        print(f"{name:10s} u_c table {key}", file=sys.stderr)
    print(stored.write(tables), file=sys.stderr)


def main(argv: list[str] | None = None) -> int:
    """Recalibrate every preset and rewrite data/presets.json and the stored u_c tables
    (``--tables``: the tables only)."""
    if "--tables" in (sys.argv[1:] if argv is None else argv):
        store_tables()
        return 0
    out = []
    for name in TARGETS:
        p = calibrate(name)
        c = p.calibration
        free = c["free_parameter"]
        print(f"{name:10s} {free} = {p.params[free]:.5g}  u_c = {c['achieved_u_c_m'] * 1e6:.4f} um "
              f"(target {c['target_u_c_m'] * 1e6:.2f})", file=sys.stderr)
        out.append({"name": p.name, "description": p.description, "params": p.params,
                    "calibration": c})
    path = resources.files("reduced.roughness").joinpath("data/presets.json")
    with open(path, "w") as f:
        json.dump(out, f, indent=1)
        f.write("\n")
    store_tables()
    return 0


if __name__ == "__main__":
    sys.exit(main())
