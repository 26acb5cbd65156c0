"""scripts/fmtctl against the running full-core simulation (issue #5): the C++ Verilator
harness of ``make sim`` in serve mode (``python -m bench.core.run_sim_rtl --serve PORT``,
bench/core/sim_main.cpp) bridges socket://127.0.0.1:PORT to the UART of fmt_core inside
bench/core/fmt_core_sim_top.v, so that the same fmtctl drives the simulation and the
board.  Small sensor (4 x 6, N = 64), sim/scenes/small.json (a still finger and a
drag: events every frame), 12 scene frames, CLK_PER_SAMPLE 3, UART_DIV 4, the -O0
build of the harness test (own tag: pytest-xdist may run both at once).

Each run is one subprocess in its own session, driven like a user does it: wait for the
line "serving the RTL UART on socket://127.0.0.1:<port>", run fmtctl (its default
socket timeout), end the serving; the scene's frames are compared with the fixed-point
model as in ``make sim`` (exit 0 only with no golden mismatch, no frame dropped).
The checks use the logs (hm.log / ev.log / fe.log of the loggers, serve.log of the
bridge: every UART byte with its cycle, so every register value read is pinned to the
cycles [request received, reply sent]):

A. small.json with both contacts lifting before frame 10 (no event after the tracker's
   hold-off, ~130 frames: the latency counters then hold still), fmtctl info, get
   FRAME_COUNT (twice or more, until frame 400), latency, heatmap --out x.npy, then
   Ctrl-C (SIGINT to the process group: a clean end, exit 0):
   * INFO: version 1.0 and the sensor's sizes; every request got its reply (no error
     frame, no byte outside a valid frame on either side, no UART framing error);
   * FRAME_COUNT: > 0, increasing, and between the frame ends logged at the two ends
     of its transaction;
   * latency: the counters of the READ reply (and fmtctl's printout) EQUAL the
     per-frame latencies computed from ev.log / fe.log (count, min, max, last);
   * heat map: the .npy equals bit for bit the logged heat map of the frame that
     SNAP_STATUS names, and that frame ended after the SNAP_REQ write.
B. small.json (a finger stays: events every frame), ``--serve-once``: fmtctl touches
   --count 5; each streamed event equals the logged event of the same frame and ID
   (every field, time stamp included), and every frame but the last streamed one comes
   whole (all its logged events, in order: the report FIFO); serving ends when the
   client disconnects.
C. ``--serve-seconds 1`` and no client: serving ends by itself; with
   ``--serve-log-frames 5`` the loggers stop after about 5 frames of serving.
Verilator only (a C++ Verilator harness).
"""
from __future__ import annotations

import json
import re
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from bench.core import run_sim_rtl as rsr
from bench.core.serve_proc import ServeProc
from fmt import params
from fmt import protocol as P
from fmt import regmap

ROOT = rsr.ROOT

FMTCTL = ROOT / "scripts" / "fmtctl"
SCENE = ROOT / "sim" / "scenes" / "small.json"
TAG = "tb_serve"
CPS = 3
FRAMES = 12
QUIET_FRAME = 400   # run A: no event after this frame (the lifts' hold-off ends near 140)
SLACK = 16          # clk: register pipeline between an event leaving and its counters


class Server(ServeProc):
    """python -m bench.core.run_sim_rtl --serve 0 at the small sensor (the test's -O0 build
    and tag) in its own session; ``extra`` arguments after the defaults."""

    def __init__(self, out_dir: Path, *extra: str):
        super().__init__(out_dir, [
            "--scene", str(SCENE), "--frames", str(FRAMES), "--cps", str(CPS), "--serve", "0",
            "--serve-log-frames", "-1", "--no-plot", "--quiet", "--cflags=-O0", "--tag", TAG,
            "--out", str(out_dir), *extra])

    def wait_serving(self, wall_s: float = 240.0) -> str:
        """socket://127.0.0.1:PORT"""
        return super().wait_serving(wall_s).group(1)


def fmtctl(port: str, *args: str) -> str:
    r = subprocess.run([sys.executable, str(FMTCTL), "--port", port, *args], capture_output=True,
                       text=True, timeout=90)
    assert r.returncode == 0 and "Traceback" not in r.stderr, (args, r.stdout, r.stderr)
    return r.stdout


