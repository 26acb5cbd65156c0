"""A stand-in for the core's control port on a loopback TCP socket (fmtctl's
socket://127.0.0.1:PORT, the same code path as the board's serial port and the
simulation's serve mode): INFO, READ / WRITE of a register file with the reset values
of fmt.regmap, BLKREAD of the HEATMAP window, SNAP_REQ / SNAP_STATUS snapshots taken
from a given heat-map sequence in order, and STREAM: once switched on, the given
event records are sent as event frames (pace_s apart), then nothing.

Used by the tests of fmtctl tuio / view / record; the replies are built with
fmt.protocol, so a request fmtctl gets wrong fails here like on the board.
"""
from __future__ import annotations

import socket
import struct
import threading
import time

import numpy as np

from fmt import protocol as P
from fmt import regmap
from fmt.host import events as E


class FakeCore:
    def __init__(self, cfg, heatmaps=None, records=(), pace_s: float = 0.002,
                 snapshot_frames=None, snap_delay_s: float = 0.0):
        self.cfg = cfg
        self.heatmaps = None if heatmaps is None else np.asarray(heatmaps)
        self.snap_frames = (list(snapshot_frames) if snapshot_frames is not None
                            else list(range(0 if self.heatmaps is None else len(self.heatmaps))))
        self.records = list(records)
        self.pace = pace_s
        self.regs = {r.addr: r.reset for r in regmap.REGISTERS}
        self.snap_i = -1
        self.snap = None
        self.snap_delay = snap_delay_s      # SNAP_STATUS says 'pending' this long after SNAP_REQ
        self.snap_ready = 0.0
        self.stream_on = threading.Event()
        self.sent_events = 0
        self.lock = threading.Lock()
        self.srv = socket.socket()
        self.srv.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self.srv.bind(("127.0.0.1", 0))
        self.srv.listen(4)
        self.port = self.srv.getsockname()[1]
        self.url = f"socket://127.0.0.1:{self.port}"
        self.stop = threading.Event()
        threading.Thread(target=self._serve, daemon=True).start()

    def close(self):
        self.stop.set()
        try:
            self.srv.close()
        except OSError:
            pass

    # ---- the port -----------------------------------------------------------------
    def _serve(self):
        self.srv.settimeout(0.2)
        while not self.stop.is_set():
            try:
                conn, _ = self.srv.accept()
            except (socket.timeout, OSError):
                continue
            self._client(conn)

    def _send(self, conn, data: bytes):
        with self.lock:
            conn.sendall(data)

    def _streamer(self, conn, done):
        seq = 0
        i = 0
        while not done.is_set() and i < len(self.records):
            if not self.stream_on.is_set():
                time.sleep(0.005)
                continue
            try:
                self._send(conn, P.encode(seq, P.CMD_EVENT, E.to_payload(self.records[i])))
            except OSError:
                return
            self.sent_events += 1
            seq = (seq + 1) & 0xFF
            i += 1
            time.sleep(self.pace)

    def _client(self, conn):
        conn.settimeout(0.1)
        parser = P.Parser(max_len=P.DEFAULT_PAYLOAD_MAX)
        done = threading.Event()
        threading.Thread(target=self._streamer, args=(conn, done), daemon=True).start()
        try:
            while not self.stop.is_set():
                try:
                    data = conn.recv(4096)
                except socket.timeout:
                    continue
                except OSError:
                    break
                if not data:
                    break
                for fr in parser.feed(data):
                    self._send(conn, self._execute(fr))
        finally:
            done.set()
            self.stream_on.clear()
            conn.close()

    def _execute(self, fr: P.Frame) -> bytes:
        c, p = fr.cmd, fr.payload
        if c == P.CMD_INFO:
            return P.reply(fr.seq, c, P.info_payload(self.cfg, regmap.regmap_id()))
        if c == P.CMD_READ:
            addr, n = struct.unpack(">HB", p)
            st = regmap.BY_NAME["SNAP_STATUS"].addr
            if addr <= st < addr + n and time.monotonic() < self.snap_ready:
                regs = dict(self.regs)
                regs[st] = (regs[st] & ~(1 << 31)) | (1 << 30)      # a capture is pending
                return P.reply(fr.seq, c, P.words_payload(regs.get(a, 0) for a in range(addr, addr + n)))
            return P.reply(fr.seq, c, P.words_payload(self.regs.get(a, 0) for a in range(addr, addr + n)))
        if c == P.CMD_WRITE:
            addr = struct.unpack(">H", p[:2])[0]
            for k in range((len(p) - 2) // 4):
                self._write(addr + k, struct.unpack(">I", p[2 + 4 * k:6 + 4 * k])[0])
            return P.reply(fr.seq, c)
        if c == P.CMD_BLKREAD:
            addr, n = struct.unpack(">HH", p)
            hm = self.snap if self.snap is not None else np.zeros((self.cfg.rows, self.cfg.cols), int)
            base = regmap.WINDOW_BY_NAME["HEATMAP"].base
            flat = hm.ravel()
            words = [int(flat[a - base]) if 0 <= a - base < flat.size else 0 for a in range(addr, addr + n)]
            return P.reply(fr.seq, c, P.words_payload(words))
        if c == P.CMD_STREAM:
            (self.stream_on.set if p[0] & 1 else self.stream_on.clear)()
            return P.reply(fr.seq, c)
        return P.error_reply(fr.seq, P.ERR_CMD, c)

    def _write(self, addr: int, v: int):
        if addr == regmap.BY_NAME["SNAP_REQ"].addr and v & 1 and self.heatmaps is not None:
            self.snap_i = min(self.snap_i + 1, len(self.heatmaps) - 1)
            self.snap = self.heatmaps[self.snap_i]
            self.regs[regmap.BY_NAME["SNAP_STATUS"].addr] = (1 << 31) | (self.snap_frames[self.snap_i] & 0xFFFF)
            self.snap_ready = time.monotonic() + self.snap_delay
            return
        self.regs[addr] = v
