"""fmtctl -- host tool for the FMT control/monitor port (UART, pyserial).

    fmtctl --port /dev/ttyUSB0 [--baud 115200] info
    fmtctl --port socket://127.0.0.1:PORT get NAME
    fmtctl --port ... set NAME VALUE
    fmtctl --port ... heatmap --out hm.npy [--png hm.png] [--frames K]
    fmtctl --port ... touches [--count N]          (JSON lines on stdout)
    fmtctl --port ... latency                       (the latency counters as a report)
    fmtctl --port ... calibrate --out cal.json [--frames K] [--yes]
    fmtctl --port ... load-cal cal.json
    fmtctl regs                                     (the register map; no port needed)
    fmtctl --port ... tuio [--host H --port P] [--version 1.1|2.0]   (TUIO over OSC/UDP)
    fmtctl --port ... uinput [--devnode /dev/uinput]                 (Linux multitouch device)
    fmtctl --port ... view [--png-dir DIR]          (heat map + contacts; or --recording F.npz)
    fmtctl --port ... record --out F.npz [--snapshots K] [--events N] [--seconds S]

NAME is a register name of docs/REGISTERS.md (case-insensitive) or an address (0x...).
The simulation serves the core's UART on a socket (python -m bench.core.run_sim_rtl --serve
PORT): socket:// ports get a longer default reply timeout (10 s; the simulated UART runs
at a few kB/s or less, and the wire time computed from --baud does not apply there).
Protocol: docs/PROTOCOL.md; the host outputs and the recording format: docs/host.md.  Any failure (port unreachable, timeout, CRC error, device
error reply) prints ONE line on stderr and exits with status 2 (1 for usage errors).
"""
from __future__ import annotations

import argparse
import json
import struct
import sys
import time
from pathlib import Path

import numpy as np

from fmt import protocol as P
from fmt import regmap


class FmtError(Exception):
    """A failure reported as one line."""