def frame_count(text: str) -> int:
    m = re.match(r"FRAME_COUNT = (\d+) \(0x[0-9A-F]+\)$", text.strip())
    assert m, text
    return int(m.group(1))


# ---- logs --------------------------------------------------------------------------------
def uart_frames(log: Path):
    """serve.log -> (host frames, core frames, bad bytes): lists of (cycle of the last
    byte, Frame) in order, each side parsed byte by byte with the host parser."""
    sides = {"H": (P.Parser(), []), "D": (P.Parser(), [])}
    for line in log.read_text().splitlines():
        p = line.split()
        if p[0] in sides:
            parser, out = sides[p[0]]
            for fr in parser.feed(bytes([int(p[2])])):
                out.append((int(p[1]), fr))
    return sides["H"][1], sides["D"][1], sides["H"][0].dropped + sides["D"][0].dropped


def transactions(host, core):
    """[(request cycle, request, reply cycle, reply)], replies matched by SEQ and CMD."""
    out = []
    for t1, rq in host:
        rep = next(((t2, fr) for t2, fr in core
                    if t2 > t1 and fr.seq == rq.seq and fr.cmd in (rq.cmd | 0x80, P.CMD_ERROR)), None)
        assert rep is not None, f"no reply to {rq} (cycle {t1})"
        assert rep[1].cmd == rq.cmd | 0x80, f"error reply {rep[1]} to {rq}"
        out.append((t1, rq, rep[0], rep[1]))
    return out


def reads_of(trans, name: str, count: int = 1):
    addr = regmap.BY_NAME[name].addr
    return [(t1, t2, P.payload_words(rp.payload)) for t1, rq, t2, rp in trans
            if rq.cmd == P.CMD_READ and rq.payload == bytes([addr >> 8, addr & 0xFF, count])]


def latency_stats(evs, fend, upto: int) -> dict:
    """The latency counters as the logs give them for the events up to cycle ``upto``."""
    first, last = {}, {}
    for e in evs:
        if e["cycle"] > upto or e["frame"] not in fend:
            continue
        f = e["frame"]
        first.setdefault(f, e["cycle"] - fend[f])
        if e["last"]:
            last[f] = e["cycle"] - fend[f]
    out = {}
    for key, d in (("FIRST", first), ("LAST", last)):
        v = [d[f] for f in sorted(d, key=lambda f: fend[f])]
        out[key] = {"COUNT": len(v), "MIN": min(v) if v else None, "MAX": max(v) if v else None,
                    "LAST": v[-1] if v else None}
    return out


def lift_scene(path: Path) -> Path:
    """small.json with both contacts lifting inside windows before frame 10: the core
    keeps making frames while serving, but no events (the latency counters hold still)."""
    sc = json.loads(SCENE.read_text())
    n_s = 64 / params.SMALL.fs_hz                     # one frame (N samples, M = 1)
    fs = params.SMALL.fs_hz
    sc["name"] = "small_lift"
    sc["contacts"][0]["active"] = [[0.0, 6 * n_s + 10 / fs]]
    sc["contacts"][1]["active"] = [[5 * n_s + 17 / fs, 8 * n_s + 30 / fs]]
    path.write_text(json.dumps(sc))
    return path


