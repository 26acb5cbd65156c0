"""cocotb testbench of rtl/fmt_uart_tx.v and rtl/fmt_uart_rx.v (through the
simulation-only top tb/fmt_uart/fmt_uart_tb_top.v).

Checks, under both simulators, for an even and an odd divisor: tx -> rx loopback of
random bytes sent back to back; the transmitted waveform decoded bit by bit by an
independent model (uart_bfm) with exact bit timing (DIV clocks per bit, ready/valid
handshake); the receiver fed by the model (random bytes, random idle gaps); glitch
rejection (a low pulse shorter than half a bit is not a start bit); a low stop bit
gives frame_err_o and a held-low line (break) gives no further bytes.
"""
from __future__ import annotations

import random
from pathlib import Path

import cocotb
import pytest
from cocotb.triggers import ClockCycles, ReadOnly, RisingEdge

from common.runner import run_cocotb, sources
from common.tb_util import ClockedTB, env_int
from fmt_uart.uart_bfm import UartBfm

HERE = Path(__file__).parent


class TB(ClockedTB):
    def __init__(self, dut):
        super().__init__(dut)
        self.div = env_int("DIV", 4)
        dut.loop_i.value = 0
        dut.tx_valid_i.value = 0
        dut.tx_data_i.value = 0
        dut.rxd_i.value = 1
        self.received = []            # (byte, frame_err) from the RTL receiver
        cocotb.start_soon(self._rx_collect())

    async def _rx_collect(self):
        while True:
            await RisingEdge(self.clk)
            await ReadOnly()
            if int(self.dut.rx_valid_o.value):
                self.received.append((int(self.dut.rx_data_o.value), int(self.dut.rx_frame_err_o.value)))

    async def tx_send(self, data: bytes):
        """Offer the bytes to the RTL transmitter back to back (valid held); a byte is
        taken at a rising edge where valid and ready are both high."""
        for b in data:
            await self.writable()
            self.dut.tx_data_i.value = b
            self.dut.tx_valid_i.value = 1
            while True:
                await ReadOnly()
                ready = int(self.dut.tx_ready_o.value)
                await RisingEdge(self.clk)
                if ready:
                    break
        await self.writable()
        self.dut.tx_valid_i.value = 0

    async def wait_received(self, n: int, bits: int = 40):
        for _ in range(bits * self.div * max(1, n)):
            if len(self.received) >= n:
                return
            await RisingEdge(self.clk)
        raise AssertionError(f"received {len(self.received)} of {n} bytes")


@cocotb.test()
async def loopback_random(dut):
    """tx -> rx loopback: random bytes back to back arrive unchanged, no framing error."""
    tb = TB(dut)
    dut.loop_i.value = 1
    await tb.reset()
    rng = random.Random(env_int("SEED", 1))
    data = bytes(rng.randrange(256) for _ in range(48)) + b"\x00\xff\x55\xaa"
    await tb.tx_send(data)
    await tb.wait_received(len(data))
    await ClockCycles(tb.clk, 12 * tb.div)
    assert [b for b, _ in tb.received] == list(data)
    assert not any(e for _, e in tb.received)


@cocotb.test()
async def tx_waveform(dut):
    """The transmitter's line, decoded by the bit-level model: values, 8N1 framing, and
    exact timing (a byte every 10 * DIV clocks when valid is held)."""
    tb = TB(dut)
    await tb.reset()
    bfm = UartBfm(tb.clk, dut.rxd_i, dut.txd_o, tb.div, tb.period_ns)
    rng = random.Random(env_int("SEED", 2))
    data = bytes(rng.randrange(256) for _ in range(16))
    edges = []

    async def watch():
        prev = 1
        t = 0
        while True:
            await RisingEdge(tb.clk)
            await ReadOnly()
            t += 1
            v = int(dut.txd_o.value)
            if prev == 1 and v == 0:
                edges.append(t)
            prev = v

    cocotb.start_soon(watch())
    await tb.tx_send(data)
    got = await bfm.recv(len(data))
    assert got == data
    assert not bfm.bit_errors, bfm.bit_errors
    # every start bit follows a high stop bit (or the idle line), so each byte has a
    # falling edge at its start; back to back, starts are exactly 10 * DIV clocks apart
    expect = [edges[0] + 10 * tb.div * i for i in range(len(data))]
    assert all(s in edges for s in expect), (edges[:20], expect)


@cocotb.test()
async def rx_from_model(dut):
    """The model drives the receiver: random bytes with random idle gaps, no errors."""
    tb = TB(dut)
    await tb.reset()
    bfm = UartBfm(tb.clk, dut.rxd_i, dut.txd_o, tb.div, tb.period_ns)
    rng = random.Random(env_int("SEED", 3))
    data = bytes(rng.randrange(256) for _ in range(40))
    for b in data:
        await bfm.send_byte(b)
        if rng.random() < 0.3:
            await ClockCycles(tb.clk, rng.randrange(1, 3 * tb.div))
    await tb.wait_received(len(data))
    assert tb.received == [(b, 0) for b in data]


@cocotb.test()
async def glitch_and_framing(dut):
    """A short low glitch is no start bit; a low stop bit flags frame_err_o; a break
    (line held low) yields no further bytes; then normal reception resumes."""
    tb = TB(dut)
    await tb.reset()
    bfm = UartBfm(tb.clk, dut.rxd_i, dut.txd_o, tb.div, tb.period_ns)
    # glitch: low for fewer clocks than half a bit (minus the vote window)
    glitch = max(1, tb.div // 2 - 2)
    await tb.writable()
    dut.rxd_i.value = 0
    await ClockCycles(tb.clk, glitch)
    dut.rxd_i.value = 1
    await ClockCycles(tb.clk, 20 * tb.div)
    assert tb.received == [], tb.received
    # low stop bit
    await bfm.send_byte(0x3C, stop=0)
    # hold the line low (break) for 30 bit times
    dut.rxd_i.value = 0
    await ClockCycles(tb.clk, 30 * tb.div)
    dut.rxd_i.value = 1
    await ClockCycles(tb.clk, 3 * tb.div)
    assert tb.received == [(0x3C, 1)], tb.received
    await bfm.send(b"\x81\x7e")
    await tb.wait_received(3)
    assert tb.received[1:] == [(0x81, 0), (0x7E, 0)]


# ---- pytest entry ------------------------------------------------------------------
@pytest.mark.parametrize("div", [7])   # odd divisor; DIV = 4 and 5 run in the ctrl-port tests
def test_fmt_uart(sim, div):
    run_cocotb(
        sim=sim,
        toplevel="fmt_uart_tb_top",
        sources=sources("fmt_uart_tx") + sources("fmt_uart_rx") + [HERE / "fmt_uart_tb_top.v"],
        test_module="test_fmt_uart",
        test_dir=HERE,
        parameters={"DIV": div},
        extra_env={"DIV": div},
    )
