"""fmtctl uinput: the pure mapping (fmt.host.uinput.MTMapper: reports -> protocol-B input
events) everywhere; the uinput device itself where /dev/uinput is writable (skipped with
one line where not); a missing module, device or port is one line and exit 2."""
from __future__ import annotations

import os
import re
import subprocess
import sys
import time
from pathlib import Path

import pytest

from fmt.host import events as E
from fmt.host import uinput as U

HERE = Path(__file__).parent
FMTCTL = HERE.parents[1] / "scripts" / "fmtctl"
sys.path.insert(0, str(HERE))

S = E.Sensor(rows=30, cols=40, pitch_mm=5.0)


def rec(frame, id_, typ, x, y, last=False, **kw):
    r = {"frame": frame, "time": 0, "id": id_, "type": typ, "last": last, "x_q": x, "y_q": y,
         "strength": 5000, "axis_major_q": 300, "axis_minor_q": 200, "angle": 160, "flags": 0}
    r.update(kw)
    return r


def replay(mapper, evs):
    """Apply input events like the kernel's MT state: slot -> {code: value}; the
    single-touch state; SYN_REPORT count."""
    slots, st, slot, syn = {}, {}, 0, 0
    for t, c, v in evs:
        if t == U.EV_ABS and c == U.ABS_MT_SLOT:
            slot = v
        elif t == U.EV_ABS and c == U.ABS_MT_TRACKING_ID:
            if v < 0:
                slots.pop(slot, None)
            else:
                slots[slot] = {c: v}
        elif t == U.EV_ABS and c >= U.ABS_MT_TOUCH_MAJOR:
            slots[slot][c] = v
        elif t == U.EV_SYN:
            syn += 1
        else:
            st[(t, c)] = v
    return slots, st, syn


def test_codes_match_the_kernel_header_and_evdev():
    hdrs = [Path("/usr/include/linux/input-event-codes.h"), Path("/usr/include/linux/input.h")]
    names = [n for n in dir(U) if re.match(r"^(EV|SYN|BTN|ABS|MT_TOOL|INPUT_PROP)_", n)]
    if all(h.exists() for h in hdrs):
        defs = dict(re.findall(r"#define\s+(\w+)\s+(0x[0-9a-fA-F]+|\d+)\b",
                               "".join(h.read_text() for h in hdrs)))
        for n in names:
            assert int(defs[n], 0) == getattr(U, n), n
    try:
        from evdev import ecodes
    except ImportError:
        return
    for n in names:
        if hasattr(ecodes, n):                       # (evdev has no MT_TOOL_* names)
            assert getattr(ecodes, n) == getattr(U, n), n


