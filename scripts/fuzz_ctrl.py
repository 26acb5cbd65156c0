#!/usr/bin/env python3
"""Control-port fuzzing through the RTL (issue #15, item 2).

Random and mutated bytes go to the UART of the whole small core (``fmt_core``, 4 x 6,
UART_DIV 4: 40 clk per byte, timeout 20 bit times) in the C++ Verilator harness in
serve mode (``python -m bench.core.run_sim_rtl --scene sim/scenes/small.json --serve 0
--serve-once``); every reply byte is checked against the protocol model
(``fmt.protocol.CtrlPortModel``, the twin of ``rtl/fmt_ctrl_port.v``) and a shadow of
the registers:

* the stream is cut into bursts (bytes back to back on the line, then an idle line):
  valid INFO / READ / WRITE / BLKREAD / STREAM(off) requests, frames with a flipped bit
  (bad CRC), a deleted, inserted or repeated byte, a wrong LEN or COUNT for the command
  (good CRC), unknown commands, junk (also with stray SYNC bytes), runs of valid frames,
  error storms (a junk byte and an unknown command, 8 bytes for 2 errors); a burst may
  end in a truncated frame (TIMEOUT), junk (JUNK) or a LEN above PAYLOAD_MAX (LEN
  replied at once, the rest discarded until the line is idle);
* every reply must arrive, byte for byte as the model says, in order, with nothing
  else on the line; a reply missing after --wall seconds is a hang.  Every malformed
  frame gets its one ERROR reply; a valid frame after garbage is answered
  (resynchronisation);
* READ replies are checked against a shadow of the registers: every rw register
  (initial values read once at the start), changed only by WRITEs whose ACK came back
  (replies are checked in order, so a READ after a WRITE is compared only once the
  WRITE's ACK has been); const registers, unmapped addresses (0) and strobes (0);
  CTRL_ERRORS (saturating at 0xFFFF: the error storms reach it within 10^6 bytes) and
  CTRL_LAST_ERR equal the model's count and last code, STATUS bit 4 (control-port
  error, sticky, cleared by writing 0x10) its sticky flag.  Of the other ro registers,
  windows and STATUS bits (the core's own state) only the bits above the width (0);
* the receive FIFO (128 bytes + the head register) must hold what arrives while the
  port replies: the ordinary bursts (up to ~7 kB) are kept below BACKLOG_MAX bytes of
  backlog by a timing model of the port (:func:`timeline`: host and reply bytes both
  40 clk; :func:`fit_burst` puts junk before a request that would exceed it, so that
  the parser catches up); a burst longer than the FIFO is fine while the port is not
  replying.  Overflow bursts
  check the documented overflow: a request with a long reply (>= 187 bytes), then
  >= 140 bytes more while it goes out: the reply, one ERROR OVERFLOW (SEQ 0, request
  CMD 0), the rest discarded until the line is idle (none of its WRITEs may land);
* "never hangs" in clk (:func:`check_timing`, from the harness's serve.log): every
  reply ends by the timing model's time + LATE_MAX clk, and the logged receive backlog
  stays below the FIFO's size.

Registers the fuzzer never writes: :data:`NEVER_WRITE` (with the reason).  Not sent:
UART framing errors (the harness's socket bridge always sends a good stop bit) and
STREAM on (event frames would interleave with the replies and fill the FIFO).

Deterministic: the bytes depend only on --seed (never on timing).  Exit 0 and one
summary line (``--json``: a JSON object) when every check passed; exit 1 with one line
``fuzz_ctrl: FAIL seed=S burst=B after N bytes: <what>; frame <hex>`` naming the
request behind the reply that failed; exit 2 on bad arguments or when the simulation
does not start.

    python scripts/fuzz_ctrl.py [--bytes 1000000] [--seed 1] [--port socket://127.0.0.1:P]
"""
from __future__ import annotations

import argparse
import binascii
import json
import random
import re
import socket
import struct
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
for _p in (str(ROOT), str(ROOT / "sim")):
    if _p not in sys.path:
        sys.path.insert(0, _p)

from bench.core.serve_proc import ServeFailed, ServeProc   # noqa: E402
from fmt import params                      # noqa: E402
from fmt import protocol as P               # noqa: E402
from fmt import regmap                      # noqa: E402


def fast_crc() -> None:
    """The model's CRC in C for this process (binascii.crc_hqx is CRC-16 poly 0x1021, MSB
    first, no final XOR: with init 0xFFFF it is CRC-16/CCITT-FALSE), checked against the
    model's own first."""
    slow = P.crc16
    fast = lambda data, crc=0xFFFF: binascii.crc_hqx(bytes(data), crc)   # noqa: E731
    assert fast(b"123456789") == slow(b"123456789") == 0x29B1
    r = random.Random(0)
    for n in range(1, 80):
        x = bytes(r.randrange(256) for _ in range(n))
        assert fast(x) == slow(x), x
    P.crc16 = fast


