"""cocotb testbench of rtl/fmt_ctrl_port.v with the generated rtl/fmt_regfile.v, through
the simulation-only top tb/fmt_ctrl_port/fmt_ctrl_tb_top.v (dummy block RAM, tone-plan
window memories, test-driven status inputs).

Every reply is compared byte for byte with the model twin ``fmt.protocol.CtrlPortModel``
(parser, error replies, counters) executing on a register-file model
(``fmt.regmap.RegfileModel``) and a model of the dummy memories.  Checks: INFO;
reset values of every readable register; multi-word writes and reads; w1c flags;
windows; strobe; block reads; event streaming on/off; and bad input -- garbage,
truncated frames (inter-byte timeout) cut at every header position, bad CRC, bad
length (too long for the buffer, wrong for the command), unknown commands, a UART
framing error, random garbage bursts with embedded sync bytes -- each followed by
the error counter, the last error code and a register snapshot read back through good
frames (nothing written by a bad frame, the next good frame works).
"""
from __future__ import annotations

import random
import struct
from pathlib import Path

import cocotb
import pytest
from cocotb.triggers import ClockCycles, ReadOnly, RisingEdge

from common.runner import long_run, run_cocotb, sources
from common.tb_util import ClockedTB, env_int, env_str
from fmt import params, protocol as P, regmap
from fmt_uart.uart_bfm import UartBfm

HERE = Path(__file__).parent
# the fixed status inputs of fmt_ctrl_tb_top.v
FIXED_INPUTS = {"EV_DROP_COUNT": 3, "EV_SKIP_COUNT": 5, "FLAT_SAT_COUNT": 7, "LM_DROP_COUNT": 9,
                "LAT_FIRST_LAST": 101, "LAT_FIRST_MIN": 100, "LAT_FIRST_MAX": 140, "LAT_FIRST_COUNT": 4242,
                "LAT_LAST_LAST": 201, "LAT_LAST_MIN": 200, "LAT_LAST_MAX": 240, "LAT_LAST_COUNT": 4243,
                "LAT_TRIG_LAST": 301, "LAT_TRIG_MIN": 300, "LAT_TRIG_MAX": 340, "LAT_TRIG_COUNT": 7,
                "LAT_TRIG_ARMED": 1}


