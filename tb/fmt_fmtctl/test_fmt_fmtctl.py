"""End-to-end test of scripts/fmtctl against the RTL control port.

The cocotb side serves the simulated UART of tb/fmt_ctrl_port/fmt_ctrl_tb_top.v
(fmt_ctrl_port + the generated fmt_regfile + dummy memories) on
socket://127.0.0.1:<free port>: a TCP server inside the cocotb process whose received
bytes are driven into the RTL's rxd at the UART bit rate and whose transmitted bytes
(decoded from txd) are sent back.  fmtctl runs in a subprocess: info, set/get, a
heat-map snapshot to .npy compared with the preloaded RAM, the latency report, and
touches (events offered by the test once fmtctl has turned the stream on), calibrate
(on the static RAM) and load-cal (a cell read back through the calibration windows).

Plain pytest tests (no simulator): fmtctl on an unreachable port, on a silent server
(timeout) and on a server answering with a corrupt CRC prints one line on stderr and
exits non-zero.
"""
from __future__ import annotations

import json
import os
import random
import re
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import cocotb
import numpy as np
import pytest
from cocotb.triggers import ClockCycles, ReadOnly, RisingEdge

from common.runner import long_run, run_cocotb, sources
from common.tb_util import ClockedTB, env_int, env_str
from fmt import params, protocol as P, regmap
from fmt_uart.uart_bfm import UartBfm

HERE = Path(__file__).parent
ROOT = HERE.parents[1]
FMTCTL = ROOT / "scripts" / "fmtctl"
TOP = ROOT / "tb" / "fmt_ctrl_port" / "fmt_ctrl_tb_top.v"


class Bridge:
    """TCP server on a free loopback port <-> the RTL UART pins."""

    def __init__(self, tb):
        self.tb = tb
        self.srv = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        self.srv.bind(("127.0.0.1", 0))
        self.srv.listen(4)
        self.srv.setblocking(False)
        self.port = self.srv.getsockname()[1]
        self.conn = None
        self.to_dut = bytearray()
        self.sender = None
        cocotb.start_soon(self.run())

    async def run(self):
        bfm = self.tb.bfm
        while True:
            await ClockCycles(self.tb.clk, 8)
            if self.conn is None:
                try:
                    self.conn, _ = self.srv.accept()
                    self.conn.setblocking(False)
                except BlockingIOError:
                    pass
            if self.conn is not None:
                try:
                    data = self.conn.recv(4096)
                    if data:
                        self.to_dut += data
                    else:                        # client closed
                        self.conn.close()
                        self.conn = None
                except BlockingIOError:
                    pass
            out = bytearray()
            while bfm.pending():
                out.append(bfm.rx_queue.get_nowait()[0])
            if out and self.conn is not None:
                self.conn.setblocking(True)
                self.conn.sendall(bytes(out))
                self.conn.setblocking(False)
            if self.to_dut and (self.sender is None or self.sender.done()):
                data = bytes(self.to_dut)
                self.to_dut.clear()
                self.sender = cocotb.start_soon(bfm.send(data))


