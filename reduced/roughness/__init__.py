"""Rough-surface contact: power spectra, Persson theory and the critical gap u_c(p).

Public entry points::

    from reduced.roughness import critical_gap_table, preset, read_psd_csv, spectrum_from_line_scan
    table = critical_gap_table(preset("pmma-1.89").spectrum(), 4e6, 0.5, p_over_E)   # a UcTable

Modules: `spectrum` (convention, parametric spectra, 1D <-> 2D), `line_scan`, `separation` (moments,
contact area, mean separation), `persson` (critical junction, the u_c table), `effective_medium` (Bruggeman leak rate), `surfaces`
(calibrated presets), `stored` (the presets' u_c tables, shipped), `bem` (a periodic boundary-element check).
"""

from .line_scan import read_line_scan, spectrum_from_line_scan
from .persson import critical_gap_table, uc_table
from .spectrum import PowerSpectrum, read_psd_csv, self_affine
from .surfaces import load_presets, preset

__all__ = ["PowerSpectrum", "critical_gap_table", "load_presets", "preset",
           "read_line_scan", "read_psd_csv", "self_affine", "spectrum_from_line_scan", "uc_table"]