@pytest.mark.verilator_only
def test_fmt_core_serve(sim, tmp_path):
    assert sim == "verilator"
    cfg = params.SMALL
    d = rsr.job_dir(cfg, CPS, TAG)

    # ---- run A: a scene whose contacts lift; info, FRAME_COUNT, latency, heat map; Ctrl-C
    srv = Server(tmp_path, "--scene", str(lift_scene(tmp_path / "small_lift.json")), "--serve-seconds", "150")
    try:
        port = srv.wait_serving()
        outs = {}
        outs["info"] = fmtctl(port, "info")
        # FRAME_COUNT until the lift events are surely out (hold-off ~130 frames after the
        # lifts near frame 9): then the latency counters hold still
        outs["fc"] = []
        t0 = time.monotonic()
        while len(outs["fc"]) < 2 or frame_count(outs["fc"][-1]) < QUIET_FRAME:
            assert time.monotonic() - t0 < 90, outs["fc"]
            outs["fc"].append(fmtctl(port, "get", "FRAME_COUNT"))
        outs["latency"] = fmtctl(port, "latency")
        npy = tmp_path / "hm.npy"
        outs["heatmap"] = fmtctl(port, "heatmap", "--out", str(npy))
        srv.interrupt()
        rc, text = srv.finish()
    finally:
        srv.kill()
    assert rc == 0, text
    assert "golden mismatches 0" in text and "end: signal" in text, text
    rep = json.loads((tmp_path / "small_lift" / "report.json").read_text())
    assert rep["golden_mismatches"] == 0 and rep["frames_dropped"] == 0 and rep["frames"] >= FRAMES, rep
    assert rep["serve"]["clients"] == 3 + len(outs["fc"]) and rep["serve"]["framing_errors"] == 0, rep["serve"]

    # INFO
    info = dict(line.split(": ", 1) for line in outs["info"].strip().splitlines())
    assert info["version"] == "1.0", info
    assert (int(info["rows"]), int(info["cols"]), int(info["n_fft"]), int(info["hm_width"]),
            int(info["bin_lo"])) == (cfg.rows, cfg.cols, cfg.n_fft, cfg.hm_width, cfg.bin_lo), info
    assert info["regmap_id"] == info["host_regmap_id"], info   # rtl/fmt_regmap.vh is current

    host, core, bad = uart_frames(d / "serve.log")
    assert bad == 0, f"{bad} bytes outside valid frames on the UART"
    trans = transactions(host, core)
    assert [rq.cmd for _t, rq, _t2, _r in trans][:1] == [P.CMD_INFO]
    hm_rows, eof, evs, fend = rsr.parse_logs(d, cfg)
    eof_cycles = np.array([c for c, _f in eof])
    fend_cycles = np.array(sorted(fend.values()))
    types = {e["type"] for e in evs}
    assert {"new", "lift"} <= types, types
    # (the lift events come after the tracker's hold-off, ~130 frames: early while serving)

    # FRAME_COUNT: > 0, increasing, between the frame ends logged around the transaction
    fc = [frame_count(x) for x in outs["fc"]]
    assert 0 < fc[0] and all(a < b for a, b in zip(fc, fc[1:])), fc
    rd = reads_of(trans, "FRAME_COUNT")
    assert [w[0] for _a, _b, w in rd][:len(fc)] == fc, (rd, fc)     # (the last one: fmtctl latency)
    for t1, t2, (v,) in rd:
        lo = min(np.count_nonzero(eof_cycles <= t1 - SLACK), np.count_nonzero(fend_cycles <= t1 - SLACK))
        hi = max(np.count_nonzero(eof_cycles <= t2), np.count_nonzero(fend_cycles <= t2))
        assert lo <= v <= hi, (v, lo, hi, t1, t2)

    # latency counters (the READ of LAT_FIRST_LAST .. LAT_TRIG_ARMED): no event while
    # serving, so they must equal the values computed from the logs exactly
    got, lo, hi = check_latency(trans, evs, fend, outs["latency"])
    assert lo == hi and got == {k: lo[k] for k in got}, (got, lo, hi)

    # heat map: the snapshot named by SNAP_STATUS, bit for bit
    m = re.match(r"heat map \((\d+), (\d+)\) of frame (\d+) saved", outs["heatmap"])
    assert m, outs["heatmap"]
    fnum = int(m.group(3))
    hm = np.load(npy)
    assert hm.shape == (cfg.rows, cfg.cols)
    snap_req = regmap.BY_NAME["SNAP_REQ"].addr
    t_req = max(t for t, rq, _t2, _r in trans
                if rq.cmd == P.CMD_WRITE and rq.payload[:2] == bytes([snap_req >> 8, snap_req & 0xFF]))
    rows = hm_rows.get(fnum & 0xFFFF)
    assert rows is not None and len(rows) == cfg.rows, f"frame {fnum} not logged"
    logged = np.array([rows[r][1] for r in range(cfg.rows)], dtype=np.int64)
    assert np.array_equal(hm, logged), (hm, logged)
    end_cycle = [c for c, f in eof if f == fnum][-1]
    assert end_cycle > t_req, "the snapshot is a frame that ended after SNAP_REQ"
    summary = {"serve": rep["serve"], "frame_count": fc, "latency": got, "snapshot_frame": fnum}

    # ---- run B: small.json (a finger stays: events every frame), --serve-once: touches
    srv = Server(tmp_path, "--serve-once", "--serve-seconds", "120")
    try:
        port = srv.wait_serving()
        out = fmtctl(port, "touches", "--count", "5", "--event-timeout", "30")
        rc, text = srv.finish()
    finally:
        srv.kill()
    assert rc == 0 and "end: client" in text and "golden mismatches 0" in text, text
    _hm, _eof, evs, _fend = rsr.parse_logs(d, cfg)
    streamed = [json.loads(x) for x in out.strip().splitlines()]
    assert len(streamed) == 5
    by_key = {(e["frame"], e["id"]): e for e in evs}
    for s in streamed:
        e = by_key.get((s["frame"], s["id"]))
        assert e is not None, f"streamed event {s} not in ev.log"
        exp = {"time": e["time"], "type": e["type"], "last": bool(e["last"]), "x": e["x_q"] / 256.0,
               "y": e["y_q"] / 256.0, "strength": e["strength"], "axis_major": e["axis_major_q"] / 256.0,
               "axis_minor": e["axis_minor_q"] / 256.0, "flags": e["flags"]}
        assert {k: s[k] for k in exp} == exp, (s, e)
        assert round(s["angle_rad"] * 256 / np.pi) == e["angle"], (s, e)
    assert [s["frame"] for s in streamed] == sorted(s["frame"] for s in streamed)
    # whole reports (fmt_report_fifo): every frame before the last one streamed arrives
    # with all its logged events, in the port's order, and its last one flagged
    frames = sorted({s["frame"] for s in streamed})
    assert len(frames) >= 2, frames
    for f in frames[:-1]:
        got_f = [(s["id"], s["last"]) for s in streamed if s["frame"] == f]
        exp_f = [(e["id"], bool(e["last"])) for e in evs if e["frame"] == f]
        assert got_f == exp_f, (f, got_f, exp_f)
    summary["events"] = [(s["frame"], s["id"]) for s in streamed]

    # ---- run C: the wall-clock limit ends serving with no client at all; the loggers
    # stop after 5 frames of serving
    srv = Server(tmp_path, "--serve-seconds", "1", "--serve-log-frames", "5")
    try:
        srv.wait_serving()
        rc, text = srv.finish()
    finally:
        srv.kill()
    assert rc == 0 and "end: seconds" in text and "0 clients" in text and "golden mismatches 0" in text, text
    start = json.loads((tmp_path / "small" / "report.json").read_text())["serve"]["start_cycle"]
    _hm, eof, _evs, _fend = rsr.parse_logs(d, cfg)
    n_after = sum(1 for c, _f in eof if c >= start)
    assert 4 <= n_after <= 7, f"{n_after} frames logged while serving, the loggers were to stop after 5"
    print(json.dumps(summary))


