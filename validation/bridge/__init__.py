"""The bridge between the two halves, as a library: typed values in, typed values out, no
command line, no argparse namespaces.

- `design`: the cup a curve or table was computed for (`resolve_cup`, `CupChoice`);
- `pipeline`: the FEM pipeline written once (design -> mesh -> material -> contact law -> curve);
- `handoff`: the stiffness curve and its sidecar, the FEM's hand-off to the reduced model;
- `coupled`: the FEM suction table of a design and the coupled route's model;
- `lifetimes`: every lifetime, through `reduced.solve_lifetime`;
- `study`, `products`: one case end to end and its lazily computed, content-cached products;
- `cache`: the one content-keyed cache.

The applications (`validation.cli` and its commands, scenes, sweeps, render, crosscheck) call it.
"""
