"""The register map of the FMT core, written once, and its generators.

The table :data:`REGISTERS` (below) is the only place a register is defined.  Reset
values come from ``fmt.params.DEFAULT`` and ``fmt.settings.TouchSettings()`` where a
default exists there.  ``python -m fmt.generate`` writes

* ``rtl/fmt_regfile.v``   -- the decode (write enables, registered read mux, reset
  values, rw registers as output ports, ro registers as input ports),
* ``docs/REGISTERS.md``  -- the register and window tables (README material),

and ``scripts/fmtctl`` imports this module for the names and addresses.
``sim/tests/test_regmap.py`` fails when a committed generated file is stale.

Access types:

``const``   read-only literal (ID, version); no port.
``rw``      read/write register in the register file; output ``<name>_o``.
``ro``      read-only; input ``<name>_i`` sampled when read.
``w1c``     sticky flags: input ``<name>_set_i`` sets bits, writing 1 clears them
            (a set in the same cycle wins); output ``<name>_o``.
``window``  a data port into a memory of the core, addressed by a selector ``rw``
            register: a write gives the one-cycle strobe ``<name>_we_o`` with
            ``<name>_wdata_o``, a read gives ``<name>_re_o`` and returns
            ``<name>_rdata_i`` (which must be valid while the selector is stable).
``strobe``  write-only command: a write gives ``<name>_we_o`` with
            ``<name>_wdata_o``; reads return 0.

Block windows (:data:`WINDOWS`) live in the separate block-read address space of
the control port (``blk_addr``), read with the BLKREAD command.
"""
from __future__ import annotations

import argparse
import math
import sys
from dataclasses import dataclass
from pathlib import Path

from . import params, protocol
from .settings import TouchSettings
from .tracker import TrackParams

ROOT = Path(__file__).resolve().parents[2]
REGFILE_PATH = ROOT / "rtl" / "fmt_regfile.v"
VH_PATH = REGFILE_PATH.parent / "fmt_regmap.vh"
DOC_PATH = ROOT / "docs" / "REGISTERS.md"

CFG = params.DEFAULT
SETTINGS = TouchSettings()
WINDOWS_M = 1                               # windows per frame (brief: M = 1 by default)
FRAME_PERIOD_S = WINDOWS_M * CFG.n_fft / CFG.fs_hz
# Processing clock of the default build: 3 x fs = 125 MHz (docs/ARCHITECTURE.md,
# "Clocking"; params.py has no CLK_PER_SAMPLE yet).
CLK_PER_SAMPLE = 3
PROC_CLK_HZ = CLK_PER_SAMPLE * CFG.fs_hz
HOST_REPORT_HZ = 250                        # brief: Windows hosts accept at most 250 Hz
_TRACK = TrackParams.from_settings(CFG, SETTINGS, FRAME_PERIOD_S)
_ROW_W = max(1, math.ceil(math.log2(CFG.rows)))          # fmt_touch ROW_IDX_W
_COL_W = max(1, math.ceil(math.log2(CFG.cols)))          # fmt_touch COL_IDX_W
_LIM_W = math.ceil(math.log2(CFG.max_touches + 1))       # fmt_touch LIM_W
_HOLD_W = 12                                             # fmt_touch HOLD_W
_V_W = _TRACK.v_w                                        # fmt_touch V_W (max_speed is V_W-1 bits)

ACCESS = ("const", "rw", "ro", "w1c", "window", "strobe")


@dataclass(frozen=True)
class Reg:
    name: str        # upper case; the Verilog port prefix is the lower-case name
    addr: int        # 16-bit word address on the register bus
    width: int       # 1..32 bits, right-aligned in the 32-bit data word
    access: str      # see ACCESS
    reset: int       # reset value (rw, w1c) or the literal (const); 0 otherwise
    desc: str

    @property
    def port(self) -> str:
        return self.name.lower()


@dataclass(frozen=True)
class Window:
    name: str
    base: int        # first word address in the block-read space
    size: int        # words
    desc: str


