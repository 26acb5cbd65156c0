"""Model tests of sim/fmt/protocol.py: CRC check value, frame round trips, the host
parser's resynchronisation, and the RTL-twin parser model on hand-made cases."""
from __future__ import annotations

import random

import pytest

from fmt import params, protocol as P


def test_crc_check_value():
    # CRC-16/CCITT-FALSE catalogue check value
    assert P.crc16(b"123456789") == 0x29B1
    assert P.crc16(b"") == 0xFFFF


def test_crc_bitwise_reference():
    """Table-driven CRC equals a plain bit-serial implementation (the RTL's loop)."""
    rng = random.Random(1)
    for _ in range(50):
        data = bytes(rng.randrange(256) for _ in range(rng.randrange(0, 40)))
        c = 0xFFFF
        for b in data:
            for i in range(7, -1, -1):
                fb = ((c >> 15) ^ (b >> i)) & 1
                c = ((c << 1) & 0xFFFF) ^ (0x1021 if fb else 0)
        assert P.crc16(data) == c


def test_round_trip():
    rng = random.Random(2)
    frames = []
    for i in range(40):
        payload = bytes(rng.randrange(256) for _ in range(rng.choice([0, 1, 5, 64, 300])))
        frames.append(P.Frame(seq=i & 0xFF, cmd=rng.randrange(256), payload=payload))
    data = b"".join(P.encode(f.seq, f.cmd, f.payload) for f in frames)
    assert P.decode(data) == frames


def test_frame_layout():
    f = P.req_read(7, 0x123, 2)
    assert f[:6] == bytes([0xA5, 0x00, 0x03, 0x07, P.CMD_READ, 0x01])
    assert f[6:8] == bytes([0x23, 0x02])
    assert int.from_bytes(f[-2:], "big") == P.crc16(f[1:-2])


def test_resync_after_garbage_and_corruption():
    rng = random.Random(3)
    good = [P.encode(i, P.CMD_INFO | 0x80, bytes(range(i))) for i in range(1, 6)]
    stream = b""
    for g in good:
        junk = bytes(rng.choice([0xA5, 0x00, 0xFF, rng.randrange(256)]) for _ in range(rng.randrange(0, 12)))
        bad = bytearray(g)
        bad[rng.randrange(1, len(bad))] ^= 0x10
        stream += junk + bytes(bad) + g
    # a junk SYNC with a plausible LEN holds the parser until LEN bytes are there, so the
    # host bounds LEN by the longest reply it expects (fmtctl does, per request)
    frames = P.Parser(max_len=16).feed(stream)
    assert [f.seq for f in frames] == [1, 2, 3, 4, 5]
    # byte-at-a-time feeding gives the same frames
    p = P.Parser(max_len=16)
    got = []
    for b in stream:
        got += p.feed(bytes([b]))
    assert got == frames


def test_info_roundtrip():
    cfg = params.SMALL
    info = P.decode_info(P.info_payload(cfg, 0xBEEF, 64))
    assert (info["rows"], info["cols"], info["n_fft"], info["regmap_id"]) == (4, 6, 64, 0xBEEF)
    with pytest.raises(P.ProtocolError):
        P.decode_info(b"\x00" * 16)


def test_event_pack_roundtrip():
    ev = {"frame": 513, "time": 0xDEADBEEF, "id": 3, "type": 1, "last": True, "x": 0x0280,
          "y": 0x0140, "strength": 4000, "axis_major": 0x0180, "axis_minor": 0x0100,
          "angle": 64, "flags": 5}
    p = P.pack_event(ev)
    assert len(p) == P.EVENT_BYTES
    u = P.unpack_event(p)
    assert (u["x"], u["y"], u["type"], u["last"], u["strength"]) == (2.5, 1.25, "move", True, 4000)


def _model():
    log = []

    def execute(seq, cmd, p):
        log.append((seq, cmd, p))
        return b"ok" if cmd == P.CMD_INFO else b""

    return P.CtrlPortModel(execute, 64), log


def test_ctrl_model_errors():
    m, log = _model()
    good = P.req_write(5, 2, [1])
    # junk alone: one error reply after the idle line
    assert m.burst(b"\x00\x01") == [P.error_reply(0, P.ERR_JUNK)]
    # junk straight before a frame: counted, no reply, the frame is served
    assert m.burst(b"\x00" + good) == [P.reply(5, P.CMD_WRITE)]
    assert (m.err_count, m.err_last) == (2, P.ERR_JUNK)
    # truncation after SEQ and after CMD
    assert m.burst(good[:4]) == [P.error_reply(5, P.ERR_TIMEOUT, 0)]
    assert m.burst(good[:6]) == [P.error_reply(5, P.ERR_TIMEOUT, P.CMD_WRITE)]
    bad = bytearray(good)
    bad[7] ^= 1
    assert m.burst(bytes(bad) + good) == [P.error_reply(5, P.ERR_CRC, P.CMD_WRITE), P.reply(5, P.CMD_WRITE)]
    assert m.burst(P.encode(9, 0x33)) == [P.error_reply(9, P.ERR_CMD, 0x33)]
    long = P.req_write(8, 0, list(range(20)))
    assert m.burst(long + good) == [P.error_reply(8, P.ERR_LEN, P.CMD_WRITE)]   # rest discarded
    assert len(log) == 2          # only the two good writes executed
    assert m.err_count == 7
