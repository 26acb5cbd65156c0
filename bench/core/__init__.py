"""The `make sim` bench: fmt_core under Verilator with the fixed-point model in lockstep (README.md)."""