R = Reg
REGISTERS: list[Reg] = [
    # ---- identification -------------------------------------------------------------------
    R("ID", 0x000, 32, "const", protocol.INFO_MAGIC, "Magic 0x464D5443 ('FMTC')."),
    R("VERSION", 0x001, 16, "const", protocol.VERSION, "Protocol/register-map version, major.minor in bytes."),
    R("SCRATCH", 0x002, 32, "rw", 0, "Scratch register for host tests; no effect."),
    # ---- signal chain -----------------------------------------------------------------------
    R("RUN", 0x010, 1, "rw", 1, "1 = transmit and receive; 0 = transmitters silent (heat maps keep streaming)."),
    R("PN_ENABLE", 0x011, 1, "rw", 1, "1 = PN stir/unstir on (fmt_pn_gen enable_i)."),
    R("PN_CHIP_LEN", 0x012, 10, "rw", 1, "Samples per PN chip (fmt_pn_gen chip_len_i; 0 is taken as 1)."),
    R("PN_RX_DELAY", 0x013, 6, "rw", 0, "Receive PN delay in samples (fmt_pn_gen rx_delay_i)."),
    R("WINDOWS_M", 0x014, 8, "rw", WINDOWS_M,
      "FFT windows accumulated per frame, any M from 1 to M_MAX (fmt_core parameter; 255 in "
      "the default build, so every value); 0 is taken as 1, a value above M_MAX as M_MAX. "
      "Read at the first window of each frame; heat-map cell = round half up of the mean over M."),
    R("TONE_SEL", 0x018, _ROW_W, "rw", 0, "Row selector of the tone-plan windows TONE_TW and TONE_AMP."),
    R("TONE_TW", 0x019, CFG.phase_bits, "window", 0,
      "Tuning word of row TONE_SEL (DDS phase increment; default bin k -> k << (PHASE_BITS - LOG2_N))."),
    R("TONE_AMP", 0x01A, CFG.amp_bits + 1, "window", 0,
      f"Row TONE_SEL: bits {CFG.amp_bits - 1}..0 amplitude (full scale {(1 << CFG.amp_bits) - 1}), "
      f"bit {CFG.amp_bits} enable."),
    # ---- touch processing (fmt_touch run-time inputs) ---------------------------------------
    R("TOUCH_THRESHOLD", 0x020, CFG.hm_width, "rw", SETTINGS.threshold,
      "Coarse-touch threshold on the flattened heat map (counts); fmt_touch threshold_i."),
    R("TOUCH_MODE", 0x021, 3, "rw",
      (1 if SETTINGS.neighbourhood == "moore" else 0) | (2 if SETTINGS.bias_correction else 0)
      | (4 if SETTINGS.blobs else 0),
      "Bit 0: 1 = Moore (3x3) maxima and fit, 0 = Von Neumann (moore_i); bit 1: bias correction on "
      "(bias_en_i); bit 2: blob detection on (blob_en_i: fingers inside blobs dropped, type-3 blob events)."),
    R("CONTACT_LIMIT", 0x022, _LIM_W, "rw",
      SETTINGS.max_touches if SETTINGS.max_touches is not None else CFG.max_touches,
      "Contact limit per frame, <= MAX_TOUCHES (limit_i)."),
    R("TRACK_MAX_JUMP", 0x023, 16, "rw", _TRACK.max_jump_q,
      f"Tracker L1 gate of a contact seen last frame, cells Q8.8 (default: (2 + sqrt 2) x {SETTINGS.max_speed_mm_s} "
      f"mm/s x one window + sqrt 2 x {SETTINGS.position_noise_mm} mm, rounded up; max_jump_i)."),
    R("TRACK_GATE_STEP", 0x024, 16, "rw", _TRACK.gate_step_q,
      "Growth of a contact's L1 gate per frame it is missed, cells Q8.8 (default: (2 + sqrt 2) "
      "x the maximum speed x one window, rounded up; gate_step_i)."),
    R("TRACK_HOLD_OFF", 0x025, _HOLD_W, "rw", _TRACK.hold_off_frames,
      f"Frames a missing contact keeps its ID (default {SETTINGS.hold_off_us} us; hold_off_i)."),
    R("TRACK_VEL_SHIFT", 0x026, 4, "rw", _TRACK.vel_shift,
      f"Velocity filter gain 2^-S (default from a {SETTINGS.velocity_window_us} us window; vel_shift_i)."),
    R("TRACK_MAX_SPEED", 0x027, _V_W - 1, "rw", _TRACK.max_speed_v,
      f"Velocity clamp per axis, 2^-(8+VF) cells per frame (default {SETTINGS.max_speed_mm_s} mm/s; max_speed_i)."),
    R("BLOB_THRESHOLD", 0x028, CFG.hm_width, "rw", SETTINGS.blob_threshold,
      "Cells above this belong to a connected region (blob detection)."),
    R("BLOB_MIN_CELLS", 0x029, 12, "rw", SETTINGS.blob_min_cells,
      "A region of at least this many cells is reported as a blob."),
    R("TOUCH_ON_THRESHOLD", 0x02A, CFG.hm_width, "rw", SETTINGS.on_threshold,
      "Activation threshold: a touch starts a new contact only at least this strong (counts); "
      "TOUCH_THRESHOLD is the deactivation threshold of a continuing contact (on_thr_i)."),
    R("TRACK_CONFIRM", 0x02B, 3, "rw", SETTINGS.confirm_frames,
      "Frames a new contact must be seen (matched in consecutive frames) before its new event; "
      "1 = at once, 0 is taken as 1; a contact missing before that is dropped without events "
      "(confirm_i)."),
    R("CAL_ROW", 0x030, _ROW_W, "rw", 0, "Row of the calibration windows (cal_row_i)."),
    R("CAL_COL", 0x031, _COL_W, "rw", 0, "Column of the calibration windows (cal_col_i)."),
    R("CAL_OFFSET", 0x032, CFG.hm_width, "window", 0,
      "Field-flattening offset of cell (CAL_ROW, CAL_COL), counts (cal_sel_i = 0)."),
    R("CAL_GAIN", 0x033, 16, "window", 0,
      "Field-flattening gain of cell (CAL_ROW, CAL_COL), unsigned Q2.14, 1.0 = 16384 (cal_sel_i = 1)."),
    # ---- event port -------------------------------------------------------------------------
    R("LATENCY_DIAL", 0x040, 32, "rw", 0, "Dial-a-latency: extra event delay in processing cycles (delay_i)."),
    R("REPORT_PERIOD", 0x041, 32, "rw", math.ceil(PROC_CLK_HZ / HOST_REPORT_HZ),
      f"Minimum processing cycles between reported frames (report_period_i; 0 = every frame; "
      f"default {HOST_REPORT_HZ} Hz)."),
    # ---- status -----------------------------------------------------------------------------
    R("FRAME_COUNT", 0x080, 32, "ro", 0, "Frames processed since reset."),
    R("STATUS", 0x081, 11, "w1c", 0,
      "Sticky flags, write 1 to clear: bit 0 flattening saturation, bit 1 receiver FFT "
      "overflow (an FFT stage saturated), bit 2 event port dropped a frame, bit 3 latency counter saturation, bit 4 "
      "control-port error, bit 5 localmax overflow/overrun, bit 6 tracker drop/no slot/overrun, "
      "bit 7 blob overflow (more than 8 blobs in a frame)/overrun, bit 8 a calibration write "
      "went into a frame's flattening (more writes during one frame than fmt_flatten's queue holds), "
      "bit 9 receiver heat-map cell saturated (clipped at 2^HM_W - 1), bit 10 receiver overrun (a row "
      "lost: the shared units' queue full, a row rewritten before it was read, or ce too fast)."),
    R("CTRL_ERRORS", 0x082, 16, "ro", 0, "Control-port error count, saturating (every ERROR reply and junk burst)."),
    R("CTRL_LAST_ERR", 0x083, 8, "ro", 0, "Control-port code of the last error (docs/PROTOCOL.md)."),
    R("EV_DROP_COUNT", 0x084, 16, "ro", 0, "Event port: frames dropped for lack of room."),
    R("EV_SKIP_COUNT", 0x085, 16, "ro", 0, "Event port: frames skipped by REPORT_PERIOD."),
    R("FLAT_SAT_COUNT", 0x086, 16, "ro", 0, "Flattening: saturated cells."),
    R("LM_DROP_COUNT", 0x087, 16, "ro", 0, "Localmax: candidates dropped by the contact limit."),
    R("SAT_CLEAR", 0x088, 1, "strobe", 0, "Write 1: clear the flattening saturation monitor (sat_clr_i)."),
    R("STREAM_DROP_COUNT", 0x089, 16, "ro", 0,
      "UART event stream: reports dropped whole, saturating (the previous report was still being "
      "sent, or the frame had more than 2^STREAM_AW events)."),
    R("LAT_FIRST_LAST", 0x090, 16, "ro", 0, "Latency, window end -> first event of the frame, last value (cycles)."),
    R("LAT_FIRST_MIN", 0x091, 16, "ro", 0, "Latency to the first event, minimum since clear."),
    R("LAT_FIRST_MAX", 0x092, 16, "ro", 0, "Latency to the first event, maximum since clear."),
    R("LAT_FIRST_COUNT", 0x093, 32, "ro", 0, "Frames measured (first event)."),
    R("LAT_LAST_LAST", 0x094, 16, "ro", 0, "Latency, window end -> last event of the frame, last value (cycles)."),
    R("LAT_LAST_MIN", 0x095, 16, "ro", 0, "Latency to the last event, minimum since clear."),
    R("LAT_LAST_MAX", 0x096, 16, "ro", 0, "Latency to the last event, maximum since clear."),
    R("LAT_LAST_COUNT", 0x097, 32, "ro", 0, "Frames measured (last event)."),
    R("LAT_TRIG_LAST", 0x098, 16, "ro", 0, "Touch-to-data latency, trigger input -> next new contact, last (cycles)."),
    R("LAT_TRIG_MIN", 0x099, 16, "ro", 0, "Touch-to-data latency, minimum since clear."),
    R("LAT_TRIG_MAX", 0x09A, 16, "ro", 0, "Touch-to-data latency, maximum since clear."),
    R("LAT_TRIG_COUNT", 0x09B, 32, "ro", 0, "Triggers measured."),
    R("LAT_TRIG_ARMED", 0x09C, 1, "ro", 0, "A trigger is waiting for its new-contact event."),
    R("LAT_CLEAR", 0x09F, 1, "strobe", 0, "Write 1: clear the latency statistics and histograms (clear_i)."),
    # ---- heat-map snapshot (fmt_core) ------------------------------------------------------
    R("SNAP_REQ", 0x0A0, 1, "strobe", 0,
      "Write 1: capture the next whole raw frame into the HEATMAP block window (fmt_core)."),
    R("SNAP_STATUS", 0x0A1, 32, "ro", 0,
      "Heat-map snapshot: bit 31 = a snapshot is complete, bit 30 = a capture is pending, "
      "bits 15..0 = frame number of the snapshot."),
]

