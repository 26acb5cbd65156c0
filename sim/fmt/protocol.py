"""Control-port frame protocol: encode/decode, CRC-16/CCITT-FALSE, stream parser.

This module is both the host side (used by ``scripts/fmtctl``) and the model twin of
``rtl/fmt_ctrl_port.v`` (the byte-level reply of every request, including the error
replies, is predicted here and compared bit for bit by the testbenches).

Frame (both directions), all multi-byte fields big-endian::

    SYNC(0xA5) LEN_H LEN_L SEQ CMD PAYLOAD[LEN] CRC_H CRC_L

LEN counts the payload bytes only.  The CRC is CRC-16/CCITT-FALSE (poly 0x1021,
init 0xFFFF, no reflection, no final XOR) over LEN_H..PAYLOAD (everything between
the sync byte and the CRC).  A reply echoes the request's SEQ and carries
CMD | 0x80; an error reply carries CMD = 0xFF and payload [code, request CMD].
Unsolicited event frames carry CMD = 0xE0 and their own running SEQ.
"""
from __future__ import annotations

import struct
from dataclasses import dataclass

import numpy as np

SYNC = 0xA5
VERSION = 0x0100            # protocol version reported by INFO (major.minor)
INFO_MAGIC = 0x464D5443     # "FMTC"

# ---- commands (request CMD byte) ------------------------------------------------------
CMD_INFO = 0x01      # payload: none. Reply: INFO_LEN bytes, see decode_info()
CMD_READ = 0x02      # payload: ADDR(2) COUNT(1), COUNT 1..255. Reply: COUNT x DATA(4)
CMD_WRITE = 0x03     # payload: ADDR(2) DATA(4) x k, k >= 1. Writes ADDR, ADDR+1, ...; reply empty
CMD_BLKREAD = 0x04   # payload: ADDR(2) COUNT(2), COUNT 1..16383. Reply: COUNT x WORD(4)
CMD_STREAM = 0x05    # payload: ON(1), bit 0 = event streaming on. Reply empty
REPLY_FLAG = 0x80
CMD_ERROR = 0xFF     # error reply: payload CODE(1) REQ_CMD(1)
CMD_EVENT = 0xE0     # unsolicited event frame, payload EVENT_BYTES

COMMANDS = {CMD_INFO: "INFO", CMD_READ: "READ", CMD_WRITE: "WRITE",
            CMD_BLKREAD: "BLKREAD", CMD_STREAM: "STREAM"}

# ---- error codes ------------------------------------------------------------------------
ERR_CRC = 1        # CRC mismatch (frame fully received)
ERR_TIMEOUT = 2    # truncated frame: line idle for the inter-byte timeout inside a frame
ERR_LEN = 3        # LEN > payload buffer, or LEN/COUNT not valid for the command
ERR_CMD = 4        # unknown command (CRC was good)
ERR_JUNK = 5       # bytes outside any frame (one error per burst)
ERR_FRAMING = 6    # UART stop bit low inside a frame
ERR_OVERFLOW = 7   # receive FIFO overflow (bytes sent while the port was replying)
ERROR_NAMES = {ERR_CRC: "bad CRC", ERR_TIMEOUT: "timeout (truncated frame)",
               ERR_LEN: "bad length", ERR_CMD: "unknown command", ERR_JUNK: "junk bytes",
               ERR_FRAMING: "UART framing error", ERR_OVERFLOW: "receive overflow"}

MAX_READ = 255
MAX_BLKREAD = 16383
DEFAULT_PAYLOAD_MAX = 64     # request payload buffer of the RTL (parameter PAYLOAD_MAX)
INFO_LEN = 16
EVENT_BYTES = 24


class ProtocolError(Exception):
    """A reply that cannot be decoded or an error reply."""


# ---- CRC --------------------------------------------------------------------------------
def _make_table() -> list[int]:
    t = []
    for b in range(256):
        c = b << 8
        for _ in range(8):
            c = ((c << 1) ^ 0x1021) if c & 0x8000 else (c << 1)
            c &= 0xFFFF
        t.append(c)
    return t


