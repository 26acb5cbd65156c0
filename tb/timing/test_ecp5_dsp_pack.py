"""scripts/ecp5_dsp_pack.py: the MULT18X18D register packing keeps the netlist's function.

A small design (registered operands with and without clock enables, one operand shared by
two multipliers, a product with and without a clock enable, a 24 x 16 product that Yosys
splits into partial products summed in LUTs, a multiplier fed straight from a port, one
with a constant operand) is
mapped by `synth_ecp5`, packed, and the netlists before and after are simulated beside the
RTL on random inputs (Icarus; Yosys's ECP5 cell models, and tb/timing/mult18x18d_model.v
for the multiplier, a behavioural model written here).  Every output must agree in every
cycle, and the pass must have packed what the rules allow and left what they refuse.
"""
from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))
import ecp5_dsp_pack  # noqa: E402
import timing  # noqa: E402

WORK = ROOT / "build" / "timing" / "unit" / "dsp_pack"
HERE = Path(__file__).resolve().parent

DUT = r"""
`default_nettype none
module dsp_t (
    input  wire               clk,
    input  wire               ce,
    input  wire signed [15:0] a_i,
    input  wire signed [15:0] b_i,
    input  wire signed [13:0] c_i,
    input  wire signed [23:0] w_i,
    input  wire signed [11:0] u_i,
    input  wire signed [11:0] v_i,
    output reg  signed [31:0] p1_o,   // a * b: operands and product with ce
    output reg  signed [29:0] p2_o,   // a * c: a shared with p1, product without ce
    output reg  signed [39:0] p3_o,   // w * b: partial products summed in LUTs
    output reg  signed [23:0] p4_o,   // u * v straight from the ports
    output reg  signed [33:0] p5_o    // a * a constant
);
    reg signed [15:0] a_q, b_q;
    reg signed [13:0] c_q;
    reg signed [23:0] w_q;
    always @(posedge clk) begin
        if (ce) begin
            a_q <= a_i;
            b_q <= b_i;
        end
        c_q <= c_i;
        w_q <= w_i;
        if (ce) p1_o <= a_q * b_q;
        p2_o <= a_q * c_q;
        p3_o <= w_q * b_q;
        p4_o <= u_i * v_i;
        p5_o <= a_q * 18'sd93217;
    end
endmodule
`default_nettype wire
"""

TB = r"""
`timescale 1ns/1ps
`default_nettype none
module tb;
    reg clk = 1'b0, ce = 1'b0;
    reg signed [15:0] a = 0, b = 0;
    reg signed [13:0] c = 0;
    reg signed [23:0] w = 0;
    reg signed [11:0] u = 0, v = 0;
    wire [31:0] r1, o1, k1;
    wire [29:0] r2, o2, k2;
    wire [39:0] r3, o3, k3;
    wire [23:0] r4, o4, k4;
    wire [33:0] r5, o5, k5;
    dsp_t      ref_ (.clk(clk), .ce(ce), .a_i(a), .b_i(b), .c_i(c), .w_i(w), .u_i(u), .v_i(v),
                     .p1_o(r1), .p2_o(r2), .p3_o(r3), .p4_o(r4), .p5_o(r5));
    dsp_orig   orig (.clk(clk), .ce(ce), .a_i(a), .b_i(b), .c_i(c), .w_i(w), .u_i(u), .v_i(v),
                     .p1_o(o1), .p2_o(o2), .p3_o(o3), .p4_o(o4), .p5_o(o5));
    dsp_packed pack (.clk(clk), .ce(ce), .a_i(a), .b_i(b), .c_i(c), .w_i(w), .u_i(u), .v_i(v),
                     .p1_o(k1), .p2_o(k2), .p3_o(k3), .p4_o(k4), .p5_o(k5));
    integer i, bad = 0, seed = 7;
    always #5 clk = ~clk;
    initial begin
        // registers of the three designs start from different values: compare after the
        // first cycles that load every register (ce is forced high there)
        for (i = 0; i < 600; i = i + 1) begin
            @(negedge clk);
            ce = (i < 4) ? 1'b1 : $random(seed);
            a = $random(seed); b = $random(seed); c = $random(seed);
            w = $random(seed); u = $random(seed); v = $random(seed);
            if (i >= 6 && ({r1, r2, r3, r4, r5} !== {o1, o2, o3, o4, o5} || {r1, r2, r3, r4, r5} !== {k1, k2, k3, k4, k5})) begin
                bad = bad + 1;
                if (bad < 5) $display("MISMATCH cycle %0d: ref %h %h %h %h orig %h %h %h %h packed %h %h %h %h",
                                      i, r1, r2, r3, r4, o1, o2, o3, o4, k1, k2, k3, k4);
            end
        end
        $display("DONE bad=%0d", bad);
        $finish;
    end
endmodule
`default_nettype wire
"""