WINDOWS: list[Window] = [
    Window("HEATMAP", 0x0000, CFG.rows * CFG.cols,
           "Raw heat-map snapshot (before field flattening; what `fmtctl calibrate` needs): "
           "cell (r, c) at HEATMAP + r * COLS + c, unsigned, low HM_W bits."),
    Window("LAT_HIST", 0x8000, 32,
           "Latency histograms, 32-bit bin counts: words 0..15 first event, 16..31 last event "
           "(fmt_latency hist_sel_i = bit 4, hist_addr_i = bits 3..0)."),
]

BY_NAME = {r.name: r for r in REGISTERS}
# STATUS bit i's short name (fmtctl prints the names of the set flags; the description
# above is the documentation of each)
STATUS_FLAGS = ("flat_sat", "rx_fft_ovf", "ev_drop", "lat_sat", "ctrl_err", "lm_ovf",
                "trk_drop", "blob_ovf", "cal_late", "rx_sat", "rx_overrun")


def status_names(value: int) -> list[str]:
    """Names of the STATUS bits set in value (unknown bits as bitN)."""
    out = [n for i, n in enumerate(STATUS_FLAGS) if value >> i & 1]
    extra = value >> len(STATUS_FLAGS)
    out += [f"bit{len(STATUS_FLAGS) + i}" for i in range(extra.bit_length()) if extra >> i & 1]
    return out
