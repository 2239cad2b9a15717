"""Cross-checks, benchmarks, scenes, figures and the `cupcheck` command line (composes fem and reduced)."""
