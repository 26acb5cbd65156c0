"""fmtctl tuio: the pure mapping (fmt.host.events reports -> fmt.host.tuio messages) and
an end-to-end run on loopback: fmtctl reads a known event stream (the bit-exact model's
events of tb/fmt_fmtctl/known_scene.py, sent as event frames by FakeCore over
socket://, the board's code path) and a python-osc server in the test receives, per
report, the contacts with the model's IDs and normalised positions (TUIO 1.1 and 2.0).
No simulator."""
from __future__ import annotations

import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from fmt.settings import TouchSettings
from fmt import params
from fmt.host import events as E
from fmt.host import tuio

HERE = Path(__file__).parent
ROOT = HERE.parents[1]
FMTCTL = ROOT / "scripts" / "fmtctl"
sys.path.insert(0, str(HERE))

from fake_core import FakeCore  # noqa: E402
import known_scene  # noqa: E402


def rec(frame, id_, typ, x, y, last=False, **kw):
    r = {"frame": frame, "time": 0, "id": id_, "type": typ, "last": last, "x_q": x, "y_q": y,
         "strength": 5000, "axis_major_q": 256, "axis_minor_q": 128, "angle": 64, "flags": 0}
    r.update(kw)
    return r


# ---- pure functions ---------------------------------------------------------------------
def test_payload_round_trip():
    r = rec(7, 3, "move", 0x1234, 0x0567, last=True, strength=123456, angle=200, flags=1, time=99)
    assert E.from_payload(E.to_payload(r)) == r


def test_reports_and_contacts():
    stream = [rec(1, 5, "new", 256, 512), rec(1, 6, "new", 0, 0, last=True),
              rec(2, 5, "move", 300, 512), rec(2, 0xFF, "blob", 2560, 2560, last=True),
              rec(3, 6, "lift", 0, 0, last=True),
              rec(9, 7, "new", 10, 10)]                 # a frame cut short (no last)
    reps = E.group(stream)
    assert [[r["frame"] for r in rep] for rep in reps] == [[1, 1], [2, 2], [3], [9]]
    c = E.Contacts(hold_frames=4)
    u1, u2, u3, u4 = (c.update(r) for r in reps)
    assert list(u1.alive) == [5, 6] and u1.added == [5, 6]
    assert list(u2.alive) == [5, 6, E.BLOB_KEY] and u2.alive[E.BLOB_KEY].palm
    assert u2.alive[6].frame == 1                         # absent, kept (hold-off)
    assert list(u3.alive) == [5] and sorted(u3.removed) == [6, E.BLOB_KEY]
    assert list(u4.alive) == [7] and u4.removed == [5]     # frame 9: 5 not seen for 7 > 4 frames


def test_tuio_messages_1_1_and_2_0():
    s = E.Sensor(rows=30, cols=40)
    c = E.Contacts()
    u = c.update([rec(10, 4, "new", 0, 29 * 256, strength=1 << 15),
                  rec(10, 2, "move", 39 * 256 + 128, 14 * 256 + 128),
                  rec(10, 0xFF, "blob", 20 * 256, 10 * 256, last=True)])
    m = tuio.messages(u, s, "1.1", source="fmt@h")
    assert m[0] == ("/tuio/2Dcur", ["source", "fmt@h"])
    assert m[1] == ("/tuio/2Dcur", ["alive", 2, 4])
    assert m[2][1][:2] == ["set", 2] and m[2][1][2:4] == pytest.approx([1.0, 15 / 30])   # clipped at 1
    assert m[3][1][0:2] == ["set", 4] and m[3][1][2:4] == pytest.approx([0.5 / 40, 29.5 / 30])
    assert m[4] == ("/tuio/2Dcur", ["fseq", 10])
    assert [a for a, _ in m[5:]] == ["/tuio/2Dblb"] * 3
    assert m[5][1] == ["alive", E.BLOB_KEY] and m[6][1][1] == E.BLOB_KEY
    assert m[6][1][2:4] == pytest.approx([20.5 / 40, 10.5 / 30])
    m2 = tuio.messages(u, s, "2.0", source="fmt@h")
    assert m2[0][0] == "/tuio2/frm" and m2[0][1][0] == 10 and m2[0][1][2] == (40 * 256) << 16 | 30 * 256
    ptr = [a for a in m2 if a[0] == "/tuio2/ptr"]
    assert [p[1][0] for p in ptr] == [2, 4]
    assert ptr[1][1][3:5] == pytest.approx([0.5 / 40, 29.5 / 30]) and ptr[1][1][8] == pytest.approx(0.5)
    assert ptr[0][1][5] == pytest.approx(64 * 3.141592653589793 / 256)        # angle, rad
    assert [a[0] for a in m2[-2:]] == ["/tuio2/bnd", "/tuio2/alv"]
    assert m2[-1][1] == [2, 4, E.BLOB_KEY]
    with pytest.raises(ValueError):
        tuio.messages(u, s, "3.0")


