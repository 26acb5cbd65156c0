"""cocotb testbench of rtl/fmt_core.v through the simulation top
tb/fmt_core/fmt_core_sim_top.v (fmt_core + fmt_channel_sim + coupling-update player +
loggers), against the fixed-point models (sim/fmt/run_sim_rtl.py: fmt_tx_fixed ->
channel twin -> rx_heatmaps_fixed -> touch.process_frames(fixed=True)).

``run_scene`` (also the engine of ``python -m fmt.run_sim_rtl``) reads a job file
(FMT_CORE_JOB): it loads the calibration through the core's local register bus, resets
the core again (the calibration RAM keeps its contents, the registers return to their
reset values), programs the settings in the first cycles after the reset, and runs the
clock for the job's cycles with no Python on the per-cycle path (the loggers write
heat-map beats, events and frame ends to files).  With FMT_CORE_UART=1 it then talks to
the control port over the UART (fmt.protocol): SCRATCH write/read, ID, FRAME_COUNT, the
latency counters, a heat-map snapshot (SNAP_REQ, SNAP_STATUS, BLKREAD of the HEATMAP
window) and the latency histogram window.

pytest: the small sensor (4 x 6, N = 64) with a finger, a drag that starts mid-window and
a tap (touch down and lift inside windows), CLK_PER_SAMPLE 1 and 3, both simulators:
heat maps and events bit-exact with the model, register access over the UART, latency
counters equal to the cycles measured from the logs, the snapshot equal to the logged
frame, the calibration windows read back.  FMT_CORE_DEFAULT=1 adds the default 30 x 40 sensor under Verilator (latency at
full size; the build takes minutes).
"""
from __future__ import annotations

import json
import os
import sys
import time
from pathlib import Path

import cocotb
import numpy as np
import pytest
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles, FallingEdge, First, ReadOnly, RisingEdge

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "sim"))
sys.path.insert(0, str(ROOT / "tb"))

