#!/usr/bin/env python3
"""Estimate the flip-flops XST would pack into DSP48E and block-RAM registers (issue #10).

Yosys's `synth_xilinx -family xc5v` maps multipliers to DSP48E and memories to RAMB18/36
but leaves every register beside them in fabric flip-flops (FDRE / FDSE).  XST packs
such registers into the primitives (DSP48E AREG / BREG, one or two stages, and PREG;
RAMB DOA_REG / DOB_REG), so the fabric flip-flop count of a Yosys run overstates what the
part needs.  This script reads a flattened xc5v netlist (the `xc5v.json` that
`scripts/timing.py` writes per block) and counts, as an estimate:

* DSP input registers: a flip-flop whose output drives only DSP48E A or B inputs (one
  stage), and a flip-flop feeding only such a flip-flop (the second stage, A1/B1);
* DSP output registers: a flip-flop whose input is a DSP48E P bit that drives nothing
  else (PREG; one stage);
* block-RAM output registers: a flip-flop whose input is a RAMB read-data bit that
  drives nothing else (DO*_REG; one stage).

It does not check that the packed bits share one clock enable and reset (XST needs that
per register group), nor XST's other rules; an estimate, information only.  Prints, per
netlist: fabric flip-flops, those packable by the rules above, and the rest.

    python scripts/xst_pack_estimate.py build/timing/<run>/<block>/xc5v.json ...
"""
from __future__ import annotations

import json
import sys
from collections import defaultdict

FF_TYPES = {"FDRE", "FDSE", "FDCE", "FDPE", "FDRE_1", "FD"}
DSP_IN = {"A", "B"}
DSP_TYPES = {"DSP48E"}
RAM_DO = {"DO", "DOA", "DOB", "DOADO", "DOBDO", "DOPA", "DOPB"}


def top_module(d: dict) -> dict:
    tops = [v for v in d["modules"].values() if v.get("attributes", {}).get("top")]
    if len(tops) != 1:
        raise SystemExit("xst_pack_estimate: the netlist has no single top module")
    return tops[0]


def estimate(path: str) -> dict:
    m = top_module(json.load(open(path)))
    driver = {}                       # bit -> (cell, type, port)
    loads = defaultdict(list)         # bit -> [(cell, type, port)]
    for name, c in m["cells"].items():
        dirs = c.get("port_directions", {})
        for port, bits in c["connections"].items():
            for b in bits:
                if not isinstance(b, int):
                    continue              # constants
                if dirs.get(port) == "output":
                    driver[b] = (name, c["type"], port)
                else:
                    loads[b].append((name, c["type"], port))
    ffs = {n: c for n, c in m["cells"].items() if c["type"] in FF_TYPES}

    def q_bit(c):
        return c["connections"]["Q"][0]

    def d_bit(c):
        return c["connections"]["D"][0]

    dsp_in = set()
    for n, c in ffs.items():
        ld = loads.get(q_bit(c), [])
        if ld and all(t in DSP_TYPES and p in DSP_IN for _, t, p in ld):
            dsp_in.add(n)
    dsp_in2 = set()
    for n, c in ffs.items():
        if n in dsp_in:
            continue
        ld = loads.get(q_bit(c), [])
        if len(ld) == 1 and ld[0][0] in dsp_in:
            dsp_in2.add(n)
    dsp_out, ram_out = set(), set()
    for n, c in ffs.items():
        drv = driver.get(d_bit(c))
        if drv is None or len(loads.get(d_bit(c), [])) != 1:
            continue
        _, t, p = drv
        if t in DSP_TYPES and p == "P":
            dsp_out.add(n)
        elif t.startswith("RAMB") and p in RAM_DO:
            ram_out.add(n)
    n_ff = len(ffs)
    packed = len(dsp_in) + len(dsp_in2) + len(dsp_out) + len(ram_out)
    cells = defaultdict(int)
    for c in m["cells"].values():
        cells[c["type"]] += 1
    return {"netlist": path, "ff": n_ff, "dsp_in": len(dsp_in), "dsp_in2": len(dsp_in2),
            "dsp_out": len(dsp_out), "ram_out": len(ram_out), "packable": packed,
            "fabric_after": n_ff - packed,
            "dsp48e": cells["DSP48E"], "ramb": sum(v for k, v in cells.items() if k.startswith("RAMB"))}


def main(argv=None) -> int:
    paths = (argv if argv is not None else sys.argv[1:])
    if not paths or any(p.startswith("-") for p in paths):
        print("usage: python scripts/xst_pack_estimate.py NETLIST.json ...", file=sys.stderr)
        return 2
    tot = defaultdict(int)
    for p in paths:
        try:
            r = estimate(p)
        except (OSError, ValueError, KeyError) as e:
            print(f"xst_pack_estimate: {p}: {e}", file=sys.stderr)
            return 2
        print(f"{p}: {r['ff']} FF; packable into DSP48E inputs {r['dsp_in']} + {r['dsp_in2']} "
              f"(second stage), outputs {r['dsp_out']}, RAMB outputs {r['ram_out']} -> "
              f"{r['fabric_after']} in the fabric ({r['dsp48e']} DSP48E, {r['ramb']} RAMB)")
        for k in ("ff", "packable", "fabric_after"):
            tot[k] += r[k]
    if len(paths) > 1:
        print(f"total: {tot['ff']} FF, {tot['packable']} packable, {tot['fabric_after']} in the fabric")
    return 0


if __name__ == "__main__":
    sys.exit(main())
