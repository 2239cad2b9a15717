"""Second method: periodic BEM (Polonsky-Keer) mean separation vs Persson/Yang-Persson u(p).

Slow. Run with `scripts/test -m slow tests/test_rough_bem.py -s` to see the measured numbers.
"""

import numpy as np
import pytest
from scipy.special import erfinv

from reduced.roughness.bem import random_surface, solve_contact
from reduced.roughness.persson import Moments, mean_separation
from reduced.roughness.spectrum import self_affine

pytestmark = pytest.mark.slow

L = 1.0


def case(n):
    """Roll-off at 8 q_L (self-averaging plateau), cutoff at 8 grid cells per wavelength."""
    spec = self_affine(H=0.8, q0_per_m=2 * np.pi * 2 / L, qr_per_m=2 * np.pi * 8 / L,
                       q1_per_m=2 * np.pi * (n / 8) / L, h_rms_m=1e-2, n=1000)
    return spec, Moments.of(spec)


@pytest.mark.parametrize("n,seed", [(256, 0), (256, 1), (512, 0)])
def test_bem_mean_separation_matches_persson(n, seed):
    spec, mom = case(n)
    h = random_surface(spec, n, L, seed)
    for area in (0.1, 0.2, 0.3):
        pstar = erfinv(area) * spec.slope_rms() / np.sqrt(2)    # Persson's A/A0 = area
        bem = solve_contact(h, L, pstar, 1.0, tol=1e-7)
        persson = float(mean_separation(mom, pstar, None, 0.45))
        ratio = bem.mean_separation_m / persson
        print(f"n={n} seed={seed} A/A0 Persson {area:.2f} BEM {bem.contact_area_ratio:.3f}  "
              f"u BEM {bem.mean_separation_m:.5f} Persson {persson:.5f} ratio {ratio:.3f} "
              f"({bem.iterations} it)")
        # issue 4: Persson's u and a BEM u agree to roughly 10 % for A/A0 in 0.1 .. 0.35
        assert ratio == pytest.approx(1.0, abs=0.10)