WINDOW_BY_NAME = {w.name: w for w in WINDOWS}


def validate() -> None:
    seen = {}
    for r in REGISTERS:
        assert r.access in ACCESS, r
        assert 1 <= r.width <= 32, r
        assert 0 <= r.addr < 1 << 16, r
        assert r.addr not in seen, f"{r.name} and {seen.get(r.addr)} share address 0x{r.addr:03X}"
        seen[r.addr] = r.name
        assert 0 <= r.reset < (1 << r.width), f"{r.name}: reset {r.reset} does not fit {r.width} bits"
    assert len(BY_NAME) == len(REGISTERS)


def lookup(name: str) -> Reg:
    try:
        return BY_NAME[name.upper()]
    except KeyError:
        raise KeyError(f"unknown register '{name}' (known: {', '.join(BY_NAME)})") from None


def regmap_id() -> int:
    """16-bit identity of the register map (CRC of its canonical text), reported by
    INFO so a host can tell it talks to the same map."""
    text = ";".join(f"{r.name},{r.addr},{r.width},{r.access},{r.reset}" for r in REGISTERS)
    text += ";" + ";".join(f"{w.name},{w.base},{w.size}" for w in WINDOWS)
    return protocol.crc16(text.encode())


# ---- register-file model (twin of the generated RTL) ---------------------------------------
class RegfileModel:
    """Behaviour of fmt_regfile seen from the bus: reads and writes of rw/const/w1c."""

    def __init__(self):
        self.val = {r.name: r.reset for r in REGISTERS if r.access in ("rw", "w1c", "const")}

    def write(self, addr: int, data: int) -> None:
        for r in REGISTERS:
            if r.addr == addr:
                m = (1 << r.width) - 1
                if r.access == "rw":
                    self.val[r.name] = data & m
                elif r.access == "w1c":
                    self.val[r.name] &= ~data & m

    def read(self, addr: int, inputs: dict | None = None) -> int:
        inputs = inputs or {}
        for r in REGISTERS:
            if r.addr == addr:
                m = (1 << r.width) - 1
                if r.name in self.val:
                    return self.val[r.name]
                if r.access in ("ro", "window"):
                    return inputs.get(r.name, 0) & m
                return 0
        return 0