@pytest.mark.skipif(shutil.which("iverilog") is None, reason="needs Icarus Verilog")
def test_pack_keeps_function():
    WORK.mkdir(parents=True, exist_ok=True)
    (WORK / "dsp_t.v").write_text(DUT)
    orig = WORK / "orig.json"
    timing.yosys(f"read_verilog {timing.rel(WORK / 'dsp_t.v')}; synth_ecp5 -top dsp_t -json {timing.rel(orig)}",
                 WORK / "synth.log", "yosys synth_ecp5 (dsp_t)")
    nl = json.loads(orig.read_text())
    mults = [c for c in nl["modules"]["dsp_t"]["cells"].values() if c["type"] == "MULT18X18D"]
    assert len(mults) >= 4
    st = ecp5_dsp_pack.pack(nl, "dsp_t")
    packed = WORK / "packed.json"
    packed.write_text(json.dumps(nl))
    # p1 and p2: both operands from flip-flops and a flip-flop on the product: packed;
    # p4's operands come from ports (product packed, operands not); p3's partial
    # products go through LUT adders (operands packed, products not)
    assert st["packed_out"] >= 3, st
    assert st["packed_in"] >= 2, st
    assert st["packed_in"] < st["mults"], st
    cells = nl["modules"]["dsp_t"]["cells"]
    for c in cells.values():
        if c["type"] == "MULT18X18D" and c["parameters"].get("REG_INPUTA_CLK") == "CLK0":
            assert c["parameters"]["REG_INPUTB_CLK"] == "CLK0"      # both operands or neither
    # both netlists flattened into plain Verilog by Yosys with the ECP5 cell models (which
    # Icarus cannot parse itself) and the multiplier model, renamed
    for js, name in ((orig, "dsp_orig"), (packed, "dsp_packed")):
        timing.yosys(f"read_json {timing.rel(js)}; hierarchy -top dsp_t; "
                     f"techmap -autoproc -map +/ecp5/cells_sim.v -map {timing.rel(HERE / 'mult18x18d_model.v')}; "
                     f"opt_clean; rename dsp_t {name}; write_verilog -noattr {timing.rel(WORK / (name + '.v'))}",
                     WORK / f"{name}.log", f"yosys write_verilog ({name})")
    (WORK / "tb.v").write_text(TB)
    vvp = WORK / "tb.vvp"
    subprocess.run(["iverilog", "-g2005", "-o", str(vvp), "-s", "tb",
                    str(WORK / "tb.v"), str(WORK / "dsp_t.v"), str(WORK / "dsp_orig.v"),
                    str(WORK / "dsp_packed.v")], check=True, capture_output=True, text=True)
    out = subprocess.run(["vvp", "-n", str(vvp)], check=True, capture_output=True, text=True).stdout
    assert "DONE bad=0" in out, out[-2000:]