_TABLE = _make_table()


def crc16(data: bytes, crc: int = 0xFFFF) -> int:
    """CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF, MSB first, no final XOR)."""
    for b in data:
        crc = ((crc << 8) & 0xFFFF) ^ _TABLE[((crc >> 8) ^ b) & 0xFF]
    return crc


# ---- frames ------------------------------------------------------------------------------
@dataclass(frozen=True)
class Frame:
    seq: int
    cmd: int
    payload: bytes = b""


def encode(seq: int, cmd: int, payload: bytes = b"") -> bytes:
    """One frame: SYNC LEN(2) SEQ CMD PAYLOAD CRC(2)."""
    payload = bytes(payload)
    if len(payload) > 0xFFFF:
        raise ValueError("payload longer than 65535 bytes")
    body = struct.pack(">HBB", len(payload), seq & 0xFF, cmd & 0xFF) + payload
    return bytes([SYNC]) + body + struct.pack(">H", crc16(body))


class Parser:
    """Incremental host-side frame parser that always resynchronises: it hunts for
    SYNC, and when the CRC of a candidate frame fails it drops only that sync byte and
    hunts again from the next byte (so a frame hidden behind garbage is still found).
    ``max_len`` bounds LEN (a larger LEN is taken as a false sync)."""

    def __init__(self, max_len: int = 0xFFFF):
        self.buf = bytearray()
        self.max_len = max_len
        self.dropped = 0           # bytes discarded while hunting

    def feed(self, data: bytes) -> list[Frame]:
        self.buf += data
        out = []
        while True:
            i = self.buf.find(bytes([SYNC]))
            if i < 0:
                self.dropped += len(self.buf)
                self.buf.clear()
                return out
            if i:
                self.dropped += i
                del self.buf[:i]
            if len(self.buf) < 3:
                return out
            n = (self.buf[1] << 8) | self.buf[2]
            if n > self.max_len:
                self.dropped += 1
                del self.buf[:1]
                continue
            total = 1 + 4 + n + 2
            if len(self.buf) < total:
                return out
            body = bytes(self.buf[1:5 + n])
            crc = (self.buf[5 + n] << 8) | self.buf[6 + n]
            if crc16(body) != crc:
                self.dropped += 1
                del self.buf[:1]
                continue
            out.append(Frame(seq=body[2], cmd=body[3], payload=body[4:]))
            del self.buf[:total]


def decode(data: bytes) -> list[Frame]:
    """All valid frames in ``data`` (garbage and corrupt frames skipped)."""
    return Parser().feed(data)


# ---- request payloads --------------------------------------------------------------------
def req_info(seq: int) -> bytes:
    return encode(seq, CMD_INFO)


def req_read(seq: int, addr: int, count: int = 1) -> bytes:
    return encode(seq, CMD_READ, struct.pack(">HB", addr, count))


def req_write(seq: int, addr: int, values) -> bytes:
    vals = [int(v) & 0xFFFFFFFF for v in values]
    return encode(seq, CMD_WRITE, struct.pack(">H", addr) + b"".join(struct.pack(">I", v) for v in vals))


def req_blkread(seq: int, addr: int, count: int) -> bytes:
    return encode(seq, CMD_BLKREAD, struct.pack(">HH", addr, count))


def req_stream(seq: int, on: bool) -> bytes:
    return encode(seq, CMD_STREAM, bytes([1 if on else 0]))


