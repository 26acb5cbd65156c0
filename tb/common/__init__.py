"""Shared testbench helpers: the cocotb runner wrapper and small drivers."""
