"""Reports of the core's event stream -> a Linux multitouch protocol-B device (uinput,
python-evdev).

:class:`MTMapper` is the pure mapping: one report's contacts (events.Update) -> the
input events (type, code, value) of one evdev frame, ending with SYN_REPORT:

* every contact gets a slot (ABS_MT_SLOT, lowest free first) and a tracking ID
  (ABS_MT_TRACKING_ID, a running 16-bit number: a reused contact ID is a new contact);
  a contact that ends gets ABS_MT_TRACKING_ID -1 in its slot; more contacts than slots
  are left out until a slot frees;
* ABS_MT_POSITION_X/Y = x_q / y_q + 128: 1/256 cell from the sensor's left / top edge
  (0 .. cols * 256 - 1), resolution 256 / pitch units per mm;
* ABS_MT_TOUCH_MAJOR/MINOR = the ellipse's axes (2 x the event's semi-axes), same units;
* ABS_MT_ORIENTATION = angle - 128 (-128..128, 0 = major axis along y, 128 = a quarter
  turn clockwise: along x);
* ABS_MT_PRESSURE = strength, clipped to 65535;
* ABS_MT_TOOL_TYPE = MT_TOOL_FINGER, or MT_TOOL_PALM for a blob (palm) event;
* single-touch emulation for legacy readers: BTN_TOUCH, ABS_X/Y and ABS_PRESSURE of the
  finger in the lowest slot.

Only the values that change are sent (the kernel filters repeats anyway).  The event
codes are those of linux/input-event-codes.h (stable ABI; checked against the header and
evdev.ecodes by the test), so the mapping runs without evdev.
"""
from __future__ import annotations

from .events import Sensor, Update

EV_SYN, EV_KEY, EV_ABS = 0x00, 0x01, 0x03
SYN_REPORT = 0
BTN_TOUCH = 0x14A
ABS_X, ABS_Y, ABS_PRESSURE = 0x00, 0x01, 0x18
ABS_MT_SLOT = 0x2F
ABS_MT_TOUCH_MAJOR = 0x30
ABS_MT_TOUCH_MINOR = 0x31
ABS_MT_ORIENTATION = 0x34
ABS_MT_POSITION_X = 0x35
ABS_MT_POSITION_Y = 0x36
ABS_MT_TOOL_TYPE = 0x37
ABS_MT_TRACKING_ID = 0x39
ABS_MT_PRESSURE = 0x3A
MT_TOOL_FINGER, MT_TOOL_PALM = 0, 2
INPUT_PROP_DIRECT = 0x01
PRESSURE_MAX = 0xFFFF