def test_pack_refuses_reset_and_signed_pins():
    """A product register with a reset is not packed; a non-constant SIGNEDA stops the pass
    for that multiplier."""
    nl = {"modules": {"t": {"attributes": {"top": "1"}, "cells": {
        "m": {"type": "MULT18X18D", "parameters": {},
              "port_directions": {**{f"A{i}": "input" for i in range(18)},
                                  **{f"B{i}": "input" for i in range(18)},
                                  **{f"P{i}": "output" for i in range(36)},
                                  "SIGNEDA": "input", "SIGNEDB": "input"},
              "connections": {**{f"A{i}": [10 + i] for i in range(18)},
                              **{f"B{i}": ["0"] for i in range(18)},
                              **{f"P{i}": [100 + i] for i in range(36)},
                              "SIGNEDA": ["1"], "SIGNEDB": ["1"]}},
        "r": {"type": "TRELLIS_FF",
              "parameters": {"CEMUX": "1 ", "CLKMUX": "CLK", "GSR": "DISABLED", "LSRMUX": "LSR",
                             "REGSET": "RESET", "SRMODE": "LSR_OVER_CE"},
              "port_directions": {"CLK": "input", "DI": "input", "LSR": "input", "Q": "output"},
              "connections": {"CLK": [2], "DI": [100], "LSR": [3], "Q": [200]}}}}}}
    st = ecp5_dsp_pack.pack(nl)
    assert st == {"mults": 1, "packed_in": 0, "packed_out": 0, "ffs_removed": 0}
    nl["modules"]["t"]["cells"]["r"]["connections"]["LSR"] = ["0"]
    nl["modules"]["t"]["cells"]["m"]["connections"]["SIGNEDA"] = [5]
    st = ecp5_dsp_pack.pack(nl)
    assert st["packed_out"] == 0
    nl["modules"]["t"]["cells"]["m"]["connections"]["SIGNEDA"] = ["1"]
    st = ecp5_dsp_pack.pack(nl)
    assert st["packed_out"] == 1 and "r" not in nl["modules"]["t"]["cells"]
    assert nl["modules"]["t"]["cells"]["m"]["connections"]["P0"] == [200]


def test_pack_keeps_ram_output_register():
    """An operand flip-flop loaded from a block RAM's read data stays in the fabric (the
    RAM's output register); so does the other operand (both or neither)."""
    ff = {"CEMUX": "1 ", "CLKMUX": "CLK", "GSR": "DISABLED", "LSRMUX": "LSR", "REGSET": "RESET"}
    ffdir = {"CLK": "input", "DI": "input", "LSR": "input", "Q": "output"}
    cells = {
        "m": {"type": "MULT18X18D", "parameters": {},
              "port_directions": {**{f"A{i}": "input" for i in range(18)},
                                  **{f"B{i}": "input" for i in range(18)},
                                  **{f"P{i}": "output" for i in range(36)}},
              "connections": {**{f"A{i}": [10] for i in range(18)},
                              **{f"B{i}": [11] for i in range(18)},
                              **{f"P{i}": ["x"] for i in range(36)}}},
        "ra": {"type": "TRELLIS_FF", "parameters": ff, "port_directions": ffdir,
               "connections": {"CLK": [2], "DI": [20], "LSR": ["0"], "Q": [10]}},
        "rb": {"type": "TRELLIS_FF", "parameters": ff, "port_directions": ffdir,
               "connections": {"CLK": [2], "DI": [21], "LSR": ["0"], "Q": [11]}},
        "ram": {"type": "DP16KD", "parameters": {}, "port_directions": {"DOA0": "output"},
                "connections": {"DOA0": [20]}}}
    nl = {"modules": {"t": {"attributes": {"top": "1"}, "cells": cells}}}
    st = ecp5_dsp_pack.pack(nl)
    assert st["packed_in"] == 0 and "ra" in cells and "rb" in cells
    cells["ram"]["connections"]["DOA0"] = [99]              # no longer the RAM's data
    st = ecp5_dsp_pack.pack(nl)
    assert st["packed_in"] == 1 and "ra" not in cells and "rb" not in cells
    assert cells["m"]["connections"]["A0"] == [20] and cells["m"]["connections"]["B0"] == [21]


def test_cli_refuses_a_bad_netlist(tmp_path, capsys):
    """One line and exit status 2 for a file that is not JSON or has no top module; the
    file is left as it was."""
    bad = tmp_path / "bad.json"
    for text in ("not json", '{"modules": {}}'):
        bad.write_text(text)
        assert ecp5_dsp_pack.main([str(bad)]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and err[0].startswith("ecp5_dsp_pack: ")
        assert bad.read_text() == text