def test_frm_time_tag_parses():
    from pythonosc.osc_message import OscMessage
    msg = tuio._osc_message("/tuio2/frm", [12, None, 77, "fmt:core@h"], 1.7e9 + 0.25)
    back = OscMessage(msg.dgram)
    assert back.params[0] == 12 and back.params[2] == 77 and back.params[3] == "fmt:core@h"
    assert b",itis" in msg.dgram
    dt, frac = back.params[1]                  # (whole seconds, 32-bit fraction)
    from datetime import timezone
    assert abs(dt.replace(tzinfo=timezone.utc).timestamp() + frac / 2 ** 32 - (1.7e9 + 0.25)) < 1e-6


# ---- end to end on loopback -------------------------------------------------------------
class Receiver:
    """A python-osc UDP server on a free loopback port; every message in arrival order."""

    def __init__(self):
        from pythonosc.dispatcher import Dispatcher
        from pythonosc.osc_server import ThreadingOSCUDPServer
        self.msgs = []
        d = Dispatcher()
        d.set_default_handler(lambda addr, *args: self.msgs.append((addr, list(args))))
        self.srv = ThreadingOSCUDPServer(("127.0.0.1", 0), d)
        self.port = self.srv.server_address[1]
        threading.Thread(target=self.srv.serve_forever, daemon=True).start()

    def close(self):
        self.srv.shutdown()
        self.srv.server_close()


def run_fmtctl(*args, timeout=120):
    return subprocess.run([sys.executable, str(FMTCTL), *args], capture_output=True, text=True,
                          timeout=timeout)


@pytest.fixture(scope="module")
def scene():
    cfg = params.DEFAULT
    hm = known_scene.heatmaps(cfg)
    return cfg, known_scene.records(hm, cfg)


def expected_per_frame(records, cfg):
    """frame -> {id: (x, y)} of the model's new/move events (hold-frames 0)."""
    s = E.Sensor(cfg.rows, cfg.cols)
    out = {}
    for r in records:
        d = out.setdefault(r["frame"], {})
        if r["type"] in ("new", "move"):
            d[r["id"]] = s.norm(r["x_q"], r["y_q"])
    return out


@pytest.mark.parametrize("version", ["1.1", "2.0"])
def test_tuio_end_to_end(scene, version):
    cfg, records = scene
    n_reports = len(E.group(records))
    core = FakeCore(cfg, records=records, pace_s=0.001)
    rx = Receiver()
    try:
        r = run_fmtctl("--port", core.url, "tuio", "--port", str(rx.port), "--version", version,
                       "--count", str(n_reports), "--hold-frames", "0")
        time.sleep(0.3)                       # the last datagrams
    finally:
        rx.close()
        core.close()
    assert r.returncode == 0 and "Traceback" not in r.stderr, r.stderr
    assert f"{n_reports} bundles" in r.stdout
    exp = expected_per_frame(records, cfg)
    got = {}
    if version == "1.1":
        cur = {}
        for addr, args in rx.msgs:
            if addr != "/tuio/2Dcur":
                continue
            if args[0] == "alive":
                alive = args[1:]
                cur = {}
            elif args[0] == "set":
                cur[args[1]] = tuple(args[2:4])
            elif args[0] == "fseq":
                assert sorted(cur) == sorted(alive)
                got[args[1]] = cur
    else:
        cur, frame = {}, None
        for addr, args in rx.msgs:
            if addr == "/tuio2/frm":
                frame, cur = args[0], {}
            elif addr == "/tuio2/ptr":
                cur[args[0]] = tuple(args[3:5])
            elif addr == "/tuio2/alv":
                assert sorted(args) == sorted(cur)
                got[frame] = cur
    assert sorted(got) == sorted(exp), (sorted(got), sorted(exp))
    for f, d in exp.items():
        assert sorted(got[f]) == sorted(d), f
        for i, (x, y) in d.items():
            assert got[f][i] == pytest.approx((x, y), abs=1e-6), (f, i)   # OSC float32
    k = TouchSettings().confirm_frames - 1           # new contacts reported k frames later
    assert len(exp[k]) == 2 and len(exp[6 + k]) == 3 and len(exp[16]) == 2     # the scene happened


def test_tuio_missing_package_and_port():
    code = ("import sys; sys.modules['pythonosc'] = None; from fmt.host.cli import main; "
            "sys.exit(main(['--port', 'socket://127.0.0.1:1', 'tuio']))")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert "python-osc" in r.stderr and "Traceback" not in r.stderr
    r = run_fmtctl("--port", "socket://127.0.0.1:1", "tuio")
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1 and "refused" in r.stderr.lower()