class TB(ClockedTB):
    def __init__(self, dut):
        super().__init__(dut)
        self.cfg = params.get(env_str("CFG", "small"))
        self.div = env_int("DIV", 4)
        self.tmo_bits = env_int("TIMEOUT_BITS", 20)
        self.pmax = env_int("PAYLOAD_MAX", 64)
        for n in ("mem_we_i", "mem_addr_i", "mem_wdata_i", "frame_count_i", "status_set_i",
                  "evs_valid_i", "evs_data_i"):
            getattr(dut, n).value = 0
        self.bfm = UartBfm(self.clk, dut.rxd_i, dut.txd_o, self.div, self.period_ns)
        self.regs = regmap.RegfileModel()
        self.model = P.CtrlPortModel(self.execute, self.pmax)
        self.mem = [0] * 64
        self.tone_tw = {}
        self.tone_amp = {}
        self.cal = {}                 # (CAL_OFFSET or CAL_GAIN, row & 7, col & 7) -> value
        self.frame_count = 0
        self.err_seen = 0
        self.stream = False
        self.seq = 0
        self.lat_clear_pulses = 0
        cocotb.start_soon(self._watch_strobes())

    async def _watch_strobes(self):
        while True:
            await RisingEdge(self.clk)
            await ReadOnly()
            if int(self.dut.lat_clear_o.value):
                self.lat_clear_pulses += 1

    # ---- model of the tb top --------------------------------------------------------
    def _sync_status(self):
        if self.model.err_count != self.err_seen:       # every error pulses STATUS bit 4
            self.regs.val["STATUS"] |= 0x10
            self.err_seen = self.model.err_count

    def read_reg(self, addr: int) -> int:
        self._sync_status()
        sel = self.regs.val["TONE_SEL"]
        inputs = {"FRAME_COUNT": self.frame_count, "CTRL_ERRORS": self.model.err_count,
                  "CTRL_LAST_ERR": self.model.err_last,
                  "TONE_TW": self.tone_tw.get(sel, 0), "TONE_AMP": self.tone_amp.get(sel, 0),
                  **{k: self.cal.get(self._cal_key(k), 0) for k in ("CAL_OFFSET", "CAL_GAIN")},
                  **FIXED_INPUTS}
        return self.regs.read(addr, inputs)

    def _cal_key(self, name):
        return (name, self.regs.val["CAL_ROW"] & 7, self.regs.val["CAL_COL"] & 7)

    def write_reg(self, addr: int, data: int) -> None:
        self._sync_status()
        sel = self.regs.val["TONE_SEL"]
        for k in ("CAL_OFFSET", "CAL_GAIN"):
            if addr == regmap.BY_NAME[k].addr:
                self.cal[self._cal_key(k)] = data & 0xFFFF
        if addr == regmap.BY_NAME["TONE_TW"].addr:
            self.tone_tw[sel] = data & 0xFFFFFFFF
        elif addr == regmap.BY_NAME["TONE_AMP"].addr:
            self.tone_amp[sel] = data & 0x1FF
        self.regs.write(addr, data)

    def blk_word(self, a: int) -> int:
        return self.mem[a] if a < 64 else (((~a) & 0xFFFF) << 16) | a

    def execute(self, seq, cmd, p: bytes) -> bytes:
        if cmd == P.CMD_INFO:
            return P.info_payload(self.cfg, regmap.regmap_id(), self.pmax)
        if cmd == P.CMD_READ:
            a, n = struct.unpack(">HB", p)
            return P.words_payload(self.read_reg((a + i) & 0xFFFF) for i in range(n))
        if cmd == P.CMD_WRITE:
            a = struct.unpack(">H", p[:2])[0]
            for i, w in enumerate(P.payload_words(p[2:])):
                self.write_reg((a + i) & 0xFFFF, w)
            return b""
        if cmd == P.CMD_BLKREAD:
            a, n = struct.unpack(">HH", p)
            return P.words_payload(self.blk_word((a + i) & 0xFFFF) for i in range(n))
        if cmd == P.CMD_STREAM:
            self.stream = bool(p[0] & 1)
            return b""
        raise AssertionError("model executed a bad command")

    # ---- stimulus ----------------------------------------------------------------------
    def next_seq(self) -> int:
        self.seq = (self.seq + 1) & 0xFF
        return self.seq

    async def burst(self, data: bytes, expect: list[bytes] | None = None, what: str = ""):
        """Send ``data`` back to back, idle for the timeout, and check the replies
        against the model (or ``expect``) byte for byte; nothing else may arrive."""
        exp = self.model.burst(data) if expect is None else expect
        n = sum(len(x) for x in exp)
        sender = cocotb.start_soon(self.bfm.send(data))
        got = await self.bfm.recv(n, timeout_bits=20 * len(data) + 40 * self.tmo_bits + 400)
        await sender
        await self.bfm.idle(self.tmo_bits + 12)
        assert got == b"".join(exp), f"{what}: replies differ\n got {got.hex()}\n exp {b''.join(exp).hex()}"
        assert self.bfm.pending() == 0, f"{what}: extra bytes after the replies"
        assert not self.bfm.bit_errors, self.bfm.bit_errors

    async def request(self, frame: bytes, what: str = ""):
        await self.burst(frame, what=what)

    async def read(self, addr: int, n: int = 1):
        await self.request(P.req_read(self.next_seq(), addr, n), f"READ 0x{addr:03X}")

    async def write(self, addr: int, words):
        await self.request(P.req_write(self.next_seq(), addr, words), f"WRITE 0x{addr:03X}")

    async def snapshot(self):
        """Read every readable register range (model-checked)."""
        for a, n in ((0x000, 3), (0x010, 9), (0x020, 10), (0x030, 2), (0x040, 2), (0x080, 9),
                     (0x090, 16)):
            await self.read(a, n)

    async def start(self):
        await self.reset()
        await self.bfm.idle(4)


def R(name):
    return regmap.BY_NAME[name].addr


