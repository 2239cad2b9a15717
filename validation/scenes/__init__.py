"""Scenes: say what you want to see, compute only that.

- `schema`: the scene file (cup, material, contact, surface, fluid, loads, stiffness, outputs), validated;
- `pipeline`: the products (u_c table, stiffness curve, lifetimes) computed lazily and cached on disk;
- `outputs`: curves, lifetimes, trajectories and figures written with a manifest; `run_scene`.
"""
