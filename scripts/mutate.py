#!/usr/bin/env python3
"""`make mutate`: do the tests catch a wrong rounding, tie or delay rule?

Each mutation below changes one rule of the RTL (a rounding constant, a tie order, a
boundary, a delay) in a throwaway copy of the checkout and runs the block's own test
(Icarus, one small parametrization).  A mutation is *caught* when that test fails (pytest
exit 1; a test that did not run, e.g. a node id that matches nothing, is an error).  The
script prints one line per mutation and exits 1 if any mutation survives (the test
missed a broken rule) or if a mutation no longer applies (its original text is not
found exactly once: the RTL moved on and the list must follow; `sim/tests/
test_mutate_list.py` checks that in `make test` without running any simulation).

    python scripts/mutate.py [--only NAME ...] [--list] [--keep] [--baseline]

--baseline also runs each test on the unmutated copy first (it must pass: otherwise a
"caught" would mean nothing).  The copy holds the working tree's tracked and untracked
(not ignored) files, so uncommitted edits are tested as they are.  About 1-3 minutes per
mutation on this machine (each builds its simulation from scratch).
"""
from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

# name: (file, original text, mutated text, pytest node under tb/, the rule it breaks)
MUTATIONS = {
    "flatten_round_half_down": (
        "rtl/fmt_flatten.v",
        "wire [P_W-1:0] rnd = p4_q[c*P_W +: P_W] + HALF;",
        "wire [P_W-1:0] rnd = p4_q[c*P_W +: P_W] + HALF - 1'b1;",
        "fmt_flatten/test_fmt_flatten.py::test_fmt_flatten[icarus-SMALL]",
        "gain product rounded half up (an exact half rounds down instead)"),
    "magnitude_round_half_down": (
        "rtl/fmt_magnitude.v",
        "x_fin} << (GAIN_BITS - 1)) + round_w;",
        "x_fin} << (GAIN_BITS - 1)) + round_w - 1'b1;",
        "fmt_magnitude/test_fmt_magnitude.py::test_fmt_magnitude[icarus-19]",
        "CORDIC gain compensation rounded half up"),
    "magnitude_cordic_no_carry": (
        "rtl/fmt_magnitude.v",
        "x_n = x_q[i] + (ys ^ {IW{neg}}) + {{(IW-1){1'b0}}, neg};",
        "x_n = x_q[i] + (ys ^ {IW{neg}});",
        "fmt_magnitude/test_fmt_magnitude.py::test_fmt_magnitude[icarus-19]",
        "a CORDIC subtraction adds the inverted operand plus one (x - ys exactly)"),
    "dds_negative_rounding": (
        "rtl/fmt_dds_chan.v",
        "rnd_w = (SH > 0) ? HALF - {{(PW - 1){1'b0}}, sg2_q} : {PW{1'b0}};",
        "rnd_w = (SH > 0) ? HALF : {PW{1'b0}};",
        "fmt_dds_bank/test_fmt_dds_bank.py::test_fmt_dds_bank[icarus-small-r3]",
        "a PN-inverted word is the exact negative of the plain one"),
    "pn_rx_delay_off_by_one": (
        "rtl/fmt_pn_gen.v",
        ": history_q[rx_delay_i - 1'b1];",
        ": history_q[rx_delay_i];",
        "fmt_pn_gen/test_fmt_pn_gen.py::test_fmt_pn_gen[icarus-7]",
        "the receive sign is the transmit sign rx_delay samples earlier"),
    "rx_mean_round_down": (
        "rtl/fmt_rx_array.v",
        "+ ({{(T-MC_W){1'b0}}, b_m} << MAG_FRAC);",
        "+ {T{1'b0}};",
        "fmt_rx_array/test_fmt_rx_array.py::test_fmt_rx_array[icarus-small-3]",
        "heat-map cell = floor((sum + M F) / 2MF), round half up of the mean"),
    "magnitude_frac_rounded": (
        "rtl/fmt_magnitude.v",
        "<< (SH - 1)) : {PW{1'b0}};",
        "<< (SH - 1)) : ({{(PW-1){1'b0}}, 1'b1} << (SH - FRAC - 1));",
        "fmt_magnitude/test_fmt_magnitude.py::test_fmt_magnitude[icarus-21_frac2]",
        "magnitudes with fractional bits truncated, not rounded (the cell is the one rounding)"),
    "blob_peak_tie_last": (
        "rtl/fmt_blob.v",
        "y_peak = ({y[O_PEAK +: HM_W], ~y[O_PR +: ROW_IDX_W], ~y[O_PC +: COL_IDX_W]} >\n"
        "                      {x[O_PEAK +: HM_W], ~x[O_PR +: ROW_IDX_W], ~x[O_PC +: COL_IDX_W]});",
        "y_peak = ({y[O_PEAK +: HM_W], y[O_PR +: ROW_IDX_W], y[O_PC +: COL_IDX_W]} >\n"
        "                      {x[O_PEAK +: HM_W], x[O_PR +: ROW_IDX_W], x[O_PC +: COL_IDX_W]});",
        "fmt_blob/test_fmt_blob.py::test_fmt_blob[icarus-small]",
        "a blob's peak is its first cell (raster order) holding the largest z"),
    "blob_centroid_round_down": (
        "rtl/fmt_blob.v",
        "wire [NUM_W-1:0] num_x = {{(NUM_W-SX_W-8){1'b0}}, em_sx, 8'd0}\n"
        "                           + {{(NUM_W-SZ_W+1){1'b0}}, em_sz[SZ_W-1:1]};",
        "wire [NUM_W-1:0] num_x = {{(NUM_W-SX_W-8){1'b0}}, em_sx, 8'd0};",
        "fmt_blob/test_fmt_blob.py::test_fmt_blob[icarus-small]",
        "blob centroid = (sum z*c * 256 + sum z / 2) / sum z, round half up"),
    "interp_offset_round_down": (
        "rtl/fmt_interp.v",
        "wire [QW:0] qx1 = {1'b0, qx} + 1'b1;",
        "wire [QW:0] qx1 = {1'b0, qx};",
        "fmt_interp/test_fmt_interp.py::test_fmt_interp[icarus-small]",
        "fit offset = round half up of the 9-bit quotient"),
    "interp_clamp_boundary": (
        "rtl/fmt_interp.v",
        "wire clx = ~s18_ex & (ovx | (qx >= 257));",
        "wire clx = ~s18_ex & (ovx | (qx >= 258));",
        "fmt_interp/test_fmt_interp.py::test_fmt_interp[icarus-small]",
        "an offset of 257/512 cell or more is clamped to 0.5 cell"),
    "tracker_gate_strict": (
        "rtl/fmt_tracker.v",
        "dgt = {1'b0, dq_q[s_i*KW +: DW]} + {1'b0, ~gate_q[s_i*16 +: 16]};",
        "dgt = {1'b0, dq_q[s_i*KW +: DW]} + {1'b0, ~gate_q[s_i*16 +: 16]} + 1'b1;",
        "fmt_tracker/test_fmt_tracker.py::test_fmt_tracker[icarus-small-5]",
        "a touch at distance D <= gate (equal included) is a match candidate"),
    "tracker_gate_no_growth": (
        "rtl/fmt_tracker.v",
        "wire [16:0]      e2_gs = {1'b0, e2_g_q} + {1'b0, gate_step_i};",
        "wire [16:0]      e2_gs = {1'b0, e2_g_q};",
        "fmt_tracker/test_fmt_tracker.py::test_fmt_tracker[icarus-small-5]",
        "the gate of a contact in hold-off grows by gate_step per frame missed"),
    "tracker_confirm_late": (
        "rtl/fmt_tracker.v",
        "sc_all[s_i*5 +: 5] = {tent_q[s_i], s1 >= confirm_i, s1};",
        "sc_all[s_i*5 +: 5] = {tent_q[s_i], s1 > confirm_i, s1};",
        "fmt_tracker/test_fmt_tracker.py::test_fmt_tracker[icarus-small-5]",
        "a new contact is reported in the frame it is seen for the confirm_frames-th time"),
}