@cocotb.test()
async def info_and_registers(dut):
    """INFO, reset values, multi-word writes/reads, w1c, windows, strobe."""
    tb = TB(dut)
    await tb.start()
    rng = random.Random(env_int("SEED", 1))
    await tb.request(P.req_info(tb.next_seq()), "INFO")
    await tb.snapshot()                                 # reset values of the map
    await tb.write(R("SCRATCH"), [0xCAFEF00D])
    await tb.write(R("RUN"), [rng.getrandbits(32) for _ in range(5)])   # RUN..WINDOWS_M, masked
    await tb.write(R("TOUCH_THRESHOLD"), [rng.getrandbits(32) for _ in range(10)])
    for row, col in ((1, 2), (3, 5), (1, 2)):
        await tb.write(R("CAL_ROW"), [row, col, rng.getrandbits(16), rng.getrandbits(16)])
    await tb.write(R("CAL_ROW"), [3, 5])
    await tb.read(R("CAL_ROW"), 4)
    await tb.write(R("LATENCY_DIAL"), [rng.getrandbits(32) for _ in range(2)])
    await tb.snapshot()
    # w1c: set bits from the core side, clear some from the host
    await tb.writable()
    dut.status_set_i.value = 0x05
    await RisingEdge(tb.clk)
    await tb.writable()
    dut.status_set_i.value = 0
    tb.regs.val["STATUS"] |= 0x05
    tb.frame_count = rng.getrandbits(32)
    dut.frame_count_i.value = tb.frame_count
    await tb.read(R("FRAME_COUNT"), 2)
    await tb.write(R("STATUS"), [0x01])
    await tb.read(R("STATUS"))
    assert tb.regs.val["STATUS"] == 0x04
    # windows: selector + data in one WRITE, read back per row
    for sel in (3, 7, 0):
        await tb.write(R("TONE_SEL"), [sel, rng.getrandbits(32), rng.getrandbits(9)])
    for sel in (7, 3, 0):
        await tb.write(R("TONE_SEL"), [sel])
        await tb.read(R("TONE_SEL"), 3)
    # strobe: one pulse per write
    before = tb.lat_clear_pulses
    await tb.write(R("LAT_CLEAR"), [1])
    assert tb.lat_clear_pulses == before + 1
    await tb.read(R("LAT_CLEAR"))                       # reads 0


@cocotb.test()
async def block_read(dut):
    """BLKREAD of the preloaded heat-map snapshot and of the pattern space; limits."""
    tb = TB(dut)
    await tb.start()
    rng = random.Random(env_int("SEED", 2))
    for a in range(64):
        tb.mem[a] = rng.getrandbits(tb.cfg.hm_width)
        await tb.writable()
        dut.mem_we_i.value = 1
        dut.mem_addr_i.value = a
        dut.mem_wdata_i.value = tb.mem[a]
    await tb.writable()
    dut.mem_we_i.value = 0
    cells = tb.cfg.rows * tb.cfg.cols
    n0 = len(tb.bfm.start_times)
    req = P.req_blkread(tb.next_seq(), regmap.WINDOW_BY_NAME["HEATMAP"].base, cells)
    await tb.request(req, "heat map")
    # the reply streams without idle bits (each word is fetched while the previous byte is
    # on the wire) and starts a fixed few clocks after the request's last stop bit
    starts = tb.bfm.start_times[n0:]
    byte_ns = 10 * tb.div * tb.period_ns
    assert len(starts) == 7 + 4 * cells
    gaps = [(i, b - a) for i, (a, b) in enumerate(zip(starts, starts[1:])) if abs(b - a - byte_ns) > 0.5]
    assert not gaps, f"gaps inside the reply (byte index, ns): {gaps[:8]}"
    turn = round((starts[0] - tb.bfm.sent_end_ns) / tb.period_ns)
    dut._log.info(f"turnaround: reply start bit {turn} clocks after the request's stop bit "
                  f"ended (DIV = {tb.div})")
    assert turn <= tb.div // 2 + 8
    await tb.request(P.req_blkread(tb.next_seq(), 0x8000, 37), "pattern")
    await tb.request(P.req_blkread(tb.next_seq(), 0xFFFE, 4), "address wrap")
    await tb.request(P.req_blkread(tb.next_seq(), 0, 0), "count 0")
    await tb.request(P.req_blkread(tb.next_seq(), 0, P.MAX_BLKREAD + 1), "count too large")
    assert tb.model.err_count == 2
    await tb.read(R("CTRL_ERRORS"), 2)


