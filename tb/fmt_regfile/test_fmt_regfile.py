"""The register map checked against hand-written cases (issue #15 item 6), independent of
the generator sim/fmt/regmap.py: HAND below is typed from docs/REGISTERS.md (address,
name, width, access, reset of the default build).

Checks: docs/REGISTERS.md's table reads the same as HAND (a changed map must be changed
here by hand too), the model regmap.REGISTERS equals HAND, and the generated RTL
rtl/fmt_regfile.v (Icarus and Verilator): after reset every const/rw/w1c register reads
its reset value, a rw register keeps exactly its width (all ones written, 2^w - 1 read
back and driven on its port; 0 written, 0 read), const and ro registers ignore writes,
ro registers read their input masked to their width, STATUS bits set by status_set_i
clear only where 1 is written, strobes pulse their port with the written bit, windows
pass data and strobes, and unmapped addresses read 0.
"""
from __future__ import annotations

import re
from pathlib import Path

import cocotb
from cocotb.triggers import ReadOnly, RisingEdge

from common.runner import run_cocotb, sources
from common.tb_util import ClockedTB

ROOT = Path(__file__).resolve().parents[2]

# address name width access reset ("-": none) -- typed from docs/REGISTERS.md
HAND_TEXT = """
0x000 ID 32 const 0x464D5443
0x001 VERSION 16 const 0x100
0x002 SCRATCH 32 rw 0x0
0x010 RUN 1 rw 0x1
0x011 PN_ENABLE 1 rw 0x1
0x012 PN_CHIP_LEN 10 rw 0x1
0x013 PN_RX_DELAY 6 rw 0x0
0x014 WINDOWS_M 8 rw 0x1
0x018 TONE_SEL 5 rw 0x0
0x019 TONE_TW 32 window -
0x01A TONE_AMP 9 window -
0x020 TOUCH_THRESHOLD 16 rw 0x7D0
0x021 TOUCH_MODE 3 rw 0x3
0x022 CONTACT_LIMIT 5 rw 0x10
0x023 TRACK_MAX_JUMP 16 rw 0xB9
0x024 TRACK_GATE_STEP 16 rw 0x4
0x025 TRACK_HOLD_OFF 12 rw 0x21
0x026 TRACK_VEL_SHIFT 4 rw 0x8
0x027 TRACK_MAX_SPEED 21 rw 0xF19
0x028 BLOB_THRESHOLD 16 rw 0x3E8
0x029 BLOB_MIN_CELLS 12 rw 0xC
0x02A TOUCH_ON_THRESHOLD 16 rw 0x9C4
0x02B TRACK_CONFIRM 3 rw 0x2
0x030 CAL_ROW 5 rw 0x0
0x031 CAL_COL 6 rw 0x0
0x032 CAL_OFFSET 16 window -
0x033 CAL_GAIN 16 window -
0x040 LATENCY_DIAL 32 rw 0x0
0x041 REPORT_PERIOD 32 rw 0x7A120
0x080 FRAME_COUNT 32 ro -
0x081 STATUS 11 w1c 0x0
0x082 CTRL_ERRORS 16 ro -
0x083 CTRL_LAST_ERR 8 ro -
0x084 EV_DROP_COUNT 16 ro -
0x085 EV_SKIP_COUNT 16 ro -
0x086 FLAT_SAT_COUNT 16 ro -
0x087 LM_DROP_COUNT 16 ro -
0x088 SAT_CLEAR 1 strobe -
0x089 STREAM_DROP_COUNT 16 ro -
0x090 LAT_FIRST_LAST 16 ro -
0x091 LAT_FIRST_MIN 16 ro -
0x092 LAT_FIRST_MAX 16 ro -
0x093 LAT_FIRST_COUNT 32 ro -
0x094 LAT_LAST_LAST 16 ro -
0x095 LAT_LAST_MIN 16 ro -
0x096 LAT_LAST_MAX 16 ro -
0x097 LAT_LAST_COUNT 32 ro -
0x098 LAT_TRIG_LAST 16 ro -
0x099 LAT_TRIG_MIN 16 ro -
0x09A LAT_TRIG_MAX 16 ro -
0x09B LAT_TRIG_COUNT 32 ro -
0x09C LAT_TRIG_ARMED 1 ro -
0x09F LAT_CLEAR 1 strobe -
0x0A0 SNAP_REQ 1 strobe -
0x0A1 SNAP_STATUS 32 ro -
"""
# the block-read windows: name, base, words (HEATMAP = 30 x 40 cells)
HAND_WINDOWS = [("HEATMAP", 0x0000, 1200), ("LAT_HIST", 0x8000, 32)]


def hand() -> list:
    out = []
    for line in HAND_TEXT.strip().splitlines():
        a, n, w, acc, r = line.split()
        out.append((int(a, 16), n, int(w), acc, None if r == "-" else int(r, 16)))
    return out


HAND = hand()


def test_doc_table_equals_hand_cases():
    text = (ROOT / "docs" / "REGISTERS.md").read_text()
    rows = re.findall(r"^\| (0x[0-9A-F]{3}) \| (\w+) \| (\d+) \| (\w+) \| ([^|]+) \|", text, re.M)
    doc = [(int(a, 16), n, int(w), acc, None if r.strip() == "-" else int(r, 16)) for a, n, w, acc, r in rows]
    assert doc == HAND
    wins = re.findall(r"^\| (0x[0-9A-F]{4}) \| (\w+) \| (\d+) \|", text, re.M)
    assert [(n, int(b, 16), int(s)) for b, n, s in wins] == HAND_WINDOWS