# ---- INFO --------------------------------------------------------------------------------
def info_payload(cfg, regmap_id: int, payload_max: int = DEFAULT_PAYLOAD_MAX,
                 version: int = VERSION) -> bytes:
    """The INFO reply payload of the RTL built for ``cfg`` (16 bytes):
    MAGIC(4) VERSION(2) ROWS(1) COLS(1) LOG2_N(1) HM_W(1) BIN_LO(1) BIN_STEP(1)
    REGMAP_ID(2, low 16 bits of the register-map hash) PAYLOAD_MAX(2)."""
    return struct.pack(">IHBBBBBBHH", INFO_MAGIC, version, cfg.rows, cfg.cols, cfg.log2_n,
                       cfg.hm_width, cfg.bin_lo, cfg.bin_step, regmap_id & 0xFFFF, payload_max)


def decode_info(p: bytes) -> dict:
    if len(p) != INFO_LEN:
        raise ProtocolError(f"INFO reply of {len(p)} bytes, expected {INFO_LEN}")
    magic, ver, rows, cols, l2n, hmw, blo, bst, rid, pmax = struct.unpack(">IHBBBBBBHH", p)
    if magic != INFO_MAGIC:
        raise ProtocolError(f"INFO magic 0x{magic:08X} is not 0x{INFO_MAGIC:08X}")
    return {"version": f"{ver >> 8}.{ver & 0xFF}", "rows": rows, "cols": cols,
            "n_fft": 1 << l2n, "hm_width": hmw, "bin_lo": blo, "bin_step": bst,
            "regmap_id": rid, "payload_max": pmax}


# ---- replies of the RTL (model twin) -----------------------------------------------------
def reply(seq: int, cmd: int, payload: bytes = b"") -> bytes:
    return encode(seq, cmd | REPLY_FLAG, payload)


def error_reply(seq: int, code: int, req_cmd: int = 0) -> bytes:
    return encode(seq, CMD_ERROR, bytes([code, req_cmd & 0xFF]))


def words_payload(words) -> bytes:
    return b"".join(struct.pack(">I", int(w) & 0xFFFFFFFF) for w in words)


def payload_words(p: bytes) -> list[int]:
    if len(p) % 4:
        raise ProtocolError(f"payload of {len(p)} bytes is not whole 32-bit words")
    return list(struct.unpack(f">{len(p) // 4}I", p))


def check_reply(fr: Frame, seq: int, cmd: int) -> bytes:
    """Payload of a good reply to (seq, cmd); ProtocolError on an error reply."""
    if fr.cmd == CMD_ERROR:
        code = fr.payload[0] if fr.payload else 0
        raise ProtocolError(f"device error {code} ({ERROR_NAMES.get(code, 'unknown')}) "
                            f"for command 0x{cmd:02X}")
    if fr.seq != seq or fr.cmd != (cmd | REPLY_FLAG):
        raise ProtocolError(f"unexpected reply seq={fr.seq} cmd=0x{fr.cmd:02X} "
                            f"to seq={seq} cmd=0x{cmd:02X}")
    return fr.payload


# ---- events ------------------------------------------------------------------------------
EVENT_FIELDS = ("frame", "time", "id", "type", "last", "x", "y", "strength",
                "axis_major", "axis_minor", "angle", "flags")
_EV_STRUCT = ">HIBBHHIHHBBH"   # 24 bytes; the last H is reserved (0)
EVENT_TYPES = {0: "new", 1: "move", 2: "lift", 3: "blob"}


def pack_event(ev: dict) -> bytes:
    """The 24-byte event payload (docs/PROTOCOL.md): frame(2) time(4) id(1)
    type_last(1: bits 1..0 type, bit 7 last) x(2) y(2) strength(4) axis_major(2)
    axis_minor(2) angle(1) flags(1) reserved(2).  x, y, axes: cells, 8 fraction bits."""
    tl = (ev["type"] & 3) | (0x80 if ev.get("last") else 0)
    return struct.pack(_EV_STRUCT, ev["frame"], ev["time"], ev["id"], tl, ev["x"], ev["y"],
                       ev["strength"], ev["axis_major"], ev["axis_minor"], ev["angle"],
                       ev["flags"], 0)