@cocotb.test()
async def bad_frames(dut):
    """Every kind of bad input: one ERROR reply (or the documented silent count), the
    counter, the last code, registers unchanged, and the next good frame works."""
    tb = TB(dut)
    await tb.start()
    await tb.write(R("SCRATCH"), [0x12345678])
    good = P.req_write(0x42, R("SCRATCH"), [0xBAD0BAD0])
    cases = []
    cases.append(("junk only", b"\x00\x13\x37\xff"))
    cases.append(("junk then a good READ", b"\x01\x02" + P.req_read(0x43, R("SCRATCH"))))
    for cut in (1, 2, 3, 4, 5, 7, len(good) - 1):
        cases.append((f"truncated at {cut}", good[:cut]))
    bad = bytearray(good)
    bad[8] ^= 0x01
    cases.append(("bad CRC (payload bit)", bytes(bad)))
    bad = bytearray(good)
    bad[-1] ^= 0x80
    cases.append(("bad CRC (CRC bit)", bytes(bad)))
    cases.append(("LEN > PAYLOAD_MAX", P.req_write(0x44, R("SCRATCH"), list(range((tb.pmax - 2) // 4 + 1)))))
    cases.append(("READ LEN 2", P.encode(0x45, P.CMD_READ, b"\x00\x02")))
    cases.append(("READ count 0", P.req_read(0x46, R("SCRATCH"), 0)))
    cases.append(("WRITE LEN 5", P.encode(0x47, P.CMD_WRITE, b"\x00\x02\xde\xad\xbe")))
    cases.append(("WRITE LEN 8", P.encode(0x47, P.CMD_WRITE, b"\x00\x02\xde\xad\xbe\xef\x00\x01")))
    cases.append(("INFO with payload", P.encode(0x48, P.CMD_INFO, b"\x00")))
    cases.append(("STREAM LEN 2", P.encode(0x48, P.CMD_STREAM, b"\x01\x00")))
    cases.append(("unknown command 0x33", P.encode(0x49, 0x33, b"\x00\x02")))
    cases.append(("unknown command 0x82", P.encode(0x4A, 0x82)))
    cases.append(("two bad CRCs back to back", bytes(bad) + bytes(bad)))
    cases.append(("bad CRC then a good frame", bytes(bad) + P.req_read(0x4B, R("SCRATCH"))))
    for what, data in cases:
        before = tb.model.err_count
        await tb.burst(data, what=what)
        assert tb.model.err_count > before, what
        await tb.read(R("CTRL_ERRORS"), 2)              # counter and last code
        await tb.read(R("SCRATCH"))                     # unchanged: still 0x12345678
        assert tb.regs.val["SCRATCH"] == 0x12345678, what
    assert tb.model.err_count == len(cases) + 1     # one error per case, two for the double CRC
    # a UART framing error inside a frame: error reply, the rest of the frame (sent on
    # without a pause, as a host would) is discarded until the line is idle
    before = tb.model.err_count
    frame = P.req_write(0x50, R("SCRATCH"), [0xFEEDFACE])
    exp = P.error_reply(0x50, P.ERR_FRAMING, P.CMD_WRITE)

    async def send_with_bad_stop():
        await tb.bfm.send(frame[:6])
        await tb.bfm.send_byte(frame[6], stop=0)
        await tb.bfm.send(frame[7:])

    sender = cocotb.start_soon(send_with_bad_stop())
    got = await tb.bfm.recv(len(exp), timeout_bits=400)
    await sender
    await tb.bfm.idle(tb.tmo_bits + 12)
    assert got == exp, got.hex()
    assert tb.bfm.pending() == 0, "one reply only"
    tb.model.err_count = before + 1
    tb.model.err_last = P.ERR_FRAMING
    await tb.read(R("CTRL_ERRORS"), 2)
    await tb.read(R("SCRATCH"))
    # receive overflow: the host sends on while a long reply goes out; the good reply
    # completes, then one OVERFLOW error (SEQ 0), the rest is discarded until idle
    rd = P.req_read(0x51, 0x090, 16)
    exp = [b"".join(tb.model.burst(rd))]            # the READ reply (model executes it)
    exp.append(P.error_reply(0, P.ERR_OVERFLOW, 0))
    tb.model.err_count += 1
    tb.model.err_last = P.ERR_OVERFLOW
    more = P.req_write(0x52, R("SCRATCH"), [0xDEADDEAD]) * 3     # 39 bytes, never executed
    await tb.burst(rd + more, expect=exp, what="overflow")
    await tb.read(R("CTRL_ERRORS"), 2)
    await tb.read(R("SCRATCH"))
    await tb.snapshot()


@cocotb.test()
async def garbage_resync(dut):
    """Random bursts of garbage (with sync bytes), corrupt and good frames, replies and
    counters model-checked; the parser always resynchronises."""
    tb = TB(dut)
    await tb.start()
    rng = random.Random(env_int("SEED", 4))
    for it in range(env_int("GARBAGE_BURSTS", 12)):
        parts = []
        for _ in range(rng.randrange(1, 4)):
            k = rng.random()
            if k < 0.4:
                parts.append(bytes(rng.choice([0xA5, rng.randrange(256)]) for _ in range(rng.randrange(1, 9))))
            elif k < 0.7:
                f = bytearray(P.req_write(tb.next_seq(), R("SCRATCH"), [rng.getrandbits(32)]))
                f[rng.randrange(1, len(f))] ^= 1 << rng.randrange(8)
                parts.append(bytes(f))
            else:
                parts.append(P.req_read(tb.next_seq(), R("SCRATCH")))
        if rng.random() < 0.5:
            parts.append(P.req_write(tb.next_seq(), R("SCRATCH"), [rng.getrandbits(32)]))
        await tb.burst(b"".join(parts), what=f"burst {it}")
        await tb.read(R("CTRL_ERRORS"), 2)
        await tb.read(R("SCRATCH"))


@cocotb.test()
async def event_stream(dut):
    """STREAM on: offered events go out as event frames with a running SEQ; STREAM off:
    events are taken (dropped) and nothing is sent."""
    tb = TB(dut)
    await tb.start()
    rng = random.Random(env_int("SEED", 5))
    await tb.request(P.req_stream(tb.next_seq(), True), "stream on")
    assert int(dut.stream_en_o.value) == 1
    for i in range(3):
        ev = {"frame": rng.getrandbits(16), "time": rng.getrandbits(32), "id": i, "type": i % 4,
              "last": i == 2, "x": rng.getrandbits(16), "y": rng.getrandbits(16),
              "strength": rng.getrandbits(16), "axis_major": 300, "axis_minor": 200,
              "angle": 17, "flags": 9}
        payload = P.pack_event(ev)
        await tb.writable()
        dut.evs_data_i.value = int.from_bytes(payload, "big")
        dut.evs_valid_i.value = 1
        while True:
            await ReadOnly()
            rdy = int(dut.evs_ready_o.value)
            await RisingEdge(tb.clk)
            if rdy:
                break
        await tb.writable()
        dut.evs_valid_i.value = 0
        exp = P.encode(i, P.CMD_EVENT, payload)
        got = await tb.bfm.recv(len(exp), timeout_bits=100)
        assert got == exp, f"event {i}: {got.hex()} vs {exp.hex()}"
        fr = P.decode(got)[0]
        assert P.unpack_event(fr.payload)["id"] == i
    await tb.request(P.req_stream(tb.next_seq(), False), "stream off")
    await tb.writable()
    dut.evs_valid_i.value = 1
    await ReadOnly()
    assert int(dut.evs_ready_o.value) == 1, "stream off: events are dropped, not held"
    await tb.writable()
    dut.evs_valid_i.value = 0
    await ClockCycles(tb.clk, 60 * tb.div)
    assert tb.bfm.pending() == 0, "no event frame with the stream off"


# ---- pytest entry ------------------------------------------------------------------
@pytest.mark.parametrize("cfg_name,div", [("small", 4), ("medium", 5)])
def test_fmt_ctrl_port(sim, cfg_name, div):
    if sim == "verilator" and cfg_name != "small":
        pytest.skip("second size under Icarus only: a Verilator build costs ~20 s of the time budget")
    if sim == "icarus" and cfg_name != "small" and not long_run():
        pytest.skip("make test: the small size under both simulators; the second size in "
                    "make test-long (FMT_LONG=1), for make test's time")
    cfg = params.get(cfg_name)
    tmo, pmax = 20, 64
    vp = cfg.verilog_params()
    run_cocotb(
        sim=sim,
        toplevel="fmt_ctrl_tb_top",
        sources=sources("fmt_ctrl_port") + sources("fmt_regfile")
        + [HERE / "fmt_ctrl_tb_top.v"],
        test_module="test_fmt_ctrl_port",
        test_dir=HERE,
        parameters={"DIV": div, "TIMEOUT_BITS": tmo, "PAYLOAD_MAX": pmax,
                    "REGMAP_ID": regmap.regmap_id(),
                    **{k: vp[k] for k in ("ROWS", "COLS", "LOG2_N", "HM_W", "BIN_LO", "BIN_STEP")}},
        extra_env={"CFG": cfg_name, "DIV": div, "TIMEOUT_BITS": tmo, "PAYLOAD_MAX": pmax},
    )