class Device:
    """One control port.  Requests are serialised; every reply is matched by SEQ."""

    def __init__(self, port: str, baud: int, timeout: float):
        try:
            import serial  # pyserial
        except ImportError as e:
            raise FmtError("pyserial is not installed (pip install pyserial)") from e
        self.serial_mod = serial
        try:
            self.ser = serial.serial_for_url(port, baudrate=baud, timeout=0.02)
        except (serial.SerialException, OSError, ValueError) as e:
            raise FmtError(str(e) if port in str(e) else f"cannot open {port}: {e}") from None
        self.port = port
        self.baud = baud
        self.timeout = timeout
        self.seq = int(time.time() * 1000) & 0xFF
        self.parser = P.Parser()
        self.pending: list[P.Frame] = []
        self._info = None
        self.snap_frame = None      # frame number of the last heat-map snapshot (SNAP_STATUS)

    def close(self):
        try:
            self.ser.close()
        except Exception:
            pass

    # ---- transport ---------------------------------------------------------------
    def _read_frames(self, max_len: int, deadline: float) -> list[P.Frame]:
        self.parser.max_len = max_len
        while time.monotonic() < deadline:
            try:
                data = self.ser.read(4096)
            except (self.serial_mod.SerialException, OSError) as e:
                raise FmtError(f"{self.port}: read failed: {e}") from None
            if data:
                frames = self.parser.feed(data)
                if frames:
                    return frames
        return []

    def transact(self, cmd: int, payload: bytes = b"", reply_len: int = 0) -> bytes:
        self.seq = (self.seq + 1) & 0xFF
        seq = self.seq
        try:
            self.ser.write(P.encode(seq, cmd, payload))
            self.ser.flush()
        except (self.serial_mod.SerialException, OSError) as e:
            raise FmtError(f"{self.port}: write failed: {e}") from None
        # time on the wire at the baud rate plus the allowed latency
        wire = 10.0 * (len(payload) + reply_len + 16) / self.baud
        deadline = time.monotonic() + self.timeout + wire
        dropped0 = self.parser.dropped
        while True:
            # LEN bound: this reply, an error reply or an event frame (events may be on)
            frames = self._read_frames(max(reply_len, P.EVENT_BYTES), deadline)
            if not frames:
                bad = self.parser.dropped - dropped0
                why = f" ({bad} bytes with a bad CRC or framing discarded)" if bad else ""
                raise FmtError(f"no valid reply to {P.COMMANDS.get(cmd, hex(cmd))} from "
                               f"{self.port} within {self.timeout + wire:.1f} s{why}")
            answer = None
            for fr in frames:
                if fr.cmd == P.CMD_EVENT:
                    self.pending.append(fr)   # kept for events(), in order
                elif fr.seq == seq and answer is None:
                    answer = fr
                # anything else is a stale reply (e.g. a junk-burst error): ignored
            if answer is not None:
                try:
                    return P.check_reply(answer, seq, cmd)
                except P.ProtocolError as e:
                    raise FmtError(str(e)) from None

    # ---- commands ----------------------------------------------------------------
    def info(self) -> dict:
        if self._info is None:
            try:
                self._info = P.decode_info(self.transact(P.CMD_INFO, b"", P.INFO_LEN))
            except P.ProtocolError as e:
                raise FmtError(str(e)) from None
        return self._info

    def read(self, addr: int, n: int = 1) -> list[int]:
        out = []
        while n > 0:
            k = min(n, P.MAX_READ)
            p = self.transact(P.CMD_READ, struct.pack(">HB", addr, k), 4 * k)
            out += P.payload_words(p)
            addr += k
            n -= k
        return out

    def write(self, addr: int, values) -> None:
        values = [int(v) & 0xFFFFFFFF for v in values]
        per = max(1, (self.info()["payload_max"] - 2) // 4)
        for i in range(0, len(values), per):
            chunk = values[i:i + per]
            self.transact(P.CMD_WRITE, struct.pack(">H", addr + i)
                          + b"".join(struct.pack(">I", v) for v in chunk), 0)

    def blkread(self, addr: int, n: int) -> list[int]:
        out = []
        while n > 0:
            k = min(n, 1024)
            out += P.payload_words(self.transact(P.CMD_BLKREAD, struct.pack(">HH", addr, k), 4 * k))
            addr += k
            n -= k
        return out

    def stream(self, on: bool) -> None:
        self.transact(P.CMD_STREAM, bytes([1 if on else 0]), 0)

    def payloads(self, count: int | None, timeout: float, wait: float = 0.2):
        """Yield event payloads until ``count`` (None = forever); after ``wait`` s
        without an event, yield None (callers may then do other work)."""
        got = 0
        last = time.monotonic()
        while count is None or got < count:
            while self.pending:
                fr = self.pending.pop(0)
                yield fr.payload
                got += 1
                last = time.monotonic()
                if count is not None and got >= count:
                    return
            frames = self._read_frames(P.EVENT_BYTES, time.monotonic() + wait)
            self.pending += [f for f in frames if f.cmd == P.CMD_EVENT]
            if not self.pending:
                if time.monotonic() - last > timeout:
                    raise FmtError(f"no event for {timeout:.1f} s (is anything touching the sensor?)")
                yield None

    def events(self, count: int | None, timeout: float):
        """Yield decoded events (protocol.unpack_event) until ``count`` (None = forever)."""
        for p in self.payloads(count, timeout):
            if p is not None:
                yield P.unpack_event(p)

    def records(self, count: int | None, timeout: float, wait: float = 0.2):
        """Yield event records (fmt.host.events) until ``count``; None after ``wait`` s
        without an event."""
        from fmt.host import events as E
        for p in self.payloads(count, timeout, wait):
            try:
                yield None if p is None else E.from_payload(p)
            except P.ProtocolError as e:
                raise FmtError(str(e)) from None

    def heatmap(self) -> "np.ndarray":
        import numpy as np
        inf = self.info()
        rows, cols = inf["rows"], inf["cols"]
        if "SNAP_REQ" in regmap.BY_NAME:            # request a coherent whole-frame snapshot
            self.write(regmap.BY_NAME["SNAP_REQ"].addr, [1])
            st_addr = regmap.BY_NAME["SNAP_STATUS"].addr
            deadline = time.monotonic() + self.timeout
            while True:
                st = self.read(st_addr)[0]
                if (st >> 31) & 1 and not (st >> 30) & 1:     # complete, nothing pending
                    self.snap_frame = st & 0xFFFF
                    break
                if time.monotonic() > deadline:
                    raise FmtError(f"heat-map snapshot not complete within {self.timeout:.1f} s "
                                   f"(SNAP_STATUS 0x{st:08X})")
        w = self.blkread(regmap.WINDOW_BY_NAME["HEATMAP"].base, rows * cols)
        mask = (1 << inf["hm_width"]) - 1
        return (np.array(w, dtype=np.int64) & mask).reshape(rows, cols)


def parse_int(s: str) -> int:
    try:
        return int(s, 0)
    except ValueError:
        raise FmtError(f"'{s}' is not a number") from None


def resolve(name: str):
    """(address, Reg or None) of a register name or a numeric address."""
    if name[:1].isdigit():
        a = parse_int(name)
        for r in regmap.REGISTERS:
            if r.addr == a:
                return a, r
        return a, None
    try:
        r = regmap.lookup(name)
    except KeyError as e:
        raise FmtError(str(e.args[0])) from None
    return r.addr, r


# ---- sub-commands ------------------------------------------------------------------------
def cmd_info(dev: Device, a) -> None:
    inf = dev.info()
    for k, v in inf.items():
        print(f"{k}: {v}")
    local = regmap.regmap_id() & 0xFFFF
    print(f"host_regmap_id: {local}")
    if inf["regmap_id"] != local:
        print("warning: the device's register map differs from this fmtctl's", file=sys.stderr)


def cmd_get(dev: Device, a) -> None:
    addr, r = resolve(a.name)
    v = dev.read(addr)[0]
    label = r.name if r else f"0x{addr:03X}"
    print(f"{label} = {v} (0x{v:X})")


def cmd_set(dev: Device, a) -> None:
    addr, r = resolve(a.name)
    v = parse_int(a.value)
    if r is not None:
        if r.access in ("const", "ro"):
            raise FmtError(f"{r.name} is read-only ({r.access})")
        if v < 0 or v >= 1 << r.width:
            raise FmtError(f"{v} does not fit {r.name} ({r.width} bits)")
    dev.write(addr, [v])
    if r is not None and r.access == "rw":
        back = dev.read(addr)[0]
        if back != v:
            raise FmtError(f"{r.name}: wrote {v}, read back {back}")
    print(f"{r.name if r else hex(addr)} = {v} (0x{v:X})")


def cmd_heatmap(dev: Device, a) -> None:
    import numpy as np
    frames, nums = [], []
    for _ in range(max(1, a.frames)):
        frames.append(dev.heatmap())
        nums.append(dev.snap_frame)
    hm = frames[0] if len(frames) == 1 else np.stack(frames)
    np.save(a.out, hm)
    of = "" if nums[0] is None else " of frame " + ",".join(str(n) for n in nums)
    print(f"heat map {hm.shape}{of} saved to {a.out} (min {hm.min()}, max {hm.max()})")
    if a.png:
        try:
            import matplotlib
            matplotlib.use("Agg")
            import matplotlib.pyplot as plt
        except ImportError:
            raise FmtError("--png needs matplotlib (pip install matplotlib); the .npy was saved") from None
        fig, ax = plt.subplots(figsize=(6, 5))
        im = ax.imshow(frames[-1], origin="upper", interpolation="nearest")
        ax.set_xlabel("column (x)")
        ax.set_ylabel("row (y)")
        fig.colorbar(im, ax=ax, label="counts")
        fig.savefig(a.png, dpi=100)
        print(f"image saved to {a.png}")


def cmd_touches(dev: Device, a) -> None:
    dev.stream(True)
    try:
        for ev in dev.events(a.count, a.event_timeout):
            print(json.dumps(ev), flush=True)
    finally:
        try:
            dev.stream(False)
        except FmtError:
            pass


def cmd_latency(dev: Device, a) -> None:
    base = regmap.BY_NAME["LAT_FIRST_LAST"].addr
    n = regmap.BY_NAME["LAT_TRIG_ARMED"].addr - base + 1
    v = dict(zip(range(base, base + n), dev.read(base, n)))
    val = lambda name: v[regmap.BY_NAME[name].addr]
    st = {k: dev.read(regmap.BY_NAME[k].addr)[0]
          for k in ("FRAME_COUNT", "EV_DROP_COUNT", "EV_SKIP_COUNT", "STATUS")}
    win = regmap.WINDOW_BY_NAME["LAT_HIST"]
    hist = dev.blkread(win.base, win.size)
    us = lambda c: c / regmap.PROC_CLK_HZ * 1e6
    print(f"latency in processing-clock cycles ({regmap.PROC_CLK_HZ / 1e6:.0f} MHz) and us")
    for key, what in (("FIRST", "window end -> first event"), ("LAST", "window end -> last event"),
                      ("TRIG", "trigger -> new contact")):
        l, lo, hi, cnt = (val(f"LAT_{key}_{f}") for f in ("LAST", "MIN", "MAX", "COUNT"))
        rng = f"min {lo} max {hi}" if cnt else "min - max -"
        print(f"  {what:26s} last {l} {rng} count {cnt}  "
              f"(last {us(l):.3f} us, max {us(hi):.3f} us)")
    if val("LAT_TRIG_ARMED"):
        print("  trigger armed: waiting for a new contact")
    half = win.size // 2
    print(f"  histogram first event ({half} bins): " + " ".join(map(str, hist[:half])))
    print(f"  histogram last event  ({half} bins): " + " ".join(map(str, hist[half:])))
    print(f"  frames {st['FRAME_COUNT']}, event frames dropped {st['EV_DROP_COUNT']}, "
          f"skipped {st['EV_SKIP_COUNT']}, status flags 0x{st['STATUS']:03X}"
          + (f" ({', '.join(regmap.status_names(st['STATUS']))})" if st['STATUS'] else ""))


def cmd_calibrate(dev: Device, a) -> None:
    import numpy as np
    from fmt import flatten
    inf = dev.info()
    print(f"capturing {a.frames} untouched frames: keep the sensor clear", file=sys.stderr)
    base = np.stack([dev.heatmap() for _ in range(a.frames)])
    if not a.yes:
        print("place the calibration object (flat sheet covering the sensor), then press Enter",
              file=sys.stderr)
        sys.stdin.readline()
    cal = np.stack([dev.heatmap() for _ in range(a.frames)])
    from fmt.params import SensorConfig
    cfg = SensorConfig(name="device", rows=inf["rows"], cols=inf["cols"], n_fft=inf["n_fft"],
                       bin_lo=inf["bin_lo"], bin_step=inf["bin_step"], hm_width=inf["hm_width"])
    offset, gain = flatten.calibrate(base, cal, None, cfg)
    out = {"rows": inf["rows"], "cols": inf["cols"], "hm_width": inf["hm_width"],
           "gain_frac_bits": flatten.GAIN_FRAC, "offset": offset.tolist(), "gain": gain.tolist()}
    Path(a.out).write_text(json.dumps(out))
    print(f"calibration saved to {a.out} (offset mean {offset.mean():.1f}, "
          f"gain {gain.min() / flatten.GAIN_ONE:.3f}..{gain.max() / flatten.GAIN_ONE:.3f})")


def cmd_load_cal(dev: Device, a) -> None:
    try:
        cal = json.loads(Path(a.file).read_text())
        offset, gain = cal["offset"], cal["gain"]
    except (OSError, ValueError, KeyError) as e:
        raise FmtError(f"cannot read calibration {a.file}: {e}") from None
    inf = dev.info()
    if len(offset) != inf["rows"] or len(offset[0]) != inf["cols"]:
        raise FmtError(f"calibration is {len(offset)} x {len(offset[0])}, device is "
                       f"{inf['rows']} x {inf['cols']}")
    base = regmap.BY_NAME["CAL_ROW"].addr        # CAL_ROW, CAL_COL, CAL_OFFSET, CAL_GAIN
    n = 0
    for r in range(inf["rows"]):
        for c in range(inf["cols"]):
            dev.write(base, [r, c, int(offset[r][c]), int(gain[r][c])])
            n += 1
    print(f"loaded {n} cells")


# ---- the event stream as reports (tuio, uinput, view, record) -----------------------------
class streaming:
    """STREAM on inside the with-block, off after it (best effort)."""

    def __init__(self, dev: Device):
        self.dev = dev

    def __enter__(self):
        self.dev.stream(True)
        return self

    def __exit__(self, *exc):
        try:
            self.dev.stream(False)
        except FmtError:
            pass
        return False


def hold_frames(dev: Device, a) -> int:
    """--hold-frames, or (auto, < 0) from the device's registers (events.auto_hold_frames)."""
    if a.hold_frames >= 0:
        return a.hold_frames
    from fmt.host import events as E
    regs = {n: dev.read(regmap.BY_NAME[n].addr)[0] for n in ("WINDOWS_M", "REPORT_PERIOD", "TRACK_HOLD_OFF")}
    return E.auto_hold_frames(regs, dev.info()["n_fft"])


def updates(dev: Device, a):
    """(events.Update, report) for every report of the stream, forever (until the
    caller stops or no event arrives for --event-timeout s)."""
    from fmt.host import events as E
    grouper, contacts = E.Reports(), E.Contacts(hold_frames(dev, a))
    for rec in dev.records(None, a.event_timeout):
        if rec is None:
            continue
        for rep in grouper.feed(rec):
            yield contacts.update(rep), rep


def cmd_tuio(dev: Device, a) -> None:
    import socket
    from fmt.host import events as E
    from fmt.host import tuio
    sensor = E.Sensor.from_info(dev.info())
    try:
        snd = tuio.Sender(a.host, a.osc_port, sensor, a.version, source=f"fmt@{socket.gethostname()}")
    except OSError as e:
        raise FmtError(f"cannot send OSC to {a.host}:{a.osc_port}: {e}") from None
    t0 = time.monotonic()
    with streaming(dev):
        for upd, _rep in updates(dev, a):
            try:
                snd.send(upd, time.time())
            except OSError as e:
                raise FmtError(f"cannot send OSC to {a.host}:{a.osc_port}: {e}") from None
            if a.count and snd.bundles >= a.count:
                break
    print(f"tuio {a.version}: {snd.bundles} bundles to {a.host}:{a.osc_port} "
          f"in {time.monotonic() - t0:.1f} s")


def pre_uinput(a) -> None:
    import os
    if not os.path.exists(a.devnode):
        raise FmtError(f"{a.devnode} does not exist (load the uinput module: modprobe uinput)")
    if not os.access(a.devnode, os.W_OK):
        raise FmtError(f"{a.devnode} is not writable by this user (udev rule or group 'input')")


def cmd_uinput(dev: Device, a) -> None:
    from fmt.host import events as E
    from fmt.host import uinput as U
    sensor = E.Sensor.from_info(dev.info(), a.pitch_mm)
    try:
        ud = U.Device(U.MTMapper(sensor, a.slots), devnode=a.devnode)
    except OSError as e:
        raise FmtError(str(e)) from None
    print(f"uinput device {ud.path}: {sensor.cols} x {sensor.rows} cells, {a.slots} slots", flush=True)
    n = 0
    try:
        with streaming(dev):
            for upd, _rep in updates(dev, a):
                ud.send(upd)
                n += 1
                if a.count and n >= a.count:
                    break
    finally:
        ud.close()
    print(f"uinput: {n} reports")


def cmd_view(dev: Device | None, a) -> None:
    from fmt.host import events as E
    from fmt.host import view as V
    if a.recording:
        rec = _load_recording(a.recording)
        sensor = E.Sensor(rec.rows, rec.cols)
        hold = a.hold_frames if a.hold_frames >= 0 else E.auto_hold_frames(
            rec.meta.get("registers", {}), int(rec.meta["info"]["n_fft"]))
        frames = V.frames_of_recording(rec, hold)
    else:
        sensor = E.Sensor.from_info(dev.info())
        a.hold_frames = hold_frames(dev, a)
        frames = V.frames_of_device(dev, a)
    import contextlib
    t0 = time.monotonic()
    with streaming(dev) if dev is not None else contextlib.nullcontext():
        if a.png_dir:
            n = V.render_to_pngs(frames, sensor, a.png_dir, limit=a.frames or None, vmax=a.vmax)
        else:
            try:
                n = V.show_live(frames, sensor, limit=a.frames or None, vmax=a.vmax)
            except RuntimeError as e:
                raise FmtError(str(e)) from None
    dt = time.monotonic() - t0
    where = f" to {a.png_dir}" if a.png_dir else ""
    print(f"view: {n} frames{where} in {dt:.1f} s ({n / max(dt, 1e-9):.1f} frames/s)")


def _load_recording(path):
    from fmt.host import recording as R
    try:
        return R.load(path)
    except ValueError as e:
        raise FmtError(str(e)) from None


def cmd_record(dev: Device, a) -> None:
    from fmt.host import events as E
    from fmt.host import recording as R
    if not (a.snapshots or a.events or a.seconds):
        raise FmtError("record: give --snapshots, --events or --seconds (or a mix)")
    info = dev.info()
    regs = {r.name: dev.read(r.addr)[0] for r in regmap.REGISTERS if r.access == "rw"}
    cal = None
    if a.with_cal:
        rows, cols = info["rows"], info["cols"]
        off = [[0] * cols for _ in range(rows)]
        gain = [[0] * cols for _ in range(rows)]
        base = regmap.BY_NAME["CAL_ROW"].addr            # CAL_ROW, CAL_COL, CAL_OFFSET, CAL_GAIN
        for r in range(rows):
            for c in range(cols):
                dev.write(base, [r, c])
                off[r][c], gain[r][c] = dev.read(base + 2, 2)
        dev.write(base, [regs.get("CAL_ROW", 0), regs.get("CAL_COL", 0)])
        cal = (off, gain)
    hms, hfr, hts, evs, ets = [], [], [], [], []
    t0 = time.monotonic()

    def drain():
        while dev.pending:
            fr = dev.pending.pop(0)
            if fr.cmd == P.CMD_EVENT:
                try:
                    evs.append(E.from_payload(fr.payload))
                except P.ProtocolError as e:
                    raise FmtError(str(e)) from None
                ets.append(time.monotonic() - t0)

    def done() -> bool:
        if a.seconds and time.monotonic() - t0 >= a.seconds:
            return True
        return (not a.snapshots or len(hms) >= a.snapshots) and (not a.events or len(evs) >= a.events)

    stopped = ""
    try:
        with streaming(dev):
            last_ev = time.monotonic()
            while not done():
                n0 = len(evs)
                if not a.snapshots or len(hms) < a.snapshots:
                    hm = dev.heatmap()
                    hms.append(hm)
                    hfr.append(-1 if dev.snap_frame is None else dev.snap_frame)
                    hts.append(time.monotonic() - t0)
                else:
                    frames = dev._read_frames(P.EVENT_BYTES, time.monotonic() + 0.2)
                    dev.pending += [f for f in frames if f.cmd == P.CMD_EVENT]
                drain()
                if len(evs) > n0:
                    last_ev = time.monotonic()
                elif a.events and time.monotonic() - last_ev > a.event_timeout:
                    raise FmtError(f"no event for {a.event_timeout:.1f} s ({len(evs)} of {a.events} recorded)")
            drain()
    except KeyboardInterrupt:
        stopped = " (interrupted)"
    meta = R.new_meta(info, a.port, regs)
    meta["report"] = {"snapshots": len(hms), "events": len(evs), "seconds": round(time.monotonic() - t0, 3)}
    rows, cols = info["rows"], info["cols"]
    rec = R.Recording(meta, np.array(hms, dtype=np.int64).reshape(-1, rows, cols), np.array(hfr, dtype=np.int64),
                      np.array(hts), evs, np.array(ets), None if cal is None else (np.array(cal[0]), np.array(cal[1])))
    path = rec.save(a.out)
    print(f"recorded {len(hms)} heat maps and {len(evs)} events in {meta['report']['seconds']:.1f} s "
          f"to {path}{stopped}")


def cmd_regs(_dev, a) -> None:
    for r in regmap.REGISTERS:
        print(f"0x{r.addr:03X} {r.name:18s} {r.access:6s} {r.width:2d}  {r.desc}")


def build_parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(prog="fmtctl", description="FMT control-port host tool")
    ap.add_argument("--port", help="serial port or pyserial URL (socket://host:port)")
    ap.add_argument("--baud", type=int, default=115200)
    ap.add_argument("--timeout", type=float, default=None,
                    help="reply timeout in s (plus wire time); default 1 s, 10 s on socket:// ports "
                         "(the simulation's UART is slow)")
    sub = ap.add_subparsers(dest="cmd", required=True)
    sub.add_parser("info", help="version and sizes").set_defaults(fn=cmd_info)
    p = sub.add_parser("get", help="read a register")
    p.add_argument("name")
    p.set_defaults(fn=cmd_get)
    p = sub.add_parser("set", help="write a register")
    p.add_argument("name")
    p.add_argument("value")
    p.set_defaults(fn=cmd_set)
    p = sub.add_parser("heatmap", help="heat-map snapshot to .npy (rows x cols)")
    p.add_argument("--out", required=True)
    p.add_argument("--png")
    p.add_argument("--frames", type=int, default=1, help="snapshots (stacked when > 1)")
    p.set_defaults(fn=cmd_heatmap)
    p = sub.add_parser("touches", help="stream touch events as JSON lines")
    p.add_argument("--count", type=int, default=None)
    p.add_argument("--event-timeout", type=float, default=10.0)
    p.set_defaults(fn=cmd_touches)
    sub.add_parser("latency", help="latency counters report").set_defaults(fn=cmd_latency)
    p = sub.add_parser("calibrate", help="field-flattening calibration (fmt.flatten.calibrate)")
    p.add_argument("--out", required=True)
    p.add_argument("--frames", type=int, default=16)
    p.add_argument("--yes", action="store_true", help="do not wait for Enter before the object frames")
    p.set_defaults(fn=cmd_calibrate)
    p = sub.add_parser("load-cal", help="write a calibration file into the core")
    p.add_argument("file")
    p.set_defaults(fn=cmd_load_cal)
    sub.add_parser("regs", help="list the register map").set_defaults(fn=cmd_regs)

    def stream_opts(p):
        p.add_argument("--count", type=int, default=0, help="stop after this many reports (0: never)")
        p.add_argument("--event-timeout", type=float, default=3600.0,
                       help="give up after this many s without an event (default 1 h)")
        p.add_argument("--hold-frames", type=int, default=-1,
                       help="a contact absent from the reports stays alive this many frames (default "
                            "-1: the tracker's hold-off + 2 report periods, from the registers)")

    p = sub.add_parser("tuio", help="the event stream as TUIO over OSC/UDP (python-osc)")
    p.add_argument("--host", default="127.0.0.1", help="OSC receiver (default 127.0.0.1)")
    p.add_argument("--port", dest="osc_port", type=int, default=3333, help="OSC UDP port (default 3333)")
    p.add_argument("--version", default="1.1", choices=("1.1", "2.0"),
                   help="TUIO 1.1 (/tuio/2Dcur) or 2.0 (/tuio2/ptr)")
    stream_opts(p)
    p.set_defaults(fn=cmd_tuio, needs=(("pythonosc", "python-osc"),))
    p = sub.add_parser("uinput", help="the event stream as a Linux multitouch (protocol B) device")
    p.add_argument("--devnode", default="/dev/uinput")
    p.add_argument("--slots", type=int, default=16, help="multitouch slots (default 16)")
    p.add_argument("--pitch-mm", type=float, default=5.0, help="electrode pitch (axis resolution)")
    stream_opts(p)
    p.set_defaults(fn=cmd_uinput, needs=(("evdev", "evdev"),), pre=pre_uinput)
    p = sub.add_parser("view", help="heat map with contacts, IDs, tracks, ellipses (live or a recording)")
    p.add_argument("--recording", help="show a recording of fmtctl record (no --port needed)")
    p.add_argument("--png-dir", help="write the frames as PNG files here (headless) instead of a window")
    p.add_argument("--frames", type=int, default=0, help="stop after this many frames (0: never / the end)")
    p.add_argument("--vmax", type=float, default=None, help="heat-map colour scale top (default: first frame's max)")
    p.add_argument("--event-timeout", type=float, default=3600.0)
    p.add_argument("--hold-frames", type=int, default=-1, help="as for tuio (default: from the registers)")
    p.set_defaults(fn=cmd_view, port_optional=lambda a: bool(a.recording),
                   needs=(("matplotlib", "matplotlib"), ("PIL", "pillow")))
    p = sub.add_parser("record", help="heat-map snapshots, events and settings to one .npz (docs/host.md)")
    p.add_argument("--out", required=True, help="the recording (.npz)")
    p.add_argument("--snapshots", type=int, default=10, help="heat-map snapshots (default 10; 0: none)")
    p.add_argument("--events", type=int, default=0, help="keep on until this many events (default 0)")
    p.add_argument("--seconds", type=float, default=0.0, help="stop after this long (0: no limit)")
    p.add_argument("--with-cal", action="store_true",
                   help="also read the field-flattening calibration (4 transactions per cell)")
    p.add_argument("--event-timeout", type=float, default=30.0)
    p.set_defaults(fn=cmd_record)
    return ap


def check_needs(a) -> None:
    """One line for a missing optional package, before the port is opened."""
    import importlib
    for mod, pkg in getattr(a, "needs", ()):
        try:
            importlib.import_module(mod)
        except ImportError:
            raise FmtError(f"fmtctl {a.cmd} needs the Python package {pkg} (pip install {pkg}; "
                           f"pinned in requirements.txt)") from None


def main(argv=None) -> int:
    a = build_parser().parse_args(argv)
    if a.cmd == "regs":
        a.fn(None, a)
        return 0
    try:
        check_needs(a)
        if getattr(a, "pre", None):
            a.pre(a)
    except FmtError as e:
        print(f"fmtctl: error: {e}", file=sys.stderr)
        return 2
    no_port = getattr(a, "port_optional", None) and a.port_optional(a)
    if not a.port and not no_port:
        print("fmtctl: error: --port is required", file=sys.stderr)
        return 1
    dev = None
    try:
        if no_port:
            a.fn(None, a)
            return 0
        timeout = a.timeout
        if timeout is None:
            timeout = 10.0 if a.port.startswith("socket://") else 1.0
        dev = Device(a.port, a.baud, timeout)
        a.fn(dev, a)
        return 0
    except FmtError as e:
        print(f"fmtctl: error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("fmtctl: interrupted", file=sys.stderr)
        return 130
    except Exception as e:                       # never a traceback for the user
        print(f"fmtctl: error: {type(e).__name__}: {e}", file=sys.stderr)
        return 2
    finally:
        if dev is not None:
            dev.close()


if __name__ == "__main__":
    sys.exit(main())