def test_mapping_protocol_b():
    m = U.MTMapper(S, slots=2)
    c = E.Contacts(hold_frames=0)
    # frame 1: two fingers
    ev1 = m.frame(c.update([rec(1, 7, "new", 256, 512), rec(1, 3, "new", 39 * 256, 0, last=True,
                                                               strength=99999, angle=0)]))
    assert ev1[-1] == (U.EV_SYN, U.SYN_REPORT, 0)
    slots, st, _ = replay(m, ev1)
    # keys in ascending order get the lowest free slots: 3 -> slot 0, 7 -> slot 1
    assert slots[0][U.ABS_MT_TRACKING_ID] == 0 and slots[1][U.ABS_MT_TRACKING_ID] == 1
    assert slots[1][U.ABS_MT_POSITION_X] == 256 + 128 and slots[1][U.ABS_MT_POSITION_Y] == 512 + 128
    assert slots[0][U.ABS_MT_POSITION_X] == 39 * 256 + 128
    assert slots[0][U.ABS_MT_PRESSURE] == 65535 and slots[1][U.ABS_MT_PRESSURE] == 5000
    assert slots[1][U.ABS_MT_TOUCH_MAJOR] == 600 and slots[1][U.ABS_MT_TOUCH_MINOR] == 400
    assert slots[1][U.ABS_MT_ORIENTATION] == 32 and slots[0][U.ABS_MT_ORIENTATION] == -128
    assert slots[0][U.ABS_MT_TOOL_TYPE] == U.MT_TOOL_FINGER
    assert st[(U.EV_KEY, U.BTN_TOUCH)] == 1 and st[(U.EV_ABS, U.ABS_X)] == 39 * 256 + 128
    # frame 2: 7 moves (only X changes), 3 lifts, a palm arrives (slot 0 again, new tracking ID)
    ev2 = m.frame(c.update([rec(2, 7, "move", 300, 512), rec(2, 3, "lift", 0, 0),
                            rec(2, 0xFF, "blob", 2560, 2560, last=True)]))
    assert (U.EV_ABS, U.ABS_MT_POSITION_Y, 640) not in ev2         # unchanged: not sent
    assert ev2[:2] == [(U.EV_ABS, U.ABS_MT_SLOT, 0), (U.EV_ABS, U.ABS_MT_TRACKING_ID, -1)]
    slots2, st2, _ = replay(m, ev1 + ev2)
    assert slots2[1][U.ABS_MT_POSITION_X] == 300 + 128 and slots2[1][U.ABS_MT_POSITION_Y] == 640
    assert slots2[0][U.ABS_MT_TOOL_TYPE] == U.MT_TOOL_PALM and slots2[0][U.ABS_MT_TRACKING_ID] == 2
    assert st2[(U.EV_ABS, U.ABS_X)] == 300 + 128                     # the finger, not the palm
    # frame 3: a third finger while both slots are taken is left out; frame 4: all gone
    ev3 = m.frame(c.update([rec(3, 7, "move", 300, 512), rec(3, 9, "new", 0, 0),
                            rec(3, 0xFF, "blob", 2560, 2560, last=True)]))
    assert (U.EV_ABS, U.ABS_MT_TRACKING_ID, 3) not in ev3
    ev4 = m.frame(c.update([rec(4, 7, "lift", 0, 0, last=True)]))
    slots4, st4, syn = replay(m, ev1 + ev2 + ev3 + ev4)
    assert slots4 == {} and st4[(U.EV_KEY, U.BTN_TOUCH)] == 0 and syn == 4
    info = m.absinfo()
    assert info[U.ABS_MT_POSITION_X] == (0, 40 * 256 - 1, 51) and info[U.ABS_MT_SLOT] == (0, 1, 0)


def test_uinput_device():
    if not (os.path.exists("/dev/uinput") and os.access("/dev/uinput", os.W_OK)):
        pytest.skip("/dev/uinput is not writable here: the uinput device test needs it")
    evdev = pytest.importorskip("evdev", reason="evdev is not installed")
    m = U.MTMapper(S)
    dev = U.Device(m, name="fmt-test-touch")
    try:
        inp = evdev.InputDevice(dev.path)
        caps = inp.capabilities()
        assert U.ABS_MT_SLOT in [c for c, _ in caps[U.EV_ABS]]
        assert U.INPUT_PROP_DIRECT in inp.input_props()
        c = E.Contacts()
        dev.send(c.update([rec(1, 4, "new", 1000, 2000, last=True)]))
        time.sleep(0.1)
        got = []
        while (e := inp.read_one()) is not None:
            got.append((e.type, e.code, e.value))
        assert (U.EV_ABS, U.ABS_MT_POSITION_X, 1128) in got and (U.EV_KEY, U.BTN_TOUCH, 1) in got
        inp.close()
    finally:
        dev.close()


def one_line(r):
    assert r.returncode == 2 and "Traceback" not in r.stderr, r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and r.stdout == "", (r.stdout, r.stderr)


def test_uinput_missing_module_device_port(tmp_path):
    code = ("import sys; sys.modules['evdev'] = None; from fmt.host.cli import main; "
            "sys.exit(main(['--port', 'socket://127.0.0.1:1', 'uinput']))")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    one_line(r)
    assert "evdev" in r.stderr
    r = subprocess.run([sys.executable, str(FMTCTL), "--port", "socket://127.0.0.1:1", "uinput",
                        "--devnode", str(tmp_path / "uinput")], capture_output=True, text=True, timeout=60)
    one_line(r)
    assert "does not exist" in r.stderr
    f = tmp_path / "ro"
    f.write_text("")
    f.chmod(0o444)
    if not os.access(f, os.W_OK):                 # (root may write anyway)
        r = subprocess.run([sys.executable, str(FMTCTL), "--port", "socket://127.0.0.1:1", "uinput",
                            "--devnode", str(f)], capture_output=True, text=True, timeout=60)
        one_line(r)
        assert "not writable" in r.stderr