class MTMapper:
    def __init__(self, sensor: Sensor, slots: int = 16):
        self.sensor = sensor
        self.slots = slots
        self.slot_of: dict[int, int] = {}          # contact key -> slot
        self.vals: dict[int, dict[int, int]] = {}  # slot -> code -> last value sent
        self.cur_slot = -1
        self.next_tid = 0
        self.touch = 0
        self.st: dict[int, int] = {}

    def absinfo(self) -> dict[int, tuple[int, int, int]]:
        """code -> (min, max, resolution) of every absolute axis."""
        s = self.sensor
        xm, ym = s.cols * 256 - 1, s.rows * 256 - 1
        res = max(1, round(256 / s.pitch_mm))
        axm = 2 * max(s.cols, s.rows) * 256
        return {ABS_X: (0, xm, res), ABS_Y: (0, ym, res), ABS_PRESSURE: (0, PRESSURE_MAX, 0),
                ABS_MT_SLOT: (0, self.slots - 1, 0), ABS_MT_TRACKING_ID: (0, 0xFFFF, 0),
                ABS_MT_POSITION_X: (0, xm, res), ABS_MT_POSITION_Y: (0, ym, res),
                ABS_MT_TOUCH_MAJOR: (0, axm, res), ABS_MT_TOUCH_MINOR: (0, axm, res),
                ABS_MT_ORIENTATION: (-128, 128, 0), ABS_MT_PRESSURE: (0, PRESSURE_MAX, 0),
                ABS_MT_TOOL_TYPE: (0, MT_TOOL_PALM, 0)}

    def values(self, c) -> dict[int, int]:
        """The per-slot axis values of one contact (events.Contact)."""
        s = self.sensor
        clip = lambda v, hi: min(max(int(v), 0), hi)
        return {ABS_MT_TOOL_TYPE: MT_TOOL_PALM if c.palm else MT_TOOL_FINGER,
                ABS_MT_POSITION_X: clip(c.x_q + 128, s.cols * 256 - 1),
                ABS_MT_POSITION_Y: clip(c.y_q + 128, s.rows * 256 - 1),
                ABS_MT_TOUCH_MAJOR: 2 * c.axis_major_q, ABS_MT_TOUCH_MINOR: 2 * c.axis_minor_q,
                ABS_MT_ORIENTATION: (c.angle & 0xFF) - 128,
                ABS_MT_PRESSURE: clip(c.strength, PRESSURE_MAX)}

    def _slot(self, out, s):
        if s != self.cur_slot:
            out.append((EV_ABS, ABS_MT_SLOT, s))
            self.cur_slot = s

    def frame(self, upd: Update) -> list[tuple[int, int, int]]:
        out: list[tuple[int, int, int]] = []
        for key in sorted(k for k in self.slot_of if k not in upd.alive):     # ended
            s = self.slot_of.pop(key)
            self._slot(out, s)
            out.append((EV_ABS, ABS_MT_TRACKING_ID, -1))
            self.vals.pop(s, None)
        for key, c in upd.alive.items():
            s = self.slot_of.get(key)
            if s is None:
                free = sorted(set(range(self.slots)) - set(self.slot_of.values()))
                if not free:
                    continue
                s = self.slot_of[key] = free[0]
                self._slot(out, s)
                out.append((EV_ABS, ABS_MT_TRACKING_ID, self.next_tid))
                self.next_tid = (self.next_tid + 1) & 0xFFFF
                self.vals[s] = {}
            v = self.values(c)
            for code, val in v.items():
                if self.vals[s].get(code) != val:
                    self._slot(out, s)
                    out.append((EV_ABS, code, val))
                    self.vals[s][code] = val
        # single-touch emulation: the finger in the lowest slot
        fingers = sorted((s, k) for k, s in self.slot_of.items() if not upd.alive[k].palm)
        touch = 1 if fingers else 0
        if touch != self.touch:
            out.append((EV_KEY, BTN_TOUCH, touch))
            self.touch = touch
        if fingers:
            v = self.vals[fingers[0][0]]
            for code, mt in ((ABS_X, ABS_MT_POSITION_X), (ABS_Y, ABS_MT_POSITION_Y),
                             (ABS_PRESSURE, ABS_MT_PRESSURE)):
                if self.st.get(code) != v[mt]:
                    out.append((EV_ABS, code, v[mt]))
                    self.st[code] = v[mt]
        out.append((EV_SYN, SYN_REPORT, 0))
        return out


class Device:
    """The uinput device (python-evdev) fed by an MTMapper."""

    def __init__(self, mapper: MTMapper, name: str = "FMT touch controller",
                 devnode: str = "/dev/uinput"):
        import evdev
        from evdev import AbsInfo, UInput
        caps = {EV_KEY: [BTN_TOUCH],
                EV_ABS: [(code, AbsInfo(value=0, min=lo, max=hi, fuzz=0, flat=0, resolution=res))
                         for code, (lo, hi, res) in mapper.absinfo().items()]}
        self.mapper = mapper
        try:
            self.ui = UInput(caps, name=name, input_props=[INPUT_PROP_DIRECT], devnode=devnode)
        except (evdev.UInputError, OSError) as e:
            raise OSError(f"cannot create the uinput device ({devnode}): {e}") from None

    def send(self, upd: Update) -> int:
        evs = self.mapper.frame(upd)
        for t, c, v in evs:
            self.ui.write(t, c, v)
        return len(evs)

    @property
    def path(self) -> str:
        return self.ui.device.path

    def close(self):
        self.ui.close()
