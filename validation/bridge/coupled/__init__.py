"""The coupled cavity route: the FEM's (u, dp) suction grid (`fem.suction`) handed to the reduced
model's `reduced.coupled.CoupledCavity` as a `reduced.suction_table.SuctionTable`, and what the
command line and the report need of it (the table's provenance, beta as the FEM sees it)."""