# ---- generators ---------------------------------------------------------------------------
def _hex(width: int, v: int) -> str:
    return f"{width}'h{v:0{(width + 3) // 4}X}"


def render_verilog() -> str:
    validate()
    L = []
    a = L.append
    a("// fmt_regfile -- GENERATED by `python -m fmt.generate` from sim/fmt/regmap.py.")
    a("// Do not edit by hand: sim/tests/test_regmap.py fails when this file is stale.")
    a("//")
    a("// Register file of the FMT core on the control port's register bus (fmt_ctrl_port).")
    a("// Bus timing: a write (reg_we_i) takes effect at the clock edge; a read (reg_re_i)")
    a("// returns its data in reg_rdata_o on the next cycle (registered read mux).  Data is")
    a("// 32 bits, a register of width w uses bits w-1..0 (other bits read 0).  Unmapped")
    a("// addresses read 0 and ignore writes.  Window/strobe ports are combinational decodes")
    a("// of the (registered) bus signals.  Reset values are those of docs/REGISTERS.md.")
    a(f"// Register map id 0x{regmap_id():04X}.")
    a("`default_nettype none")
    a("")
    a("module fmt_regfile (")
    a("    input  wire        clk,")
    a("    input  wire        rst,          // synchronous, active high: every register to its reset value")
    a("    input  wire        reg_we_i,     // write strobe")
    a("    input  wire        reg_re_i,     // read strobe")
    a("    input  wire [15:0] reg_addr_i,   // word address")
    a("    input  wire [31:0] reg_wdata_i,  // write data")
    ports = []
    for r in REGISTERS:
        w = f"[{r.width - 1}:0] " if r.width > 1 else ""
        p = r.port
        d = r.desc.split(".")[0].replace("\n", " ")
        if r.access == "rw":
            ports.append((f"output reg  {w}{p}_o", f"{r.name} (rw): {d}"))
        elif r.access == "ro":
            ports.append((f"input  wire {w}{p}_i", f"{r.name} (ro): {d}"))
        elif r.access == "w1c":
            ports.append((f"input  wire {w}{p}_set_i", f"{r.name}: bits to set"))
            ports.append((f"output reg  {w}{p}_o", f"{r.name} (w1c): {d}"))
        elif r.access == "window":
            ports.append((f"output wire {p}_we_o", f"{r.name} (window): write strobe"))
            ports.append((f"output wire {w}{p}_wdata_o", f"{r.name}: write data"))
            ports.append((f"output wire {p}_re_o", f"{r.name}: read strobe"))
            ports.append((f"input  wire {w}{p}_rdata_i", f"{r.name}: read data (valid while selected)"))
        elif r.access == "strobe":
            ports.append((f"output wire {p}_we_o", f"{r.name} (strobe): {d}"))
            ports.append((f"output wire {w}{p}_wdata_o", f"{r.name}: write data"))
    ports.append(("output reg  [31:0] reg_rdata_o", "read data, the cycle after reg_re_i"))
    for i, (decl, cmt) in enumerate(ports):
        sep = "," if i < len(ports) - 1 else ""
        a(f"    {decl}{sep}".ljust(52) + f"// {cmt}")
    a(");")
    a("")
    for r in REGISTERS:
        a(f"    localparam [15:0] A_{r.name} = 16'h{r.addr:04X};")
    a("")
    a("    // write decode")
    for r in REGISTERS:
        if r.access in ("rw", "w1c", "window", "strobe"):
            a(f"    wire wr_{r.port} = reg_we_i && (reg_addr_i == A_{r.name});")
    for r in REGISTERS:
        if r.access == "window":
            a(f"    assign {r.port}_we_o    = wr_{r.port};")
            a(f"    assign {r.port}_wdata_o = reg_wdata_i[{r.width - 1}:0];")
            a(f"    assign {r.port}_re_o    = reg_re_i && (reg_addr_i == A_{r.name});")
        elif r.access == "strobe":
            a(f"    assign {r.port}_we_o    = wr_{r.port};")
            a(f"    assign {r.port}_wdata_o = reg_wdata_i[{r.width - 1}:0];")
    a("")
    a("    always @(posedge clk) begin")
    a("        if (rst) begin")
    for r in REGISTERS:
        if r.access in ("rw", "w1c"):
            a(f"            {r.port}_o <= {_hex(r.width, r.reset)};")
    a("        end else begin")
    for r in REGISTERS:
        if r.access == "rw":
            a(f"            if (wr_{r.port}) {r.port}_o <= reg_wdata_i[{r.width - 1}:0];")
        elif r.access == "w1c":
            a(f"            {r.port}_o <= ({r.port}_o & ~(wr_{r.port} ? reg_wdata_i[{r.width - 1}:0] "
              f": {_hex(r.width, 0)})) | {r.port}_set_i;")
    a("        end")
    a("    end")
    a("")
    a("    // registered read mux")
    a("    always @(posedge clk) begin")
    a("        if (rst) begin")
    a("            reg_rdata_o <= 32'h0;")
    a("        end else if (reg_re_i) begin")
    a("            case (reg_addr_i)")
    for r in REGISTERS:
        pad = 32 - r.width
        if r.access == "const":
            src = _hex(r.width, r.reset)
        elif r.access in ("rw", "w1c"):
            src = f"{r.port}_o"
        elif r.access == "ro":
            src = f"{r.port}_i"
        elif r.access == "window":
            src = f"{r.port}_rdata_i"
        else:
            src = None
        if src is None:
            val = "32'h0"
        elif pad:
            val = f"{{{pad}'h0, {src}}}"
        else:
            val = src
        a(f"                A_{r.name}: reg_rdata_o <= {val};")
    a("                default: reg_rdata_o <= 32'h0;")
    a("            endcase")
    a("        end")
    a("    end")
    a("")
    a("endmodule")
    a("`default_nettype wire")
    a("")
    return "\n".join(L)