def check_latency(trans, evs, fend, text: str):
    """The latency READ reply and fmtctl's printout of it; the counters inside the
    bounds the logs give at both ends of the transaction.  Returns (read, lo, hi)."""
    base = regmap.BY_NAME["LAT_FIRST_LAST"].addr
    n = regmap.BY_NAME["LAT_TRIG_ARMED"].addr - base + 1
    (t1, t2, w), = reads_of(trans, "LAT_FIRST_LAST", n)
    got = {k: {f: w[regmap.BY_NAME[f"LAT_{k}_{f}"].addr - base] for f in ("LAST", "MIN", "MAX", "COUNT")}
           for k in ("FIRST", "LAST")}
    for k, what in (("FIRST", "first event"), ("LAST", "last event ")):
        g = got[k]
        assert re.search(rf"{what}\s+last {g['LAST']} min {g['MIN']} max {g['MAX']} count {g['COUNT']} ",
                         text), (g, text)
    lo, hi = latency_stats(evs, fend, t1 - SLACK), latency_stats(evs, fend, t2)
    for k in ("FIRST", "LAST"):
        g, a, b = got[k], lo[k], hi[k]
        assert 0 < a["COUNT"] <= g["COUNT"] <= b["COUNT"], (k, g, a, b)
        assert b["MIN"] <= g["MIN"] <= g["MAX"] and a["MAX"] <= g["MAX"] <= b["MAX"], (k, g, a, b)
        assert g["MIN"] <= a["MIN"], (k, g, a)
    return got, lo, hi