from common.runner import run_cocotb  # noqa: E402
from fmt import params, protocol, regmap  # noqa: E402
from fmt import run_sim_rtl as rsr  # noqa: E402
from fmt import scene as _scene  # noqa: E402
from fmt.settings import TouchSettings  # noqa: E402

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
    while done < total:
        n = min(step, total - done)
        await ClockCycles(dut.clk, n)
        done += n
        if not quiet and total > 200000:
            fr = int(dut.frames_o.value)
            rate = fr / max(time.perf_counter() - t0, 1e-9)
            print(f"\r  fmt_core: frame {fr}/{job['frames']}  ({rate:.0f} frames/s)",
                  end="", file=sys.stderr, flush=True)
    if not quiet and total > 200000:
        print(file=sys.stderr)
    wall = time.perf_counter() - t0
    res = {"wall_s": wall, "frames": int(dut.frames_o.value), "events": int(dut.events_o.value),
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


# ---- pytest entry ------------------------------------------------------------------------
def small_tap_scene(frames: int) -> _scene.Scene:
    """The small scene plus a tap that lands and lifts inside windows."""
    sc = _scene.small_scene()
    cfg = sc.cfg
    n, fs = cfg.n_fft, cfg.fs_hz
    tap = _scene.Contact(name="tap", path=[[0.0, 25.5, 15.5]],
                         active=[[3 * n / fs + 23 / fs, 7 * n / fs + 41 / fs]])
    return sc.replace(frames=frames, contacts=list(sc.contacts) + [tap])


def _run(sim, scene, cps, uart, settings, model_settings=None, extra_params=None, tag=""):
    """Run the scene on the sim top; the reference uses model_settings (default: the
    settings the registers are written with)."""
    cfg = scene.cfg
    if model_settings is not None:     # the same scene, noise and plan: only the settings differ
        _d, ref_m, _cal, _n = rsr.prepare(scene, scene.frames, cps, model_settings, cal=None,
                                          tag=f"tb_{sim}{tag}")
    d, ref, cal, n_upd = rsr.prepare(scene, scene.frames, cps, settings, cal=None, tag=f"tb_{sim}{tag}")
    if model_settings is not None:
        ref = ref_m
    # slack after the last frame for the UART phase
    run_cocotb(sim=sim, toplevel="fmt_core_sim_top", sources=rsr.sim_sources(),
               test_module="test_fmt_core", test_dir=Path(__file__).parent, testcase="run_scene",
               parameters={**rsr.sim_parameters(cfg, cps, d), **(extra_params or {})},
               extra_env={"FMT_CORE_JOB": str(d / "job.json"), "FMT_CORE_UART": int(uart),
                          "FMT_CORE_CFG": cfg.name, "FMT_QUIET": 1},
               build_args=rsr.build_args(sim, fast_sim=cfg.name == "default"),
               tag=f"c{cps}{tag}")
    res = json.loads((d / "result.json").read_text())
    rep = rsr.analyse(scene, ref, d, cps, res["status"], scene.frames, res["wall_s"], None, False, cal)
    return d, ref, res, rep


@pytest.mark.parametrize("cps", [1, 3])
def test_fmt_core(sim, cps):
    frames = 14
    # lifts within the run (small frames are 1.536 us); a gate below the tap-drag distance
    st = TouchSettings(hold_off_us=5.0, max_jump_mm=4.0)
    scene = small_tap_scene(frames)
    cfg = scene.cfg
    uart = cps == 3                              # the UART phase once per simulator (test time)
    d, ref, res, rep = _run(sim, scene, cps, uart, st)
    assert res["upd_late"] == 0 and res["upd_done"] == 1
    assert rep["frames_dropped"] == 0, rep
    assert rep["golden_detail"]["first"] is None, rep["golden_detail"]
    assert rep["golden_mismatches"] == 0
    n_ev = sum(len(e) for e in ref.events)
    types = {e.type_code for evs in ref.events for e in evs}
    assert n_ev > 0 and {0, 1, 2} <= types, f"scene must give new, move and lift events: {types}"
    # latency counters against the cycles measured from the logs (frame end -> events)
    hm_rows, eof, evs, fend = rsr.parse_logs(d, cfg)
    per = {}
    for e in evs:
        per.setdefault(e["frame"], []).append(e["cycle"])
    for f in per:
        per[f] = [c for c in per[f] if c < res["status_cycle"]]
    first = [min(c) - fend[f] for f, c in per.items() if f in fend and c]
    last = [max(c) - fend[f] for f, c in per.items() if f in fend and c]
    stt = res["status"]
    assert stt["LAT_FIRST_COUNT"] == len(first) and stt["LAT_LAST_COUNT"] == len(last)
    assert (stt["LAT_FIRST_MIN"], stt["LAT_FIRST_MAX"]) == (min(first), max(first)), (stt, first)
    assert (stt["LAT_LAST_MIN"], stt["LAT_LAST_MAX"]) == (min(last), max(last)), (stt, last)
    # FRAME_COUNT is read between the two samples of the frame counter of the sim top
    assert res["frames_before_status"] <= stt["FRAME_COUNT"] <= res["frames_at_status"]
    assert res["cal_rb"] == [0x123, 16384], res["cal_rb"]     # written offset, identity gain
    print(f"fmt_core {cfg.name} cps={cps}: {rep['frames']} frames, {len(evs)} events, "
          f"window end -> first event {min(first)}..{max(first)} clk, last {min(last)}..{max(last)} clk")
    if not uart:
        return
    # UART: registers, counters, histogram, snapshot (the event consumer stayed stopped)
    u = res["uart"]
    assert u["scratch"] == 0x5A5AC3C3 and u["id"] == protocol.INFO_MAGIC
    assert u["LAT_FIRST_COUNT"] == len(first) and u["LAT_FIRST_MIN"] == min(first)
    assert u["LAT_LAST_MAX"] == max(last)
    h_first = u["hist"]
    exp_hist = np.bincount(np.minimum(np.asarray(first) >> 5, 15), minlength=16).tolist()
    assert h_first == exp_hist, (h_first, exp_hist)
    assert u["snap_status"] >> 31 == 1
    snap_frame = u["snap_status"] & 0xFFFF
    rows = hm_rows[snap_frame]
    exp = [cell for r in range(cfg.rows) for cell in rows[r][1]]
    assert u["snap"] == exp


def small_palm_scene(frames: int) -> _scene.Scene:
    """The small scene's still finger plus a 14 mm palm that lands inside window 4."""
    sc = _scene.small_scene()
    cfg = sc.cfg
    n, fs = cfg.n_fft, cfg.fs_hz
    palm = _scene.Contact(name="palm", diameter_mm=14.0, path=[[0.0, 22.0, 12.0]],
                          active=[[4 * n / fs + 30 / fs, None]])
    return sc.replace(frames=frames, contacts=[sc.contacts[0], palm])


def test_fmt_core_blobs(sim):
    """TOUCH_MODE bit 2 (blobs on) through the register file: the palm's maximum is
    dropped and blob events follow the tracker's, bit-exact with process_frames(blobs)."""
    frames = 12
    # threshold and size between the finger (3 cells above 3500) and the palm (8 cells)
    st = TouchSettings(hold_off_us=5.0, max_jump_mm=4.0, blobs=True,
                       blob_threshold=3500, blob_min_cells=5)
    scene = small_palm_scene(frames)
    d, ref, res, rep = _run(sim, scene, 3, False, st)
    assert rep["frames_dropped"] == 0, rep
    assert rep["golden_mismatches"] == 0, rep["golden_detail"]
    per_frame = [sorted(e.type for e in evs) for evs in ref.events]
    n_blob = sum(t.count("blob") for t in per_frame)
    assert n_blob >= frames - 6, f"the palm must be a blob in the later frames: {per_frame}"
    assert all(t.count("blob") <= 1 for t in per_frame), per_frame
    # in a frame with a blob, the palm's maximum is not a finger: only the still finger
    # (the first ID) moves or is new there (the palm may be a finger while it lands)
    still = ref.events[0][0].id
    for evs in ref.events:
        if any(e.type == "blob" for e in evs):
            assert {e.id for e in evs if e.type in ("new", "move")} == {still}, evs
    assert res["status"]["STATUS"] >> 7 & 1 == 0          # no blob overflow/overrun


def test_fmt_core_no_blob_build(sim):
    """fmt_core built with BLOBS = 0: the detector is left out, so TOUCH_MODE bit 2 (written
    here) has no effect: the palm scene's events are those of the model with blobs off."""
    frames = 8
    st_on = TouchSettings(hold_off_us=5.0, max_jump_mm=4.0, blobs=True,
                          blob_threshold=3500, blob_min_cells=5)
    scene = small_palm_scene(frames)
    d, ref, res, rep = _run(sim, scene, 3, False, st_on, model_settings=st_on.replace(blobs=False),
                            extra_params={"BLOBS": 0}, tag="_nb")
    assert rep["frames_dropped"] == 0, rep
    assert rep["golden_mismatches"] == 0, rep["golden_detail"]
    types = {e.type for evs in ref.events for e in evs}
    assert "blob" not in types and len({e.id for evs in ref.events for e in evs}) == 2, types
    assert res["status"]["STATUS"] >> 7 & 1 == 0


@pytest.mark.verilator_only
@pytest.mark.skipif(not os.environ.get("FMT_CORE_DEFAULT"), reason="FMT_CORE_DEFAULT=1 runs it")
def test_fmt_core_default(sim):
    """Default 30 x 40 sensor, CLK_PER_SAMPLE 3: bit-exact and the latency against 8 us."""
    frames = int(os.environ.get("FMT_CORE_FRAMES", "60"))
    scene = _scene.default_scene().replace(frames=frames)
    d, ref, res, rep = _run(sim, scene, 3, False, TouchSettings())
    lat = rep["latency_us"]
    print(json.dumps({k: rep[k] for k in ("frames", "frames_dropped", "golden_mismatches",
                                          "latency_us", "latency_fs_cycles")}, indent=1))
    assert rep["golden_mismatches"] == 0 and rep["frames_dropped"] == 0
    assert lat["window_end_to_last_event"]["max"] <= 8.0