CFG = params.SMALL
REGMAP_ID = regmap.regmap_id()
PAYLOAD_MAX = P.DEFAULT_PAYLOAD_MAX         # fmt_core's fmt_ctrl_port: the default 64
BYTE_CLK = 10 * 4                           # 8N1 at UART_DIV 4 (run_sim_rtl.sim_parameters)
FIFO_BYTES = 128 + 1                        # 2^FIFO_AW RAM bytes + the head register
BACKLOG_MAX = 110                           # ordinary bursts stay below this backlog
TIMEOUT_CLK = 20 * 4                        # fmt_core_sim_top: UART_TIMEOUT 20 bit times
LATE_MAX = 200                              # clk a reply may end after the timing model's end
DISCARD_TAIL = 5                            # bytes after a LEN > PAYLOAD_MAX header

# Registers the fuzzer must never write, and why.  Every other address may be written:
# the rw registers (kept in the shadow), const and ro registers and unmapped addresses
# (the protocol says writes there are ignored: checked where the value is known).
NEVER_WRITE = {
    "RUN": "0 silences the transmitters: the core's operating mode",
    "PN_ENABLE": "PN stir/unstir on/off: the receive chain's mode",
    "PN_CHIP_LEN": "PN chip length: the receive chain's mode",
    "PN_RX_DELAY": "PN receive delay: the receive chain's mode",
    "WINDOWS_M": "windows per frame (up to 255x longer frames): the core's frame timing",
    "TONE_TW": "window into the DDS tone plan (rewrites a row's tone)",
    "TONE_AMP": "window into the DDS tone plan (a row's amplitude / enable)",
    "CAL_OFFSET": "window into the calibration memory (field-flattening offsets)",
    "CAL_GAIN": "window into the calibration memory (field-flattening gains)",
    "STATUS": "w1c sticky flags: written only as the bit-4 clear (0x10) the model tracks",
    "SAT_CLEAR": "strobe: clears the flattening saturation monitor",
    "LAT_CLEAR": "strobe: clears the latency statistics",
    "SNAP_REQ": "strobe: starts a heat-map snapshot (the block window changes)",
}
# rw registers among NEVER_WRITE stay in the shadow: their values must never change.

REGS = {r.addr: r for r in regmap.REGISTERS}
NO_WRITE_ADDRS = {regmap.BY_NAME[n].addr for n in NEVER_WRITE}
RW_ADDRS = sorted(r.addr for r in regmap.REGISTERS if r.access == "rw")
WRITABLE_RW = [a for a in RW_ADDRS if a not in NO_WRITE_ADDRS]
A_STATUS = regmap.BY_NAME["STATUS"].addr
A_ERRORS = regmap.BY_NAME["CTRL_ERRORS"].addr
A_LAST = regmap.BY_NAME["CTRL_LAST_ERR"].addr
STATUS_CTRL_BIT = 0x10
MAP_END = max(REGS) + 1


class Fail(Exception):
    """A check failed: (message, offending request bytes)."""

    def __init__(self, msg: str, frame: bytes = b""):
        super().__init__(msg)
        self.msg, self.frame = msg, frame


# ---- the expected behaviour ------------------------------------------------------------------
class Unsafe(Exception):
    """A burst would write a register of NEVER_WRITE or turn the stream on (a mutation
    or stray SYNC that happens to make a frame with a good CRC): not sent."""