def test_model_equals_hand_cases():
    from fmt import regmap
    model = [(r.addr, r.name, r.width, r.access, None if r.access in ("ro", "window", "strobe") else r.reset)
             for r in regmap.REGISTERS]
    assert model == HAND
    assert [(w.name, w.base, w.size) for w in regmap.WINDOWS] == HAND_WINDOWS


# ---- RTL: rtl/fmt_regfile.v against HAND ----------------------------------------------------
class TB(ClockedTB):
    def __init__(self, dut):
        super().__init__(dut)
        for h in dut:
            n = h._name
            if n.endswith("_i") and n not in ("reg_we_i", "reg_re_i"):
                h.value = 0
        dut.reg_we_i.value = 0
        dut.reg_re_i.value = 0
        dut.reg_addr_i.value = 0
        dut.reg_wdata_i.value = 0

    async def write(self, addr, data, check=None):
        d = self.dut
        await self.writable()
        d.reg_we_i.value, d.reg_addr_i.value, d.reg_wdata_i.value = 1, addr, data
        if check:
            await ReadOnly()
            check()
        await RisingEdge(self.clk)
        await self.writable()
        d.reg_we_i.value = 0

    async def read(self, addr) -> int:
        d = self.dut
        await self.writable()
        d.reg_re_i.value, d.reg_addr_i.value = 1, addr
        await RisingEdge(self.clk)
        await self.writable()
        d.reg_re_i.value = 0
        await ReadOnly()
        v = int(d.reg_rdata_o.value)
        await self.writable()
        return v


@cocotb.test()
async def regfile_equals_hand_cases(dut):
    tb = TB(dut)
    await tb.reset()
    for a, n, w, acc, r in HAND:
        if acc in ("const", "rw", "w1c"):
            assert await tb.read(a) == r, f"{n} at {a:#x}: reset value"
    ones = (1 << 32) - 1
    for a, n, w, acc, r in HAND:
        port = n.lower()
        mask = (1 << w) - 1
        await tb.writable()
        if acc == "rw":
            await tb.write(a, ones)
            assert await tb.read(a) == mask, f"{n}: width {w}"
            assert int(getattr(dut, f"{port}_o").value) == mask, f"{n}: port"
            await tb.write(a, 0)
            assert await tb.read(a) == 0, n
            await tb.write(a, r)
        elif acc == "const":
            await tb.write(a, 0)
            assert await tb.read(a) == r, f"{n}: const changed by a write"
        elif acc == "ro":
            getattr(dut, f"{port}_i").value = 0x5A5A5A5A & mask
            await tb.write(a, ones)
            assert await tb.read(a) == 0x5A5A5A5A & mask, f"{n}: read of the input"
            getattr(dut, f"{port}_i").value = 0
        elif acc == "strobe":
            def pulse(port=port, n=n):
                assert int(getattr(dut, f"{port}_we_o").value) == 1, f"{n}: no strobe"
                assert int(getattr(dut, f"{port}_wdata_o").value) == 1, f"{n}: strobe data"
            await tb.write(a, 1, check=pulse)
            await ReadOnly()
            assert int(getattr(dut, f"{port}_we_o").value) == 0, f"{n}: strobe longer than the write"
        elif acc == "window":
            def win(port=port, n=n, mask=mask):
                assert int(getattr(dut, f"{port}_we_o").value) == 1, f"{n}: no write strobe"
                assert int(getattr(dut, f"{port}_wdata_o").value) == 0x12345678 & mask, n
            await tb.write(a, 0x12345678, check=win)
            getattr(dut, f"{port}_rdata_i").value = 0x3C3C3C3C & mask
            assert await tb.read(a) == 0x3C3C3C3C & mask, f"{n}: window read data"
            getattr(dut, f"{port}_rdata_i").value = 0
    # STATUS (w1c): set by status_set_i, cleared only where 1 is written
    await tb.writable()
    dut.status_set_i.value = 0x5A5
    await RisingEdge(tb.clk)
    await tb.writable()
    dut.status_set_i.value = 0
    assert await tb.read(0x081) == 0x5A5
    await tb.write(0x081, 0x405)
    assert await tb.read(0x081) == 0x1A0
    # unmapped addresses read 0 and ignore writes
    mapped = {a for a, *_ in HAND}
    for a in (0x003, 0x00F, 0x015, 0x034, 0x0A2, 0x100, 0xFFFF):
        assert a not in mapped
        await tb.write(a, ones)
        assert await tb.read(a) == 0, f"unmapped {a:#x}"
    # a reset brings the rw registers back
    await tb.write(0x020, 1234)
    await tb.reset()
    assert await tb.read(0x020) == 0x7D0


def test_fmt_regfile(sim):
    run_cocotb(sim=sim, toplevel="fmt_regfile", sources=sources("fmt_regfile"),
               test_module="test_fmt_regfile", test_dir=Path(__file__).parent,
               build_args=["-CFLAGS", "-O0"] if sim == "verilator" else None)
