"""The cocotb engine of the ``make sim`` bench: ``run_scene`` drives
``fmt_core_sim_top`` (bench/core/fmt_core_sim_top.v: fmt_core + the Verilog channel
fmt_channel_sim + the coupling-update player + loggers) through the phases of a job.

``run_scene`` reads a job file (FMT_CORE_JOB, written by run_sim_rtl.prepare): it loads
the calibration through the core's local register bus, resets the core again (the
calibration RAM keeps its contents, the registers return to their reset values),
programs the settings in the first cycles after the reset, and runs the clock for the
job's cycles with no Python on the per-cycle path (the loggers write heat-map beats,
events and frame ends to files).  With FMT_CORE_UART=1 it then talks to the control
port over the UART (fmt.protocol): SCRATCH write/read, ID, FRAME_COUNT, the latency
counters, a heat-map snapshot (SNAP_REQ, SNAP_STATUS, BLKREAD of the HEATMAP window)
and the latency histogram window.  The result goes to the job's ``out`` file.

Loaded by the simulator (cocotb test module ``core_cocotb``, test_dir bench/core):
``python -m bench.core.run_sim_rtl --engine cocotb`` and tb/fmt_core/test_fmt_core*.py.
The C++ harness (sim_main.cpp) replays the same phases cycle for cycle.
"""
from __future__ import annotations

import json
import os
import sys
import time
from pathlib import Path

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, FallingEdge, First, ReadOnly, RisingEdge

from fmt import params, protocol, regmap
from fmt.progress import Progress

UART_DIV = 4