def render_markdown() -> str:
    validate()
    L = ["# FMT registers",
         "",
         "GENERATED by `python -m fmt.generate` from `sim/fmt/regmap.py`; do not edit "
         "(`sim/tests/test_regmap.py` fails when this file is stale).",
         "",
         f"Register map id `0x{regmap_id():04X}` (reported by the INFO command). Registers are "
         "32-bit words on a 16-bit word address; a register of width w uses bits w-1..0. "
         f"Reset values are those of the default build ({CFG.rows} x {CFG.cols}, N = {CFG.n_fft}, "
         f"M = {WINDOWS_M}, frame period {FRAME_PERIOD_S * 1e6:.3f} us) and of "
         "`fmt.settings.TouchSettings()`. Frame protocol: `docs/PROTOCOL.md`.",
         "",
         "Access: `const` literal; `rw` read/write; `ro` read-only status; `w1c` sticky flags, "
         "write 1 to clear; `window` data port into a core memory selected by a `*_SEL` register "
         "(read/write strobes to the core); `strobe` write-only command.",
         "",
         "| address | name | width | access | reset | description |",
         "|---|---|---|---|---|---|"]
    for r in REGISTERS:
        reset = f"0x{r.reset:X}" if r.access in ("rw", "w1c", "const") else "-"
        L.append(f"| 0x{r.addr:03X} | {r.name} | {r.width} | {r.access} | {reset} | {r.desc} |")
    L += ["",
          "## Block-read windows (BLKREAD command, `blk_addr` space)",
          "",
          "| base | name | words | description |",
          "|---|---|---|---|"]
    for w in WINDOWS:
        L.append(f"| 0x{w.base:04X} | {w.name} | {w.size} | {w.desc} |")
    L.append("")
    return "\n".join(L)


def render_vh() -> str:
    """rtl/fmt_regmap.vh: the register-map id as a macro, so every build of fmt_core
    (simulation or board) reports the map it was generated from in INFO."""
    return ("// GENERATED by `python -m fmt.generate` from sim/fmt/regmap.py -- do not edit.\n"
            "// FMT_REGMAP_ID: 16-bit identity of the register map (fmt.regmap.regmap_id()),\n"
            "// the default of fmt_core's REGMAP_ID (reported by the INFO command).\n"
            "`ifndef FMT_REGMAP_VH\n`define FMT_REGMAP_VH\n"
            f"`define FMT_REGMAP_ID 16'h{regmap_id() & 0xFFFF:04X}\n"
            "`endif\n")


GENERATED = {REGFILE_PATH: render_verilog, DOC_PATH: render_markdown, VH_PATH: render_vh}


def stale_files() -> list[Path]:
    return [p for p, f in GENERATED.items() if not p.exists() or p.read_text() != f()]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description="FMT register map: print the registers "
                                 "(python -m fmt.generate writes the generated files)")
    ap.parse_args(argv)
    for r in REGISTERS:
        print(f"0x{r.addr:03X} {r.name:18s} {r.access:6s} {r.width:2d} reset 0x{r.reset:X}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