class TB(ClockedTB):
    def __init__(self, dut):
        super().__init__(dut)
        self.cfg = params.get(env_str("CFG", "small"))
        self.div = env_int("DIV", 4)
        for n in ("mem_we_i", "mem_addr_i", "mem_wdata_i", "frame_count_i", "status_set_i",
                  "evs_valid_i", "evs_data_i"):
            getattr(dut, n).value = 0
        self.bfm = UartBfm(self.clk, dut.rxd_i, dut.txd_o, self.div, self.period_ns)
        self.python = env_str("HOST_PYTHON", "python3")

    async def fmtctl(self, *args, wall_s: float = 120.0):
        """Run fmtctl against the bridge while the simulation runs; (rc, stdout, stderr)."""
        proc = subprocess.Popen(
            [self.python, str(FMTCTL), "--port", f"socket://127.0.0.1:{self.bridge.port}",
             "--timeout", "60", *args],
            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        t0 = time.monotonic()
        while proc.poll() is None:
            await ClockCycles(self.clk, 100)
            if time.monotonic() - t0 > wall_s:
                proc.kill()
                raise AssertionError(f"fmtctl {args} did not finish in {wall_s} s")
        out, err = proc.communicate()
        return proc.returncode, out, err


@cocotb.test()
async def fmtctl_end_to_end(dut):
    tb = TB(dut)
    await tb.reset()
    tb.bridge = Bridge(tb)
    rng = random.Random(env_int("SEED", 1))
    rows, cols = tb.cfg.rows, tb.cfg.cols
    hm = np.array([rng.getrandbits(tb.cfg.hm_width) for _ in range(rows * cols)]).reshape(rows, cols)
    for a, v in enumerate(hm.ravel()):
        await tb.writable()
        dut.mem_we_i.value = 1
        dut.mem_addr_i.value = a
        dut.mem_wdata_i.value = int(v)
    await tb.writable()
    dut.mem_we_i.value = 0

    rc, out, err = await tb.fmtctl("info")
    assert rc == 0, err
    info = dict(line.split(": ", 1) for line in out.strip().splitlines())
    assert (info["rows"], info["cols"], info["n_fft"]) == (str(rows), str(cols), str(tb.cfg.n_fft))
    assert info["regmap_id"] == info["host_regmap_id"]

    rc, out, err = await tb.fmtctl("set", "SCRATCH", "0x1234abcd")
    assert rc == 0, err
    rc, out, err = await tb.fmtctl("get", "scratch")
    assert rc == 0 and out.strip() == "SCRATCH = 305441741 (0x1234ABCD)", (out, err)
    rc, out, err = await tb.fmtctl("set", "TOUCH_THRESHOLD", "1500")
    assert rc == 0, err
    rc, out, err = await tb.fmtctl("get", hex(regmap.BY_NAME["TOUCH_THRESHOLD"].addr))
    assert rc == 0 and out.strip() == "TOUCH_THRESHOLD = 1500 (0x5DC)", (out, err)
    rc, out, err = await tb.fmtctl("get", "CONTACT_LIMIT")    # reset value from params
    assert rc == 0 and out.strip().startswith(f"CONTACT_LIMIT = {params.DEFAULT.max_touches} "), out

    npy = Path(env_str("OUT_DIR", "/tmp")) / "hm.npy"
    rc, out, err = await tb.fmtctl("heatmap", "--out", str(npy))
    assert rc == 0, err
    got = np.load(npy)
    assert got.shape == (rows, cols) and np.array_equal(got, hm)

    rc, out, err = await tb.fmtctl("latency")
    assert rc == 0, err
    assert re.search(r"first event\s+last 101 min 100 max 140 count 4242", out), out
    assert re.search(r"trigger -> new contact\s+last 301 min 300 max 340 count 7", out), out

    # calibration: a static heat map gives offsets = the map and unit gains (no signal)
    calf = Path(env_str("OUT_DIR", "/tmp")) / "cal.json"
    rc, out, err = await tb.fmtctl("calibrate", "--out", str(calf), "--frames", "1", "--yes")
    assert rc == 0, err
    cal = json.loads(calf.read_text())
    assert np.array_equal(np.array(cal["offset"]), hm) and set(np.ravel(cal["gain"])) == {16384}
    # load-cal of a random calibration, one cell read back through the windows
    cal["offset"] = [[rng.getrandbits(16) for _ in range(cols)] for _ in range(rows)]
    cal["gain"] = [[rng.getrandbits(16) for _ in range(cols)] for _ in range(rows)]
    calf.write_text(json.dumps(cal))
    rc, out, err = await tb.fmtctl("load-cal", str(calf))
    assert rc == 0 and out.strip() == f"loaded {rows * cols} cells", (out, err)
    r, c = rows - 1, cols - 2
    for args in (("set", "CAL_ROW", str(r)), ("set", "CAL_COL", str(c))):
        assert (await tb.fmtctl(*args))[0] == 0
    rc, out, err = await tb.fmtctl("get", "CAL_GAIN")
    assert out.strip().startswith(f"CAL_GAIN = {cal['gain'][r][c]} "), (out, err)

    # errors reported by fmtctl itself: one line, non-zero
    for args in (("set", "FRAME_COUNT", "5"), ("get", "NO_SUCH_REG"), ("set", "PN_RX_DELAY", "64")):
        rc, out, err = await tb.fmtctl(*args)
        assert rc != 0 and len(err.strip().splitlines()) == 1 and "Traceback" not in err, (args, err)

    # touches: once fmtctl has switched the stream on, offer two events
    events = [{"frame": 7 + i, "time": 1000 * i, "id": i + 1, "type": i, "last": i == 1,
               "x": 0x0180 + i, "y": 0x0240, "strength": 3000 + i, "axis_major": 384,
               "axis_minor": 256, "angle": 32, "flags": 0} for i in range(2)]
    async def offer():
        while int(dut.stream_en_o.value) == 0:
            await RisingEdge(tb.clk)
        for ev in events:
            await tb.writable()
            dut.evs_data_i.value = int.from_bytes(P.pack_event(ev), "big")
            dut.evs_valid_i.value = 1
            while True:
                await ReadOnly()
                rdy = int(dut.evs_ready_o.value)
                await RisingEdge(tb.clk)
                if rdy:
                    break
            await tb.writable()
            dut.evs_valid_i.value = 0
    cocotb.start_soon(offer())
    rc, out, err = await tb.fmtctl("touches", "--count", "2")
    assert rc == 0, err
    lines = [json.loads(x) for x in out.strip().splitlines()]
    assert [e["id"] for e in lines] == [1, 2]
    assert lines[0]["x"] == 1.5 and lines[1]["type"] == "move" and lines[1]["last"] is True
    await ClockCycles(tb.clk, 2000)
    assert int(dut.stream_en_o.value) == 0, "fmtctl turns the stream off when done"


def test_fmt_fmtctl(sim, tmp_path):
    if sim == "icarus" and not long_run():
        pytest.skip("make test: under Verilator (the control port itself runs under both in "
                    "tb/fmt_ctrl_port); Icarus in make test-long (FMT_LONG=1), for make test's time")
    cfg = params.SMALL
    vp = cfg.verilog_params()
    run_cocotb(
        sim=sim,
        toplevel="fmt_ctrl_tb_top",
        sources=sources("fmt_ctrl_port") + sources("fmt_regfile") + [TOP],
        test_module="test_fmt_fmtctl",
        test_dir=HERE,
        parameters={"DIV": 4, "TIMEOUT_BITS": 20, "PAYLOAD_MAX": 64, "REGMAP_ID": regmap.regmap_id(),
                    **{k: vp[k] for k in ("ROWS", "COLS", "LOG2_N", "HM_W", "BIN_LO", "BIN_STEP")}},
        extra_env={"CFG": cfg.name, "DIV": 4, "HOST_PYTHON": sys.executable, "OUT_DIR": tmp_path},
    )


# ---- fmtctl failure modes, no simulator ----------------------------------------------
def _run(*args, timeout=30):
    return subprocess.run([sys.executable, str(FMTCTL), *args], capture_output=True, text=True,
                          timeout=timeout)


def _one_line_failure(r):
    assert r.returncode != 0
    assert "Traceback" not in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert r.stdout == ""


def test_fmtctl_unreachable_port():
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()                                   # nobody listens there now
    r = _run("--port", f"socket://127.0.0.1:{port}", "info")
    _one_line_failure(r)
    assert "refused" in r.stderr.lower()


def _server(handler):
    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen(1)

    def serve():
        c, _ = srv.accept()
        with c:
            handler(c)
        srv.close()

    threading.Thread(target=serve, daemon=True).start()
    return srv.getsockname()[1]


def test_fmtctl_timeout():
    port = _server(lambda c: time.sleep(3))
    r = _run("--port", f"socket://127.0.0.1:{port}", "--timeout", "0.5", "get", "SCRATCH")
    _one_line_failure(r)
    assert "no valid reply" in r.stderr


def test_fmtctl_bad_crc():
    def handler(c):
        req = c.recv(64)
        rep = bytearray(P.reply(req[3], req[4], P.words_payload([5])))
        rep[-1] ^= 0xFF                          # corrupt CRC
        c.sendall(bytes(rep))
        time.sleep(2)
    port = _server(handler)
    r = _run("--port", f"socket://127.0.0.1:{port}", "--timeout", "0.5", "get", "SCRATCH")
    _one_line_failure(r)
    assert "bad CRC" in r.stderr


def test_fmtctl_device_error():
    def handler(c):
        req = c.recv(64)
        c.sendall(P.error_reply(req[3], P.ERR_CRC, req[4]))
        time.sleep(1)
    port = _server(handler)
    r = _run("--port", f"socket://127.0.0.1:{port}", "--timeout", "0.5", "get", "SCRATCH")
    _one_line_failure(r)
    assert "device error 1" in r.stderr
