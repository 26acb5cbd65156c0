"""Small cocotb helpers shared by the block testbenches."""
from __future__ import annotations

import os

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import FallingEdge, RisingEdge

# fs = 125/3 MHz -> 24 ns period (the sample clock; cycle counts are what matter).
FS_PERIOD_NS = 24


class ClockedTB:
    """Base class: owns the sample clock and the synchronous reset of a DUT."""

    def __init__(self, dut, clk_name: str = "clk", rst_name: str = "rst", period_ns: int = FS_PERIOD_NS):
        self.dut = dut
        self.clk = getattr(dut, clk_name)
        self.rst = getattr(dut, rst_name)
        self.period_ns = period_ns
        cocotb.start_soon(Clock(self.clk, period_ns, unit="ns").start())

    async def writable(self):
        """Leave a ReadOnly phase: wait for the falling edge, where inputs may change."""
        await FallingEdge(self.clk)

    async def reset(self, cycles: int = 4):
        """Synchronous reset for ``cycles`` rising edges; returns just after the last one
        (the next rising edge is the first with rst low)."""
        await self.writable()
        self.rst.value = 1
        for _ in range(cycles):
            await RisingEdge(self.clk)
        await self.writable()
        self.rst.value = 0

    async def cycles(self, n: int):
        for _ in range(n):
            await RisingEdge(self.clk)


def env_int(name: str, default: int) -> int:
    return int(os.environ.get(name, default))


def env_str(name: str, default: str) -> str:
    return os.environ.get(name, default)
