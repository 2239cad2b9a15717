"""Design sweeps: many cup designs evaluated on dask.distributed, resumable, with maps of what matters.

- `spec`: the sweep file (base design, axes, grid / Latin hypercube / Sobol sampling), validated;
- `evaluate`: one design end to end (FEM curve -> stiffness, Appendix A ratio, lifetimes), its failures as rows;
- `execute`: the dask run, one committed result per design, the tidy Parquet/CSV table;
- `figures`: maps over two axes and the Pareto front of lifetime against material volume.
"""