def unpack_event(p: bytes) -> dict:
    if len(p) != EVENT_BYTES:
        raise ProtocolError(f"event payload of {len(p)} bytes, expected {EVENT_BYTES}")
    f, t, i, tl, x, y, s, ma, mi, a, fl, _ = struct.unpack(_EV_STRUCT, p)
    return {"frame": f, "time": t, "id": i, "type": EVENT_TYPES[tl & 3], "last": bool(tl & 0x80),
            "x": x / 256.0, "y": y / 256.0, "strength": s, "axis_major": ma / 256.0,
            "axis_minor": mi / 256.0, "angle_rad": a * np.pi / 256.0, "flags": fl}


# ---- byte-level model of the RTL parser (twin of fmt_ctrl_port) ---------------------------
class CtrlPortModel:
    """The replies of ``rtl/fmt_ctrl_port.v`` to bursts of bytes.

    :meth:`burst` takes bytes sent back to back (each with a good stop bit) followed by
    an idle line of at least the inter-byte timeout, and returns the reply frames in
    order.  ``execute(seq, cmd, payload)`` is called for every request whose CRC, LEN
    and command are good and returns the reply payload (or None for the protocol's own
    STREAM/INFO handling done by the caller).  Receive-FIFO overflow is not modelled
    (bursts must not make the port reply for longer than the FIFO holds)."""

    def __init__(self, execute, payload_max: int = DEFAULT_PAYLOAD_MAX):
        self.execute = execute
        self.payload_max = payload_max
        self.err_count = 0
        self.err_last = 0

    def _err(self, out, seq, code, cmd):
        self.err_count = min(self.err_count + 1, 0xFFFF)
        self.err_last = code
        out.append(error_reply(seq, code, cmd))

    def _check(self, cmd: int, p: bytes):
        """Error code for a complete, CRC-good request, or 0."""
        n = len(p)
        if cmd == CMD_INFO:
            return 0 if n == 0 else ERR_LEN
        if cmd == CMD_READ:
            return 0 if n == 3 and p[2] != 0 else ERR_LEN
        if cmd == CMD_WRITE:
            return 0 if n >= 6 and n % 4 == 2 else ERR_LEN
        if cmd == CMD_BLKREAD:
            c = (p[2] << 8) | p[3] if n == 4 else 0
            return 0 if n == 4 and 1 <= c <= MAX_BLKREAD else ERR_LEN
        if cmd == CMD_STREAM:
            return 0 if n == 1 else ERR_LEN
        return ERR_CMD

    def burst(self, data: bytes) -> list[bytes]:
        out: list[bytes] = []
        i, n = 0, len(data)
        junk = False
        while i < n:
            b = data[i]
            i += 1
            if b != SYNC:
                junk = True
                continue
            if junk:                          # junk directly before a frame: counted only
                self.err_count = min(self.err_count + 1, 0xFFFF)
                self.err_last = ERR_JUNK
                junk = False
            seq = cmd = 0
            hdr = data[i:i + 4]
            if len(hdr) < 4:                  # truncated inside the header
                if len(hdr) >= 3:
                    seq = hdr[2]
                self._err(out, seq, ERR_TIMEOUT, 0)
                return out
            ln = (hdr[0] << 8) | hdr[1]
            seq, cmd = hdr[2], hdr[3]
            i += 4
            if ln > self.payload_max:
                self._err(out, seq, ERR_LEN, cmd)
                return out                    # the rest of the burst is discarded
            if n - i < ln + 2:
                self._err(out, seq, ERR_TIMEOUT, cmd)
                return out
            payload = bytes(data[i:i + ln])
            crc = (data[i + ln] << 8) | data[i + ln + 1]
            i += ln + 2
            if crc16(bytes(hdr) + payload) != crc:
                self._err(out, seq, ERR_CRC, cmd)
                continue
            code = self._check(cmd, payload)
            if code:
                self._err(out, seq, code, cmd)
                continue
            out.append(reply(seq, cmd, self.execute(seq, cmd, payload)))
        if junk:
            self._err(out, 0, ERR_JUNK, 0)
        return out