class TB:
    """Clock, resets, the local register bus and a bit-level UART of the sim top."""

    def __init__(self, dut):
        self.dut = dut
        self.clk = dut.clk
        cocotb.start_soon(Clock(dut.clk, 8, unit="ns").start())
        for s in ("rst", "bus_we_i", "bus_re_i", "bus_addr_i", "bus_wdata_i", "trig_i", "flush_i", "play_i"):
            getattr(dut, s).value = 0
        dut.ev_ready_i.value = 1
        dut.uart_rx_i.value = 1

    async def writable(self):
        await FallingEdge(self.clk)

    async def reset(self, cycles: int):
        await self.writable()
        self.dut.rst.value = 1
        await ClockCycles(self.clk, cycles)
        await self.writable()
        self.dut.rst.value = 0

    async def bus_writes(self, writes):
        """(name, value) register writes, one per cycle, starting at the next edge."""
        d = self.dut
        await self.writable()
        for name, val in writes:
            d.bus_we_i.value = 1
            d.bus_addr_i.value = regmap.lookup(name).addr
            d.bus_wdata_i.value = int(val) & 0xFFFFFFFF
            await RisingEdge(self.clk)
            await self.writable()
        d.bus_we_i.value = 0

    async def bus_read(self, name: str) -> int:
        d = self.dut
        await self.writable()
        d.bus_re_i.value = 1
        d.bus_addr_i.value = regmap.lookup(name).addr
        await RisingEdge(self.clk)
        await self.writable()
        d.bus_re_i.value = 0
        await RisingEdge(self.clk)
        await ReadOnly()
        return int(d.bus_rdata_o.value)

    # ---- UART (8N1, UART_DIV clk per bit) ----
    async def uart_send(self, data: bytes):
        d = self.dut
        for b in data:
            bits = [0] + [(b >> i) & 1 for i in range(8)] + [1]
            for v in bits:
                await self.writable()
                d.uart_rx_i.value = v
                await ClockCycles(self.clk, UART_DIV)

    async def uart_recv(self, n_bytes_max: int, idle_bits: int = 12) -> bytes:
        """Bytes from uart_tx_o: wait for the first start bit, then take bytes until the
        line has been idle for idle_bits bit times (edge triggers, no per-cycle polling)."""
        d = self.dut
        out = bytearray()
        first = True
        while len(out) < n_bytes_max:
            limit = 400000 if first else idle_bits * UART_DIV
            t = await First(FallingEdge(d.uart_tx_o), ClockCycles(self.clk, limit))
            if not isinstance(t, FallingEdge):
                break
            first = False
            await ClockCycles(self.clk, UART_DIV // 2)      # middle of the start bit
            v = 0
            for i in range(8):
                await ClockCycles(self.clk, UART_DIV)
                await ReadOnly()
                v |= int(d.uart_tx_o.value) << i
            await ClockCycles(self.clk, UART_DIV)           # middle of the stop bit
            out.append(v)
        return bytes(out)

    async def request(self, req: bytes, cmd: int, seq: int, max_bytes: int = 4096) -> bytes:
        rx = cocotb.start_soon(self.uart_recv(max_bytes))
        await self.uart_send(req)
        data = await rx
        frames = protocol.decode(data)
        assert frames, f"no reply to command 0x{cmd:02X} (got {data.hex()})"
        return protocol.check_reply(frames[0], seq, cmd)


async def uart_checks(tb: TB, res: dict):
    """Register access, counters and the snapshot over the UART; results into res."""
    seq = 1

    async def rd(name, count=1):
        nonlocal seq
        seq = (seq + 1) & 0xFF
        p = await tb.request(protocol.req_read(seq, regmap.lookup(name).addr, count), protocol.CMD_READ, seq)
        return protocol.payload_words(p)

    async def wr(name, vals):
        nonlocal seq
        seq = (seq + 1) & 0xFF
        await tb.request(protocol.req_write(seq, regmap.lookup(name).addr, vals), protocol.CMD_WRITE, seq)

    async def blk(addr, count):
        nonlocal seq
        seq = (seq + 1) & 0xFF
        p = await tb.request(protocol.req_blkread(seq, addr, count), protocol.CMD_BLKREAD, seq, 16 + 4 * count)
        return protocol.payload_words(p)

    u = {}
    await wr("SCRATCH", [0x5A5AC3C3])
    u["scratch"] = (await rd("SCRATCH"))[0]
    u["id"] = (await rd("ID"))[0]
    names = ("LAT_FIRST_LAST", "LAT_FIRST_MIN", "LAT_FIRST_MAX", "LAT_FIRST_COUNT",
             "LAT_LAST_LAST", "LAT_LAST_MIN", "LAT_LAST_MAX", "LAT_LAST_COUNT")
    u.update(zip(names, await rd(names[0], len(names))))     # consecutive addresses
    u["hist"] = await blk(regmap.WINDOW_BY_NAME["LAT_HIST"].base, 16)
    await wr("SNAP_REQ", [1])
    cfg = params.get(os.environ.get("FMT_CORE_CFG", "small"))
    for _ in range(50):
        st = (await rd("SNAP_STATUS"))[0]
        if st >> 31:
            break
    u["snap_status"] = st
    u["snap"] = await blk(regmap.WINDOW_BY_NAME["HEATMAP"].base, cfg.rows * cfg.cols)
    res["uart"] = u


@cocotb.test()
async def run_scene(dut):
    job = json.loads(Path(os.environ["FMT_CORE_JOB"]).read_text())
    quiet = os.environ.get("FMT_QUIET", "0") == "1"
    tb = TB(dut)
    # phase 1: calibration into fmt_touch's RAM (kept through reset)
    await tb.reset(8)
    await tb.bus_writes(job["cal"])
    # phase 2: the run; the player loads G0 during the reset
    await tb.writable()
    dut.play_i.value = 1
    await tb.reset(job["reset_cycles"])
    await tb.bus_writes(job["regs"])
    t0 = time.perf_counter()
    total = job["run_cycles"]
    step = max(1000, total // 50)
    done = len(job["regs"])
    bar = Progress(total)
    # register writes during the run: [cycle (counted like `done`), name, value]
    mid = sorted(job.get("mid_regs", []), key=lambda w: w[0])
    res_mid = []
    while done < total:
        n = min(step, total - done)
        if mid and mid[0][0] - done < n:
            n = max(0, mid[0][0] - done)
        if n:
            await ClockCycles(dut.clk, n)
            done += n
        while mid and mid[0][0] <= done:
            _, name, val = mid.pop(0)
            await tb.bus_writes([(name, val)])
            res_mid.append([int(dut.cycle_o.value), name, int(val)])   # the write's edge
            done += 1
        if not quiet and total > 200000:
            fr = int(dut.frames_o.value)
            rate = fr / max(time.perf_counter() - t0, 1e-9)
            bar.update(done, f"  fmt_core: frame {fr}/{job['frames']}  ({rate:.0f} frames/s)")
    if not quiet and total > 200000:
        bar.close()
    wall = time.perf_counter() - t0
    res = {"wall_s": wall, "frames": int(dut.frames_o.value), "events": int(dut.events_o.value),
           "mid_regs": res_mid,
           "upd_late": int(dut.upd_late_o.value), "upd_done": int(dut.upd_done_o.value),
           "clip": int(dut.clip_o.value)}
    # stop the event consumer so that the counters hold still while they are read
    await tb.writable()
    dut.ev_ready_i.value = 0
    await ClockCycles(dut.clk, 4)
    res["status_cycle"] = int(dut.cycle_o.value)
    res["frames_before_status"] = int(dut.frames_o.value)
    st = {}
    for n in ("FRAME_COUNT", "STATUS", "EV_DROP_COUNT", "EV_SKIP_COUNT", "FLAT_SAT_COUNT",
              "LM_DROP_COUNT", "LAT_FIRST_MIN", "LAT_FIRST_MAX", "LAT_FIRST_COUNT",
              "LAT_LAST_MIN", "LAT_LAST_MAX", "LAT_LAST_COUNT"):
        st[n] = await tb.bus_read(n)
    res["status"] = st
    res["frames_at_status"] = int(dut.frames_o.value)
    # calibration window read-back (after the compared frames: changes one cell)
    await tb.bus_writes([("CAL_ROW", 1), ("CAL_COL", 2), ("CAL_OFFSET", 0x123)])
    await ClockCycles(dut.clk, 20)
    res["cal_rb"] = [await tb.bus_read("CAL_OFFSET"), await tb.bus_read("CAL_GAIN")]
    if os.environ.get("FMT_CORE_UART", "0") == "1":
        await uart_checks(tb, res)
    await tb.writable()
    dut.flush_i.value = 1
    await RisingEdge(dut.clk)
    await tb.writable()
    dut.flush_i.value = 0
    await ClockCycles(dut.clk, 2)
    Path(job["out"]).write_text(json.dumps(res))
