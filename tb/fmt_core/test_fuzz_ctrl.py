"""Control-port fuzzing through the RTL (issue #15 item 2): scripts/fuzz_ctrl.py with
10^5 bytes against the small fmt_core in the C++ Verilator harness (serve mode); the
full 10^6 bytes are ``make fuzz``.  Every reply is checked byte for byte against the
protocol model and the register shadow, each reply's end in clk against the port's
timing model (serve.log), and the scene's frames against the fixed-point model.  Its own
build tag and -O1 (the build is most of this test's time; -O1 runs as fast here).

test_checker_catches: the reply checker itself, without a simulation: a reply with a
wrong error code, a missing ACK, a wrong register value, a wrong bit in an unchecked
word (must pass) and a bad CRC."""
from __future__ import annotations

import json
import struct
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

import fuzz_ctrl as F                       # noqa: E402
from fmt import protocol as P               # noqa: E402

BYTES = 100_000
SEED = 15


@pytest.mark.verilator_only
@pytest.mark.long_only       # also `make fuzz`; the port's own cocotb and formal checks run in make test
def test_fuzz_ctrl(sim, tmp_path):
    assert sim == "verilator"
    r = subprocess.run([sys.executable, str(ROOT / "scripts" / "fuzz_ctrl.py"), "--bytes", str(BYTES),
                        "--seed", str(SEED), "--tag", "tb_fuzz", "--cflags=-O1", "--out", str(tmp_path),
                        "--json"], capture_output=True, text=True, timeout=900, cwd=ROOT)
    assert r.returncode == 0, r.stdout + r.stderr
    st = json.loads(r.stdout.strip().splitlines()[-1])
    print(json.dumps(st))
    assert st["bytes"] >= BYTES and st["seed"] == SEED
    assert st["ctrl_errors"] == min(st["initial"]["ctrl_errors"] + st["errors"], 0xFFFF)
    assert st["error_replies"] > 500 and st["frames_valid"] > 1000 and st["overflow_bursts"] >= 1, st
    assert st["latest_vs_model_clk"] <= F.LATE_MAX and st["max_backlog_logged"] < F.FIFO_BYTES, st


class FakeLink:
    def __init__(self, data: bytes):
        self.buf = bytearray(data)

    def read(self, n, wall_s):
        out = bytes(self.buf[:n])
        del self.buf[:n]
        return out


def test_checker_catches():
    m = F.Model({a: 0 for a in F.RW_ADDRS}, 0, 0, False)
    scratch = F.regmap.BY_NAME["SCRATCH"].addr
    data = (P.req_write(1, scratch, [0x12345678]) + P.encode(2, P.CMD_READ, b"\x00")
            + P.req_read(3, scratch, 1) + P.req_read(4, F.regmap.BY_NAME["FRAME_COUNT"].addr, 1)
            + P.req_read(5, F.A_ERRORS, 1))
    replies = m.burst(data)
    b = F.Burst(data, replies, m.masks, [b"?"] * len(replies), m)
    good = b"".join(r for r, _m in b.expected)
    assert [r[4] for r in replies] == [0x83, 0xFF, 0x82, 0x82, 0x82]
    assert replies[1] == P.error_reply(2, P.ERR_LEN, P.CMD_READ)
    assert struct.unpack(">I", replies[2][5:9])[0] == 0x12345678
    assert struct.unpack(">I", replies[4][5:9])[0] == 1           # the LEN error counted
    F.check_replies(FakeLink(good), b.expected, 1, b.requests)    # as predicted: passes

    def fails(stream):
        with pytest.raises(F.Fail):
            F.check_replies(FakeLink(stream), b.expected, 1, b.requests)

    r = list(replies)
    fails(b"".join([r[0], P.error_reply(2, P.ERR_CRC, P.CMD_READ)] + r[2:]))     # wrong code
    fails(b"".join(r[1:]))                                                         # no ACK
    fails(b"".join(r[:2] + [P.reply(3, P.CMD_READ, struct.pack(">I", 0x12345679))] + r[3:]))
    fails(b"".join(r[:4] + [P.reply(5, P.CMD_READ, struct.pack(">I", 2))]))       # error count
    odd = P.reply(4, P.CMD_READ, struct.pack(">I", 0xDEADBEEF))                   # FRAME_COUNT: not
    F.check_replies(FakeLink(b"".join(r[:3] + [odd] + r[4:])), b.expected, 1, b.requests)   # predicted
    bad = bytearray(good)
    bad[-1] ^= 1                                                                   # bad CRC
    fails(bytes(bad))