def copy_tree(dst: Path) -> None:
    """The working tree's tracked and untracked, not ignored files (no build, no .venv)."""
    files = subprocess.run(["git", "ls-files", "-z", "-co", "--exclude-standard"], cwd=ROOT,
                           check=True, capture_output=True).stdout.decode().split("\0")
    for f in files:
        if not f:
            continue
        src = ROOT / f
        if not src.is_file():          # deleted in the working tree
            continue
        out = dst / f
        out.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(src, out)
    (dst / ".venv").symlink_to(ROOT / ".venv")


def apply(dst: Path, name: str) -> None:
    path, old, new = MUTATIONS[name][:3]
    p = dst / path
    text = p.read_text()
    n = text.count(old)
    if n != 1:
        raise SystemExit(f"mutate: {name}: the original text occurs {n} times in {path} "
                         f"(expected once): update scripts/mutate.py")
    p.write_text(text.replace(old, new))


def run_test(dst: Path, node: str, log: Path) -> int:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(dst), str(dst / "sim"), str(dst / "tb")])
    venv_bin = ROOT / ".venv" / "bin"
    env["PATH"] = f"{venv_bin}{os.pathsep}{env.get('PATH', '')}"
    with log.open("w") as fh:
        return subprocess.run([sys.executable, "-m", "pytest", "-q", "-x", "-p", "no:cacheprovider",
                               node], cwd=dst / "tb", env=env, stdout=fh,
                              stderr=subprocess.STDOUT).returncode


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--only", nargs="+", metavar="NAME", help="run these mutations only")
    ap.add_argument("--list", action="store_true", help="list the mutations and exit")
    ap.add_argument("--keep", action="store_true", help="keep the copies (printed) for a look")
    ap.add_argument("--baseline", action="store_true",
                    help="run each test unmutated first (must pass)")
    a = ap.parse_args()
    if a.list:
        for k, m in MUTATIONS.items():
            print(f"{k:28s} {m[0]:22s} {m[4]}")
        return 0
    names = a.only or list(MUTATIONS)
    bad = [n for n in names if n not in MUTATIONS]
    if bad:
        print(f"mutate: unknown mutation(s) {', '.join(bad)} (see --list)", file=sys.stderr)
        return 2
    logdir = ROOT / "build" / "mutate"
    logdir.mkdir(parents=True, exist_ok=True)
    survived, failed_base, errors = [], [], []
    for name in names:
        node = MUTATIONS[name][3]
        tmp = Path(tempfile.mkdtemp(prefix=f"fmt_mut_{name}_"))
        try:
            copy_tree(tmp)
            t0 = time.time()
            if a.baseline:
                rc0 = run_test(tmp, node, logdir / f"{name}.baseline.log")
                if rc0 != 0:
                    failed_base.append(name)
                    print(f"{name:28s} BASELINE FAILED (build/mutate/{name}.baseline.log)", flush=True)
                    continue
                shutil.rmtree(tmp / "build", ignore_errors=True)
            apply(tmp, name)
            rc = run_test(tmp, node, logdir / f"{name}.log")
            # pytest: 1 = a test failed; 2-5 = interrupted, internal or usage error, no
            # test collected (e.g. a wrong node id): nothing was checked, not a catch
            verdict = {0: "SURVIVED", 1: "caught"}.get(rc, f"ERROR({rc})")
            if rc == 0:
                survived.append(name)
            elif rc != 1:
                errors.append(name)
            print(f"{name:28s} {verdict:8s} {time.time() - t0:6.0f} s  {node}", flush=True)
        finally:
            if a.keep:
                print(f"  copy kept: {tmp}")
            else:
                shutil.rmtree(tmp, ignore_errors=True)
    n_caught = len(names) - len(survived) - len(failed_base) - len(errors)
    print(f"mutate: {n_caught} of {len(names)} caught"
          + (f"; survived: {', '.join(survived)}" if survived else "")
          + (f"; baseline failed: {', '.join(failed_base)}" if failed_base else "")
          + (f"; test did not run (see build/mutate/<name>.log): {', '.join(errors)}"
             if errors else ""))
    return 1 if survived or failed_base or errors else 0


if __name__ == "__main__":
    sys.exit(main())
