"""Bit-level UART (8N1) bus-functional model for cocotb: drives an RTL receive pin and
decodes an RTL transmit pin, DIV clock cycles per bit (the RTL's own clock).

Shared by the testbenches of fmt_uart, fmt_ctrl_port and fmt_fmtctl.

Own code, not cocotb-bus: cocotb-bus 0.3.0 has no UART (its drivers and monitors are
AMBA, Avalon, OPB and XGMII), and a BusMonitor over one serial pin would still need
this bit timing (start-bit search, mid-bit sampling every DIV cycles, stop-bit check).
"""
from __future__ import annotations

import cocotb
from cocotb.queue import Queue
from cocotb.triggers import ClockCycles, FallingEdge, ReadOnly, RisingEdge, with_timeout
from cocotb.utils import get_sim_time


class UartBfm:
    def __init__(self, clk, rxd, txd, div: int, period_ns: int = 24):
        self.period_ns = period_ns
        self.clk = clk
        self.rxd = rxd              # the DUT's receive input (we drive it)
        self.txd = txd              # the DUT's transmit output (we decode it)
        self.div = div
        self.rx_queue: Queue = Queue()   # (byte, stop_bit_ok) decoded from txd
        self.bit_errors: list[str] = []
        self.start_times: list[int] = []     # sim time (ns) of each start bit decoded on txd
        self.sent_end_ns = 0                 # sim time at the end of the last stop bit we drove
        self.rxd.value = 1
        self._mon = cocotb.start_soon(self._monitor())

    # ---- drive ---------------------------------------------------------------------
    async def send_byte(self, b: int, stop: int = 1) -> None:
        bits = [0] + [(b >> i) & 1 for i in range(8)] + [stop]
        for v in bits:
            self.rxd.value = v
            await ClockCycles(self.clk, self.div)
        self.rxd.value = 1
        self.sent_end_ns = get_sim_time("ns")

    async def send(self, data: bytes, gap_bits: int = 0) -> None:
        for b in data:
            await self.send_byte(b)
            if gap_bits:
                await ClockCycles(self.clk, gap_bits * self.div)

    async def idle(self, bits: int) -> None:
        self.rxd.value = 1
        await ClockCycles(self.clk, bits * self.div)

    # ---- decode ----------------------------------------------------------------------
    async def _sample(self) -> int:
        await ReadOnly()
        v = int(self.txd.value)
        await RisingEdge(self.clk)
        return v

    async def _monitor(self):
        half = self.div // 2
        while True:
            await FallingEdge(self.txd)
            self.start_times.append(get_sim_time("ns"))
            await ClockCycles(self.clk, half)
            if await self._sample() != 0:
                self.bit_errors.append("start bit not low at its middle")
                continue
            b = 0
            for i in range(8):
                await ClockCycles(self.clk, self.div - 1)
                b |= await self._sample() << i
            await ClockCycles(self.clk, self.div - 1)
            stop = await self._sample()
            self.rx_queue.put_nowait((b, stop))
            if not stop:
                self.bit_errors.append(f"stop bit low after byte 0x{b:02X}")

    async def recv(self, n: int, timeout_bits: int = 400) -> bytes:
        """The next n bytes from txd; each must arrive within timeout_bits bit times."""
        out = bytearray()
        for _ in range(n):
            b, _stop = await with_timeout(self.rx_queue.get(),
                                          timeout_bits * self.div * self.period_ns, "ns")
            out.append(b)
        return bytes(out)

    def pending(self) -> int:
        return self.rx_queue.qsize()
