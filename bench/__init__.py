"""The benches: bench/core is the `make sim` bench (fmt_core through a scene)."""