class Model(P.CtrlPortModel):
    """CtrlPortModel plus the register shadow.  ``execute`` answers valid requests from
    the shadow and records, per reply, a bit mask of the payload bytes that are checked
    (0 = the core's own state, not predicted)."""

    errors = 0                              # every error, unsaturated

    def __init__(self, shadow: dict, err_count: int, err_last: int, status_err: bool):
        super().__init__(self._execute, PAYLOAD_MAX)
        self.regs = dict(shadow)            # rw registers as the WRITEs executed so far leave them
        self.err_count = err_count
        self._last = err_last
        self.status_err = status_err
        self.errors = 0                     # every error, unsaturated
        self.masks: list[bytes] = []        # one per good reply of the current burst

    def clone(self) -> "Model":
        m = Model(self.regs, self.err_count, self._last, self.status_err)
        m.errors = self.errors
        return m

    # every error sets err_last (CtrlPortModel._err and the junk-before-a-frame count)
    @property
    def err_last(self):
        return self._last

    @err_last.setter
    def err_last(self, code):
        self._last = code
        self.errors += 1
        self.status_err = True

    def read_word(self, a: int) -> tuple[int, int]:
        """(value, checked-bits mask) of register address a."""
        r = REGS.get(a)
        if r is None:
            return 0, 0xFFFFFFFF                    # unmapped: reads 0
        if r.access == "rw":
            return self.regs[a], 0xFFFFFFFF
        if r.access == "const":
            return r.reset, 0xFFFFFFFF
        if r.access == "strobe":
            return 0, 0xFFFFFFFF
        if a == A_ERRORS:
            return self.err_count, 0xFFFFFFFF
        if a == A_LAST:
            return self._last, 0xFFFFFFFF
        if a == A_STATUS:
            return (STATUS_CTRL_BIT if self.status_err else 0), STATUS_CTRL_BIT | 0xFFFFFF00
        return 0, 0xFFFFFFFF ^ ((1 << r.width) - 1)   # ro / window: the core's state; bits above
        #                                             the width read 0

    def _execute(self, seq, cmd, p):
        if cmd == P.CMD_INFO:
            out = P.info_payload(CFG, REGMAP_ID, PAYLOAD_MAX)
            mask = b"\xff" * len(out)
        elif cmd == P.CMD_READ:
            addr, count = struct.unpack(">HB", p)
            vals = [self.read_word((addr + i) & 0xFFFF) for i in range(count)]
            out = b"".join(struct.pack(">I", v) for v, _m in vals)
            mask = b"".join(struct.pack(">I", m) for _v, m in vals)
        elif cmd == P.CMD_WRITE:
            addr = (p[0] << 8) | p[1]
            if any((addr + i) & 0xFFFF in NO_WRITE_ADDRS and not (
                    (addr + i) & 0xFFFF == A_STATUS and p[2 + 4 * i:6 + 4 * i] == bytes([0, 0, 0, STATUS_CTRL_BIT]))
                   for i in range((len(p) - 2) // 4)):
                raise Unsafe()
            for i in range((len(p) - 2) // 4):
                a = (addr + i) & 0xFFFF
                v = struct.unpack(">I", p[2 + 4 * i:6 + 4 * i])[0]
                r = REGS.get(a)
                if r is not None and r.access == "rw":
                    self.regs[a] = v & ((1 << r.width) - 1)
                elif a == A_STATUS and v & STATUS_CTRL_BIT:
                    self.status_err = False
            out = mask = b""
        elif cmd == P.CMD_BLKREAD:
            n = (p[2] << 8) | p[3]
            out, mask = bytes(4 * n), bytes(4 * n)  # heat-map snapshot / histograms: not predicted
        else:                                       # STREAM (the fuzzer sends only "off")
            if p[0] & 1:
                raise Unsafe()
            out = mask = b""
        self.masks.append(mask)
        return out


def scan(data: bytes, payload_max: int = PAYLOAD_MAX):
    """Where the port replies in a burst: [(trigger byte index or None = after the idle
    timeout, frame start, kind)] with kind 'ok', 'err' or 'discard' (LEN > PAYLOAD_MAX:
    the rest is discarded).  Mirrors CtrlPortModel.burst (checked: same count)."""
    out = []
    i, n, junk = 0, len(data), False
    while i < n:
        b = data[i]
        i += 1
        if b != P.SYNC:
            junk = True
            continue
        junk = False
        s = i - 1
        if n - i < 4:
            out.append((None, s, "err"))
            return out
        hdr = data[i:i + 4]
        ln, cmd = (hdr[0] << 8) | hdr[1], hdr[3]
        i += 4
        if ln > payload_max:
            out.append((i - 1, s, "discard"))
            return out
        if n - i < ln + 2:
            out.append((None, s, "err"))
            return out
        payload = bytes(data[i:i + ln])
        crc = (data[i + ln] << 8) | data[i + ln + 1]
        i += ln + 2
        if P.crc16(bytes(hdr) + payload) != crc:
            out.append((i - 1, s, "err"))
            continue
        # good CRC: a reply or a LEN / CMD error; a WRITE executes for LEN - 2 clk first
        exec_clk = ln + 2 if cmd == P.CMD_WRITE else 2
        out.append((i - 1, s, ("ok", exec_clk)))
    if junk:
        out.append((None, n, "err"))
    return out


def timeline(data: bytes, replies: list[bytes], where):
    """A timing model of the port: (backlog, end) per reply.  backlog: bytes waiting
    in the receive FIFO when the reply has gone out; end: clk from the start bit of the
    burst's first byte to the end of the reply.  Host bytes enter the FIFO every
    BYTE_CLK (plus the receiver's latency), the parser takes one byte per clk when it
    is not replying, a reply of L bytes keeps it busy for L * BYTE_CLK (plus a few clk;
    a WRITE first writes for LEN clk).  A reply after the idle timeout (TIMEOUT, JUNK)
    has nothing after it: backlog 0."""
    arrive = lambda k: BYTE_CLK * (k + 1) + 8
    t, k, backlog, ends = 0.0, 0, [], []
    for (trig, _s, kind), rep in zip(where, replies):
        if trig is None:
            while k < len(data):
                t = max(t + 1, arrive(k))
                k += 1
            t += TIMEOUT_CLK + 2 + BYTE_CLK * len(rep) + 6
            backlog.append(0)
            ends.append(t)
            continue
        while k <= trig:
            t = max(t + 1, arrive(k))
            k += 1
        t += (kind[1] if isinstance(kind, tuple) else 2) + BYTE_CLK * len(rep) + 6
        backlog.append(min(len(data), int((t - 8) // BYTE_CLK)) - (trig + 1))
        ends.append(t)
    return backlog, ends


# ---- the burst generator -------------------------------------------------------------------
class Gen:
    def __init__(self, rng: random.Random):
        self.r = rng
        self.seq = 0

    def s(self):
        self.seq = (self.seq + 1) & 0xFF
        return self.seq

    def addr_read(self):
        r = self.r.random()
        if r < 0.75:
            return self.r.randrange(0, MAP_END + 8)
        if r < 0.9:
            return self.r.choice([A_STATUS, A_ERRORS, A_LAST])
        return self.r.randrange(0, 1 << 16)

    def writable(self, a: int) -> bool:
        return a not in NO_WRITE_ADDRS

    def write_range(self):
        """(addr, k): k consecutive writable addresses."""
        r = self.r
        for _ in range(20):
            if r.random() < 0.7:
                a = r.choice(WRITABLE_RW)
            elif r.random() < 0.5:
                a = r.randrange(0, MAP_END + 8)
            else:
                a = r.randrange(0, 1 << 16)
            kmax = (PAYLOAD_MAX - 2) // 4
            k = 1
            while k < kmax and r.random() < 0.6 and self.writable((a + k) & 0xFFFF):
                k += 1
            if all(self.writable((a + i) & 0xFFFF) for i in range(k)):
                return a, k
        return regmap.BY_NAME["SCRATCH"].addr, 1

    def value(self, a: int):
        r = self.r.random()
        if r < 0.3:
            return self.r.getrandbits(32)
        if r < 0.5:
            return self.r.choice([0, 1, 0xFFFFFFFF, 0x80000000, 0x7FFFFFFF])
        w = REGS[a].width if a in REGS else 32
        return self.r.getrandbits(w)

    def valid(self) -> bytes:
        r = self.r.random()
        if r < 0.40:
            a, k = self.write_range()
            return P.req_write(self.s(), a, [self.value((a + i) & 0xFFFF) for i in range(k)])
        if r < 0.60:
            return P.req_read(self.s(), self.addr_read(), self.r.choice([1, 1, 1, 2, 4, 8]))
        if r < 0.70:
            return P.req_read(self.s(), A_STATUS, 3)             # STATUS, CTRL_ERRORS, CTRL_LAST_ERR
        if r < 0.75:
            return P.req_write(self.s(), A_STATUS, [STATUS_CTRL_BIT])
        if r < 0.82:
            return P.req_info(self.s())
        if r < 0.90:
            base = self.r.choice([0, 0x8000, self.r.randrange(0, 1 << 16)])
            return P.req_blkread(self.s(), base, self.r.randrange(1, 5))
        return P.encode(self.s(), P.CMD_STREAM, bytes([self.r.randrange(0, 256) & 0xFE]))

    def bad_crc(self) -> bytes:
        f = bytearray(self.valid())
        i = self.r.choice([3, 4] + list(range(5, len(f))))    # SEQ, CMD, payload or CRC
        f[i] ^= 1 << self.r.randrange(8)
        return bytes(f)

    def wrong_len(self) -> bytes:
        r, s = self.r, self.s()
        c = r.randrange(7)
        if c == 0:
            return P.encode(s, P.CMD_INFO, bytes(r.randrange(1, 9)))
        if c == 1:
            return P.encode(s, P.CMD_READ, bytes(r.choice([0, 1, 2, 4, 5])))
        if c == 2:
            return P.encode(s, P.CMD_READ, struct.pack(">HB", r.randrange(0, 1 << 16), 0))
        if c == 3:
            n = r.choice([0, 1, 2, 3, 4, 5, 7, 8, 9, 11, 12, 64])
            return P.encode(s, P.CMD_WRITE, bytes([0, 2]) + bytes(max(0, n - 2)) if n >= 2 else bytes(n))
        if c == 4:
            return P.encode(s, P.CMD_BLKREAD, struct.pack(">HH", 0, r.choice([0, 16384, 0xFFFF, 0x8001])))
        if c == 5:
            return P.encode(s, P.CMD_BLKREAD, bytes(r.choice([0, 3, 5, 8])))
        return P.encode(s, P.CMD_STREAM, bytes(r.choice([0, 2, 3])))

    def bad_cmd(self) -> bytes:
        cmd = self.r.choice([0x00, 0x06, 0x7F, 0x80, 0x81, 0x83, 0xA5, 0xE0, 0xFF, self.r.randrange(6, 256)])
        return P.encode(self.s(), cmd, bytes(self.r.randrange(0, 9)))

    def junk(self) -> bytes:
        n = self.r.choice([1, 1, 2, 3, 5, 8, 17, 40, 200])
        b = bytes(self.r.randrange(256) for _ in range(n))
        if self.r.random() < 0.8:                          # mostly without stray SYNCs
            b = b.replace(bytes([P.SYNC]), b"\x5a")
        return b

    def mutated(self) -> bytes:
        f = bytearray(self.valid())
        for _ in range(self.r.choice([1, 1, 2, 3])):
            i = self.r.randrange(len(f))
            c = self.r.randrange(4)
            if c == 0 and len(f) > 1:
                del f[i]
            elif c == 1:
                f.insert(i, self.r.randrange(256))
            elif c == 2:
                f.insert(i, f[i])
            else:
                f[i] = self.r.randrange(256)
        return bytes(f)

    def storm(self) -> bytes:
        """Many errors in few bytes (one junk byte, then an unknown command with LEN 0:
        a JUNK count and a CMD error per 8 bytes): CTRL_ERRORS reaches its saturation
        at 0xFFFF within a 10^6-byte run."""
        out = bytearray()
        for _ in range(self.r.randrange(10, 80)):
            out.append(self.r.choice([0x00, 0x5A, 0xFF, 0x13]))
            out += P.encode(self.s(), self.r.choice([0x00, 0x06, 0x40, 0x7E]))
        return bytes(out)

    def run_of_valid(self) -> bytes:
        return b"".join(self.valid() for _ in range(self.r.randrange(2, 12)))

    def item(self) -> bytes:
        """One piece of a burst.  Most that would make the port discard the rest of the
        burst (a LEN above PAYLOAD_MAX from a mutation or a stray SYNC) are redrawn: the
        burst's ending tests that case."""
        for _ in range(10):
            b = self._item()
            if self.r.random() < 0.05 or not any(w[2] == "discard" for w in scan(b)):
                return b
        return b

    def _item(self) -> bytes:
        r = self.r.random()
        if r < 0.35:
            return self.valid()
        if r < 0.47:
            return self.bad_crc()
        if r < 0.57:
            return self.wrong_len()
        if r < 0.64:
            return self.bad_cmd()
        if r < 0.78:
            return self.junk()
        if r < 0.90:
            return self.mutated()
        if r < 0.95:
            return self.storm()
        return self.run_of_valid()

    def ending(self) -> bytes:
        r = self.r.random()
        if r < 0.25:                                        # truncated frame
            f = self.valid()
            return f[:self.r.randrange(1, len(f))]
        if r < 0.37:                                        # LEN > PAYLOAD_MAX, then a short tail
            ln = self.r.choice([PAYLOAD_MAX + 1, 0x100, 0xFFFF, self.r.randrange(PAYLOAD_MAX + 1, 1 << 16)])
            return (bytes([P.SYNC]) + struct.pack(">HBB", ln, self.s(), self.r.randrange(256))
                    + bytes(self.r.randrange(256) for _ in range(self.r.randrange(0, DISCARD_TAIL + 1))))
        if r < 0.5:
            return self.junk()
        return b""

    def burst(self, target: int) -> bytes:
        out = bytearray()
        while len(out) < target:
            out += self.item()
        return bytes(out + self.ending())

    def overflow_burst(self) -> bytes:
        """A request with a reply of >= 187 bytes, then filler while it goes out."""
        if self.r.random() < 0.5:
            n = self.r.randrange(45, 64)
            head = P.req_read(self.s(), self.r.randrange(0, MAP_END), n)
        else:
            n = self.r.randrange(45, 64)
            head = P.req_blkread(self.s(), self.r.choice([0, 0x8000]), n)
        reply_len = 4 * n + 7
        fill = bytearray()
        goal = self.r.randrange(140, reply_len - 8)
        while len(fill) < goal:
            fill += self.item()
        return head, bytes(fill[:goal])


def fit_burst(model: "Model", data: bytes):
    """Make a burst predictable: the backlog must stay below BACKLOG_MAX (junk bytes go
    in before a request whose reply would exceed it, so that the parser catches up, or
    the burst ends with a request whose reply is long) and a LEN > PAYLOAD_MAX discard
    must end before its ERROR reply does.  Returns (data, where, replies, max backlog,
    reply ends, the model after the burst); model itself is not changed."""
    for it in range(1000):
        where = scan(data)
        dis = [w for w in where if w[2] == "discard"]
        if dis and len(data) - dis[0][0] - 1 > DISCARD_TAIL:
            data = data[:dis[0][0] + 1 + DISCARD_TAIL]
            continue
        after = model.clone()
        replies = after.burst(data)
        if len(replies) != len(where):
            raise Fail(f"scan/model disagree: {len(where)} against {len(replies)} replies", data)
        backlog, ends = timeline(data, replies, where)
        over = [j for j, b in enumerate(backlog) if b > BACKLOG_MAX]
        if not over:
            return data, where, replies, max(backlog, default=0), ends, after
        trig, start, _kind = where[over[0]]
        if it >= 200:
            data = data[:start]             # (never seen: many fixes) cut before the request
        elif len(replies[over[0]]) > BACKLOG_MAX // 2:
            data = data[:trig + 1]          # a long reply: the burst ends with its request
        else:                               # junk before the request lets the parser catch up
            data = data[:start] + bytes(junk_rng.choice(JUNK_BYTES) for _ in range(backlog[over[0]])) + data[start:]
    raise Fail("could not fit a burst", data)


JUNK_BYTES = bytes(b for b in range(256) if b != P.SYNC)
junk_rng = random.Random()                  # seeded by Fuzzer (the bytes depend on --seed only)


# ---- the simulation and the socket ------------------------------------------------------------
def start_server(out_dir: Path, tag: str, cflags: str, frames: int) -> ServeProc:
    """run_sim_rtl in serve mode (--serve 0 --serve-once) in its own session."""
    return ServeProc(out_dir, [
        "--scene", str(ROOT / "sim" / "scenes" / "small.json"), "--frames", str(frames), "--serve", "0",
        "--serve-once", "--serve-seconds", "3600", "--serve-log-frames", "0", "--no-plot", "--quiet",
        "--tag", tag, f"--cflags={cflags}", "--out", str(out_dir)])


class Link:
    """The socket to the simulated UART; replies are read with a wall-time bound."""

    def __init__(self, host: str, port: int):
        self.s = socket.create_connection((host, port), timeout=30)
        self.s.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self.buf = bytearray()
        self.sent = 0                       # bytes of the fuzzing (after the start)
        self.total_sent = 0                 # every host byte on the line
        self.total_read = 0                 # every reply byte taken

    def send(self, data: bytes):
        self.s.sendall(data)
        self.sent += len(data)
        self.total_sent += len(data)

    def read(self, n: int, wall_s: float) -> bytes:
        t_end = time.monotonic() + wall_s
        while len(self.buf) < n:
            left = t_end - time.monotonic()
            if left <= 0:
                break
            self.s.settimeout(left)
            try:
                chunk = self.s.recv(65536)
            except socket.timeout:
                break
            if not chunk:
                break
            self.buf += chunk
        out = bytes(self.buf[:n])
        del self.buf[:n]
        self.total_read += len(out)
        return out

    def quiet(self, wall_s: float) -> bytes:
        """Whatever arrives within wall_s (must be nothing)."""
        self.s.settimeout(wall_s)
        try:
            chunk = self.s.recv(65536)
        except socket.timeout:
            chunk = b""
        return bytes(self.buf) + chunk

    def close(self):
        self.s.close()


def check_replies(link: Link, expected: list[tuple[bytes, bytes]], wall_s: float, requests: list[bytes]):
    """Read the replies one by one and compare: header bytes, checked payload bits, a
    valid CRC.  requests[j]: the request bytes behind reply j (for the message)."""
    for j, (exp, mask) in enumerate(expected):
        got = link.read(len(exp), wall_s)
        what = f"reply {j + 1}/{len(expected)}"
        if len(got) < len(exp):
            raise Fail(f"{what}: no reply within {wall_s:.0f} s (hang): expected {exp.hex()}, "
                       f"got {got.hex() or 'nothing'}", requests[j])
        if got[:5] != exp[:5]:
            raise Fail(f"{what}: header {got[:5].hex()} != expected {exp[:5].hex()} "
                       f"(reply {got.hex()}, expected {exp.hex()})", requests[j])
        pl = len(exp) - 7
        for i in range(pl):
            if (got[5 + i] ^ exp[5 + i]) & mask[i]:
                w = i // 4
                raise Fail(f"{what}: payload byte {i} (word {w}) differs: reply {got.hex()}, expected "
                           f"{exp.hex()} (checked bits of the word {mask[4 * w:4 * w + 4].hex()})", requests[j])
        if P.crc16(got[1:5 + pl]) != struct.unpack(">H", got[5 + pl:])[0]:
            raise Fail(f"{what}: bad CRC in reply {got.hex()}", requests[j])


class Burst:
    """A burst ready to send: bytes, expected replies with their masks, the request
    behind each reply, the model after it."""

    def __init__(self, data, replies, masks, requests, model, overflow=False, backlog=0, ends=()):
        self.data, self.requests, self.model = data, requests, model
        self.overflow, self.backlog, self.ends = overflow, backlog, list(ends)
        self.trigs: list = []               # byte index behind each reply (None: after the timeout)
        self.h0 = self.d0 = 0               # index of its first host byte / reply byte on the line
        it = iter(masks)
        self.expected = [(r, b"\xff\xff" if r[4] == P.CMD_ERROR else next(it)) for r in replies]


class Fuzzer:
    """Sends bursts and checks their replies; the next burst is prepared (from the
    model's state after the current one) while the simulation answers."""

    def __init__(self, link: Link, seed: int, wall_per_burst: float):
        self.link = link
        self.seed = seed
        self.gen = Gen(random.Random(seed))
        junk_rng.seed(seed + 1)
        self.wall = wall_per_burst
        self.stats = {"bursts": 0, "overflow_bursts": 0, "frames_valid": 0, "replies": 0,
                      "error_replies": 0, "max_backlog": 0}
        self.model: Model | None = None
        self.burst_no = 0
        self.done: list[Burst] = []         # the bursts sent, for the timing check

    def start(self):
        """Read every rw register, STATUS and the error counters: the shadow's start."""
        link, shadow = self.link, {}
        for a in RW_ADDRS:
            link.send(P.req_read(0, a, 1))
            fr = link.read(11, self.wall)
            if len(fr) != 11 or fr[4] != (P.CMD_READ | 0x80):
                raise Fail(f"initial READ of 0x{a:03X}: {fr.hex()}", P.req_read(0, a, 1))
            shadow[a] = struct.unpack(">I", fr[5:9])[0]
        link.send(P.req_read(0, A_STATUS, 3))
        fr = link.read(19, self.wall)
        if len(fr) != 19:
            raise Fail(f"initial READ of STATUS..CTRL_LAST_ERR: {fr.hex()}", P.req_read(0, A_STATUS, 3))
        st, cnt, last = struct.unpack(">III", fr[5:17])
        self.model = Model(shadow, cnt, last, bool(st & STATUS_CTRL_BIT))
        self.shadow = dict(shadow)
        self.initial = {"ctrl_errors": cnt, "last_err": last}
        self.link.sent = 0

    def prepare(self) -> Burst:
        g = self.gen
        while True:
            if g.r.random() < 0.1:
                head, fill = g.overflow_burst()
                after = self.model.clone()
                after.masks = []
                replies = after.burst(head)
                assert len(replies) == 1 and replies[0][4] != P.CMD_ERROR
                after._err(replies, 0, P.ERR_OVERFLOW, 0)
                e1 = BYTE_CLK * len(head) + 8 + 2 + BYTE_CLK * len(replies[0]) + 6
                b = Burst(head + fill, replies, after.masks, [head, head + fill], after, overflow=True,
                          ends=[e1, e1 + 2 + BYTE_CLK * len(replies[1]) + 6])
                b.trigs = [len(head) - 1, None]
            else:
                data = g.burst(g.r.choice([20, 200, 1000, 3000, 6000, 6000]))
                try:
                    fit = fit_burst(self.model, data)
                except Unsafe:
                    continue
                if not fit[0]:
                    continue
                data, where, replies, backlog, ends, after = fit
                requests = [data[w[1]:(w[0] + 1 if w[0] is not None else len(data))] for w in where]
                b = Burst(data, replies, after.masks, requests, after, backlog=backlog, ends=ends)
                b.trigs = [w[0] for w in where]
            after.masks = []
            self.model = after                  # the model runs one burst ahead of the checks
            return b

    def check(self, b: Burst):
        check_replies(self.link, b.expected, self.wall, b.requests)
        # every reply came back in order, so each WRITE's ACK was checked before the
        # replies after it: the shadow takes this burst's WRITEs
        self.shadow = dict(b.model.regs)
        st = self.stats
        st["overflow_bursts" if b.overflow else "bursts"] += 1
        st["replies"] += len(b.expected)
        st["error_replies"] += sum(1 for r, _m in b.expected if r[4] == P.CMD_ERROR)
        st["frames_valid"] += sum(1 for r, _m in b.expected if r[4] != P.CMD_ERROR)
        st["max_backlog"] = max(st["max_backlog"], b.backlog)

    def run(self, nbytes: int):
        """Up to two bursts are prepared ahead, while the simulation answers the one
        sent, so that a long preparation after a short burst leaves no idle line."""
        ahead = [self.prepare()]
        while ahead:
            cur = ahead.pop(0)
            self.burst_no += 1
            cur.h0, cur.d0 = self.link.total_sent, self.link.total_read
            self.done.append(cur)
            self.link.send(cur.data)
            while len(ahead) < 2 and self.link.sent + sum(len(b.data) for b in ahead) < nbytes:
                ahead.append(self.prepare())
            self.check(cur)
        self.finish()

    def finish(self):
        """A final READ of every rw register and the counters, then a quiet line."""
        data = b"".join(P.req_read(0x40 + i, a, 1) for i, a in enumerate(RW_ADDRS))
        data += P.req_read(0x7F, A_STATUS, 3)
        where = scan(data)
        after = self.done[-1].model.clone()    # = self.model: nothing prepared is left unsent
        replies = after.burst(data)
        self.model = after
        self.burst_no += 1
        b = Burst(data, replies, after.masks, [data[w[1]:w[0] + 1] for w in where], after,
                  ends=timeline(data, replies, where)[1])
        b.h0, b.d0 = self.link.total_sent, self.link.total_read
        self.done.append(b)
        self.link.send(data)
        self.check(b)
        extra = self.link.quiet(1.0)
        if extra:
            raise Fail(f"{len(extra)} bytes after the last reply: {extra[:64].hex()}")


def check_timing(log: Path, bursts: list[Burst]) -> dict:
    """"Never hangs", in clk: serve.log has the cycle of every host byte (H, at the end
    of its stop bit) and every reply byte (D, decoded at the middle of its stop bit).
    Each reply must end by the timing model's end (relative to its burst's first start
    bit) + LATE_MAX clk.  Returns the largest lateness and the longest time from a
    burst's last host byte to its last reply byte."""
    h, d = [], []
    with open(log) as f:
        for line in f:
            if line[0] == "H":
                h.append(int(line.split()[1]))
            elif line[0] == "D":
                d.append(int(line.split()[1]))
    import bisect
    late, drain, backlog = -10 ** 9, 0, 0
    for bno, b in enumerate(bursts, 1):
        t0 = h[b.h0] - BYTE_CLK
        last_h = h[b.h0 + len(b.data) - 1]
        if last_h - h[b.h0] != BYTE_CLK * (len(b.data) - 1):    # the timing model's premise
            raise Fail(f"burst {bno}: the harness did not send its {len(b.data)} bytes back to back "
                       f"({last_h - h[b.h0]} clk from the first to the last)", b.data)
        pos = b.d0
        for j, ((rep, _m), end) in enumerate(zip(b.expected, b.ends)):
            pos += len(rep)
            got = d[pos - 1] - t0
            if got > end + LATE_MAX:
                raise Fail(f"burst {bno} reply {j + 1}: ended {got} clk after the burst's start, "
                           f"the timing model says {end:.0f} (+{LATE_MAX})", b.requests[j])
            late = max(late, got - end)
            if not b.overflow and j < len(b.trigs) and b.trigs[j] is not None:
                # host bytes on the line by the reply's end, not yet parsed (an upper bound)
                backlog = max(backlog, bisect.bisect_right(h, d[pos - 1]) - (b.h0 + b.trigs[j] + 1))
        drain = max(drain, d[pos - 1] - last_h)
    if backlog >= FIFO_BYTES:
        raise Fail(f"a receive backlog of {backlog} bytes: the ordinary bursts overflowed the FIFO")
    return {"latest_vs_model_clk": round(late), "max_drain_clk": drain, "max_backlog_logged": backlog, "host_bytes_logged": len(h),
            "reply_bytes_logged": len(d)}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bytes", type=int, default=1_000_000, help="host bytes to send (default 10^6)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--port", default=None,
                    help="socket://127.0.0.1:P of a running serve (default: start the small core)")
    ap.add_argument("--tag", default="fuzz", help="build tag of the C++ harness (run_sim_rtl --tag)")
    ap.add_argument("--cflags", default="-O3 -march=native", help="C++ flags of the harness build")
    ap.add_argument("--out", default=str(ROOT / "build" / "fuzz"))
    ap.add_argument("--wall", type=float, default=60.0,
                    help="wall-time bound per burst's replies (s): longer is a hang")
    ap.add_argument("--json", action="store_true", help="print the summary as one JSON line")
    a = ap.parse_args(argv)
    fast_crc()
    if a.bytes < 1:
        print("fuzz_ctrl: --bytes must be >= 1", file=sys.stderr)
        return 2
    srv = None
    t0 = time.monotonic()
    try:
        if a.port:
            m = re.match(r"socket://([\w.]+):(\d+)$", a.port)
            if not m:
                print(f"fuzz_ctrl: --port {a.port}: expected socket://HOST:PORT", file=sys.stderr)
                return 2
            host, port = m.group(1), int(m.group(2))
        else:
            srv = start_server(Path(a.out), a.tag, a.cflags, frames=4)
            try:
                m = srv.wait_serving(wall_s=1200.0)
                host, port = m.group(2), int(m.group(3))
            except ServeFailed as exc:
                print(f"fuzz_ctrl: {exc}", file=sys.stderr)
                return 2
        t_serve = time.monotonic()
        try:
            link = Link(host, port)
        except OSError as exc:
            print(f"fuzz_ctrl: cannot connect to {host}:{port}: {exc}", file=sys.stderr)
            return 2
        fz = Fuzzer(link, a.seed, a.wall)
        try:
            fz.start()
            fz.run(a.bytes)
        except Fail as f:
            print(f"fuzz_ctrl: FAIL seed={a.seed} burst={fz.burst_no} after {link.sent} bytes: {f.msg}; "
                  f"frame {f.frame.hex() or '-'}", file=sys.stderr)
            return 1
        finally:
            link.close()
        t_end = time.monotonic()
        m = fz.model
        st = dict(fz.stats, seed=a.seed, bytes=link.sent, errors=m.errors, initial=fz.initial,
                  ctrl_errors=m.err_count, fuzz_wall_s=round(t_end - t_serve, 1),
                  total_wall_s=round(t_end - t0, 1))
        if srv is not None:
            try:
                rc, text = srv.finish(wall_s=300.0)
            except ServeFailed as exc:
                rc, text = -1, str(exc)
            srv = None
            mm = re.search(r"served the UART for (\d+) clk", text)
            st["sim_clk"] = int(mm.group(1)) if mm else None
            if rc != 0 or "golden mismatches 0" not in text:
                print(f"fuzz_ctrl: FAIL seed={a.seed}: the simulation ended with {rc}: {text[-1500:]}",
                      file=sys.stderr)
                return 1
            from bench.core import run_sim_rtl as rsr
            try:
                st.update(check_timing(rsr.job_dir(CFG, 3, a.tag) / "serve.log", fz.done))
            except Fail as f:
                print(f"fuzz_ctrl: FAIL seed={a.seed}: {f.msg}; frame {f.frame.hex() or '-'}", file=sys.stderr)
                return 1
        if a.json:
            print(json.dumps(st))
        else:
            timing = (f", {st['sim_clk']} clk, replies at most {st['latest_vs_model_clk']} clk after the "
                      f"timing model, receive backlog at most {st['max_backlog_logged']} bytes (logged)"
                      if "latest_vs_model_clk" in st else "")
            print(f"fuzz_ctrl: seed {a.seed}: {st['bytes']} bytes in {st['bursts']} bursts + "
                  f"{st['overflow_bursts']} overflow bursts, {st['replies']} replies ({st['frames_valid']} "
                  f"to valid requests, {st['error_replies']} ERROR), {st['errors']} errors counted "
                  f"(CTRL_ERRORS {st['ctrl_errors']}){timing}, "
                  f"{st['fuzz_wall_s']} s fuzzing, {st['total_wall_s']} s in all: pass")
        return 0
    finally:
        if srv is not None:
            srv.kill()


if __name__ == "__main__":
    sys.exit(main())
