"""Tests of scripts/timing.py (`make timing`).

- the depth walker against hand-built netlists whose answer is known by construction
  (LUT levels, carry bits, the LUT-RAM rule, DSP48E / block-RAM registration flags);
- the walker on small modules mapped by Yosys (synth_xilinx -family xc5v), checked
  against bounds that follow from the logic, not from the walker: a function of 40
  register bits needs at least 3 levels of 6-input LUTs; a 16-bit adder is one 16-bit
  carry chain;
- the whole flow (wrapper, synth_ecp5, nextpnr-ecp5, xc5v walk) on the two small
  blocks marked "smoke" in scripts/timing_blocks.json, which close 125 MHz today.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))
import timing  # noqa: E402

WORK = ROOT / "build" / "timing" / "unit"


# ---- hand-built netlists ------------------------------------------------------------------
class Net:
    """A tiny Yosys-JSON netlist builder: bits are ints, cells get port directions."""

    def __init__(self):
        self.n = 1
        self.cells = {}
        self.ports = {}
        self.names = {}

    def bit(self, name=None):
        self.n += 1
        if name:
            self.names[name] = {"bits": [self.n]}
        return self.n

    def cell(self, name, typ, ins: dict, outs: dict):
        conn = {**{k: v if isinstance(v, list) else [v] for k, v in ins.items()},
                **{k: v if isinstance(v, list) else [v] for k, v in outs.items()}}
        pd = {**{k: "input" for k in ins}, **{k: "output" for k in outs}}
        self.cells[name] = {"type": typ, "connections": conn, "port_directions": pd}

    def ff(self, name, d, clk):
        q = self.bit(name)
        self.cell(name + "_reg", "FDRE", {"C": clk, "D": d, "CE": "1", "R": "0"}, {"Q": q})
        return q

    def lut(self, name, ins: list):
        o = self.bit()
        typ = f"LUT{len(ins)}"
        self.cell(name, typ, {f"I{i}": b for i, b in enumerate(ins)}, {"O": o})
        return o

    def json(self):
        return {"modules": {"w": {"attributes": {"top": "00000000000000000000000000000001"},
                                  "ports": self.ports, "cells": self.cells,
                                  "netnames": self.names}}}


def test_walker_lut_chain_and_carry():
    n = Net()
    clk = n.bit("clk")
    n.ports["clk"] = {"direction": "input", "bits": [clk]}
    src = [n.ff(f"r{i}", n.bit(), clk) for i in range(8)]
    # r* -> three chained LUT6 -> f3_q: 3 levels
    f1 = n.lut("f1", src[:6])
    f2 = n.lut("f2", [f1] + src[1:6])
    f3 = n.lut("f3", [f2] + src[2:7])
    n.ff("f3_q", f3, clk)
    # a 3-cell CARRY4 chain fed by one LUT level: S from LUT2, CI chained: 12 bits
    ci = "0"
    last_o = None
    for k in range(3):
        s = [n.lut(f"s{k}_{j}", [src[j], src[j + 1]]) for j in range(4)]
        co = [n.bit() for _ in range(4)]
        o = [n.bit() for _ in range(4)]
        n.cell(f"cy{k}", "CARRY4", {"CI": ci, "CYINIT": "0", "S": s, "DI": ["0"] * 4},
               {"CO": co, "O": o})
        ci = co[3]
        last_o = o[3]
    n.ff("sum_q", last_o, clk)
    r = timing.depth_walk(n.json(), "w")
    assert r["worst_lut_levels"] == 3
    assert r["worst_from"].startswith("FDRE r") and r["worst_to"] == "FDRE f3_q (D)"
    assert r["worst_carry"] == 12
    assert r["carry_to"] == "FDRE sum_q (D)"
    assert r["comb_loops"] == 0 and r["unknown_cells"] == []
    # the estimate with the script's figures: clk-to-q, 3 x (logic + route), last hop, setup
    ns = timing.VIRTEX5_NS
    lut3 = ns["ff_clk_q"] + 3 * (ns["lut_logic"] + ns["route"]) + ns["route"] + ns["ff_setup"]
    carry = (ns["ff_clk_q"] + ns["lut_logic"] + ns["route"] + ns["carry_enter"]
             + 11 * ns["carry_bit"] + ns["route"] + ns["ff_setup"])
    assert r["est_ns"] == pytest.approx(round(max(lut3, carry), 2))


def test_abc_delay_hand_netlist():
    """scripts/abc_delay.py: arrivals by the ABC9 arcs of Yosys's xc5v cell library (hand
    values from its cells_sim.v specify blocks: LUT2 I0 -> O 238 ps, I1 -> O 127 ps;
    CARRY4 S[0] -> CO[3] 508 ps, CI -> O[0] 222 ps)."""
    import abc_delay
    n = Net()
    clk = n.bit("clk")
    n.ports["clk"] = {"direction": "input", "bits": [clk]}
    r0, r1 = n.ff("r0", n.bit(), clk), n.ff("r1", n.bit(), clk)
    # r0 -> LUT2 (I0) -> LUT2 (I1) -> a_q: 238 + 127 = 365
    l1 = n.lut("l1", [r0, r1])
    l2 = n.lut("l2", [r1, l1])
    n.ff("a_q", l2, clk)
    # r0 -> CARRY4 S[0] -> CO[3] -> CARRY4 CI -> O[0] -> b_q: 508 + 222 = 730
    co0, o0 = [n.bit() for _ in range(4)], [n.bit() for _ in range(4)]
    n.cell("cy0", "CARRY4", {"CI": "0", "CYINIT": "0", "S": [r0, "0", "0", "0"], "DI": ["0"] * 4},
           {"CO": co0, "O": o0})
    co1, o1 = [n.bit() for _ in range(4)], [n.bit() for _ in range(4)]
    n.cell("cy1", "CARRY4", {"CI": co0[3], "CYINIT": "0", "S": ["0"] * 4, "DI": ["0"] * 4},
           {"CO": co1, "O": o1})
    n.ff("b_q", o1[0], clk)
    ends, names, describe, cells = abc_delay.walk(n.json(), abc_delay.cell_arcs(abc_delay.find_cells_sim()))
    by_q = {}
    for e in ends:
        q = cells[e[1]]["connections"].get("Q", [None])[0]
        if e[2] == "D":
            by_q[names.get(q)] = e
    assert by_q["a_q"][0] == 365 and by_q["b_q"][0] == 730
    assert ends[0][0] == 730 and "1 LUT levels" not in describe(ends[0])
    assert " 2 LUT levels,  0 CARRY4  r0 -> a_q" in describe(by_q["a_q"])
    assert " 0 LUT levels,  2 CARRY4  r0 -> b_q" in describe(by_q["b_q"])


def test_walker_ports_lutram_dsp_bram():
    n = Net()
    clk = n.bit("clk")
    a = n.bit("a")
    n.ports["clk"] = {"direction": "input", "bits": [clk]}
    n.ports["a"] = {"direction": "input", "bits": [a]}
    # port a -> LUT -> LUT-RAM read address -> LUT -> FF: LUT, LUT-RAM read, LUT = 3 levels
    adr = n.lut("adr", [a])
    spo, dpo = n.bit(), n.bit()
    n.cell("ram", "RAM64X1D", {"WCLK": clk, "WE": "1", "D": "0",
                               **{f"A{i}": "0" for i in range(6)},
                               "DPRA0": adr, **{f"DPRA{i}": "0" for i in range(1, 6)}},
           {"SPO": spo, "DPO": dpo})
    n.ff("ram_q", n.lut("after", [dpo]), clk)
    # DSP48E: A from a LUT (unregistered operand), P[0] into an FF, P[1] into a LUT
    r0 = n.ff("op_q", "0", clk)
    p0, p1 = n.bit("p0"), n.bit("p1")
    n.cell("dsp", "DSP48E", {"CLK": clk, "A": [n.lut("opl", [r0])], "B": [r0]}, {"P": [p0, p1]})
    n.ff("p0_q", p0, clk)
    n.ff("p1_q", n.lut("pl", [p1]), clk)
    # DSP48E registered both sides: no flag
    q0 = n.bit("q0")
    n.cell("dsp_ok", "DSP48E", {"CLK": clk, "A": [r0], "B": [r0]}, {"P": [q0]})
    n.ff("q0_q", q0, clk)
    # DSP48E whose P goes through an adder (LUT2 with a flip-flop operand, CARRY4) into
    # flip-flops: the multiply-add XST packs into the DSP48E (P = A*B + C): no flag
    m0 = n.bit("m0")
    n.cell("dsp_macc", "DSP48E", {"CLK": clk, "A": [r0], "B": [r0]}, {"P": [m0]})
    c_q = n.ff("c_q", "0", clk)
    s0 = n.lut("add_s0", [m0, c_q])
    o0 = n.bit()
    n.cell("add_cy", "CARRY4", {"CI": "0", "CYINIT": "0", "S": [s0, "0", "0", "0"],
                                "DI": [m0, "0", "0", "0"]}, {"O": [o0, n.bit(), n.bit(), n.bit()]})
    n.ff("macc_q", o0, clk)
    # RAMB36: DOA into an FF only (fine), DOB into a LUT (flag)
    da, db = n.bit("da"), n.bit("db")
    n.cell("bram", "RAMB36_EXP", {"CLKARDCLKL": clk, "ADDRA": [r0]}, {"DOA": [da], "DOB": [db]})
    n.ff("da_q", da, clk)
    n.ff("db_q", n.lut("dbl", [db]), clk)
    r = timing.depth_walk(n.json(), "w")
    assert r["worst_lut_levels"] == 3
    assert r["worst_from"] == "port a[0]" and r["worst_to"] == "FDRE ram_q (D)"
    assert r["n_dsp"] == 3 and r["n_bram"] == 1
    assert len(r["unregistered_dsp"]) == 1
    assert "A/B from LUT1" in r["unregistered_dsp"][0] and "P into LUT1" in r["unregistered_dsp"][0]
    assert r["dsp_post_add"] == ["DSP48E m0"]
    assert len(r["unregistered_bram"]) == 1 and "db" in r["unregistered_bram"][0]
    assert "read data into LUT1" in r["unregistered_bram"][0]


# ---- the walker on Yosys-mapped modules ---------------------------------------------------
WALK_V = """
`default_nettype none
module walk_t (
    input  wire        clk,
    input  wire [39:0] x_i,
    input  wire [15:0] a_i,
    input  wire [15:0] b_i,
    output reg         p_o,
    output reg         f_o,
    output reg  [15:0] s_o
);
    reg [39:0] x_q;
    reg [15:0] a_q, b_q;
    // three chained LUT6 instances (Xilinx primitives, kept as they are): 3 levels
    wire f1, f2, f3;
    LUT6 #(.INIT(64'h6996966996696996)) u1 (.O(f1), .I0(x_q[0]), .I1(x_q[1]), .I2(x_q[2]),
                                            .I3(x_q[3]), .I4(x_q[4]), .I5(x_q[5]));
    LUT6 #(.INIT(64'h6996966996696996)) u2 (.O(f2), .I0(f1), .I1(x_q[6]), .I2(x_q[7]),
                                            .I3(x_q[8]), .I4(x_q[9]), .I5(x_q[10]));
    LUT6 #(.INIT(64'h6996966996696996)) u3 (.O(f3), .I0(f2), .I1(x_q[11]), .I2(x_q[12]),
                                            .I3(x_q[13]), .I4(x_q[14]), .I5(x_q[15]));
    always @(posedge clk) begin
        x_q <= x_i;
        a_q <= a_i;
        b_q <= b_i;
        p_o <= ^x_q;          // 40-input parity: >= 3 levels of 6-input LUTs
        f_o <= f3;
        s_o <= a_q + b_q;     // one 16-bit carry chain
    end
endmodule
`default_nettype wire
"""


def _netlist(name: str, src: str, script) -> dict:
    """``src`` written to WORK/<name>.v, mapped by Yosys with ``script(path of the .v)``
    (the commands before write_json), the JSON netlist loaded."""
    WORK.mkdir(parents=True, exist_ok=True)
    v = WORK / f"{name}.v"
    v.write_text(src)
    js = WORK / f"{name}.json"
    timing.yosys(f"{script(timing.rel(v))}write_json {timing.rel(js)}", WORK / f"{name}.log",
                 f"yosys {name}")
    return json.loads(js.read_text())


def test_walker_on_yosys_netlist():
    nl = _netlist("walk_t", WALK_V, lambda v: "read_verilog -lib +/xilinx/cells_sim.v; "
                  f"read_verilog {v}; synth_xilinx -family xc5v -top walk_t -noiopad; ")
    r = timing.depth_walk(nl, "walk_t")
    # 6^2 = 36 < 40 inputs: the parity needs at least 3 LUT6 levels (ABC's area mapping
    # may use more); no path of this module is deeper than the parity's
    assert r["worst_lut_levels"] >= 3
    assert "x_q" in r["worst_from"] and "p_o" in r["worst_to"]
    # the kept chain alone: cut the parity and the adder out, exactly 3 levels remain
    m = nl["modules"]["walk_t"]
    p_bits = set(m["ports"]["p_o"]["bits"]) | set(m["ports"]["s_o"]["bits"])
    m["cells"] = {n: c for n, c in m["cells"].items()
                  if not (c["type"].startswith("FD") and c["connections"]["Q"][0] in p_bits)}
    r3 = timing.depth_walk(nl, "walk_t")
    assert r3["worst_lut_levels"] == 3 and "f_o" in r3["worst_to"]
    # a_q + b_q: bit 0 enters at S[0], the sum's bit 15 leaves at O[3] of the 4th CARRY4
    assert r["worst_carry"] == 16
    assert "s_o" in r["carry_to"]
    assert r["unknown_cells"] == [] and r["comb_loops"] == 0


HIER_V = """`default_nettype none
module hier_c (input wire clk, input wire [11:0] a_i, output reg p_o);
    reg [11:0] a_q;
    always @(posedge clk) begin
        a_q <= a_i;
        p_o <= ^a_q;
    end
endmodule
module hier_t (input wire clk, input wire [11:0] a_i, input wire b_i, output reg y_o);
    wire p;
    reg  b_q;
    hier_c u_c (.clk(clk), .a_i(a_i), .p_o(p));
    always @(posedge clk) begin
        b_q <= b_i;
        y_o <= p ^ b_q;
    end
endmodule
"""


def test_walker_on_hierarchical_mapping():
    """"xc5v_hier": each module mapped on its own, then flattened: the walk sees the
    child's paths under its instance name and the path across the boundary."""
    nl = _netlist("hier_t", HIER_V, lambda v: f"read_verilog {v}; {timing.xc5v_mapping('hier_t', True)}")
    # flat after the mapping: no instance of the child is left (the rest are cell models)
    assert "hier_c" not in nl["modules"]
    m = nl["modules"]["hier_t"]
    assert not any(c["type"] == "hier_c" for c in m["cells"].values())
    assert "u_c.a_q" in m["netnames"] and "u_c.p_o" in m["netnames"]
    r = timing.depth_walk(nl, "hier_t")
    # a 12-input parity needs 2 levels of 6-input LUTs (the boundary path p -> y_o: 1)
    assert r["worst_lut_levels"] >= 2 and "u_c.a_q" in r["worst_from"]
    assert r["unknown_cells"] == [] and r["comb_loops"] == 0


# ---- the flow on two small blocks -----------------------------------------------------------
def test_timing_smoke():
    cfg = json.loads(timing.CFG.read_text())
    smoke = [b["label"] for b in cfg["blocks"] if b.get("smoke")]
    assert len(smoke) == 2
    env = dict(os.environ)
    r = subprocess.run([sys.executable, str(ROOT / "scripts" / "timing.py"), "--smoke",
                        "--report", "smoke_report.json"], cwd=ROOT, env=env,
                       capture_output=True, text=True, timeout=900)
    assert r.returncode == 0, r.stdout + r.stderr
    rep = json.loads((timing.OUT / "smoke_report.json").read_text())
    assert sorted(rep["blocks"]) == sorted(smoke)
    for lab in smoke:
        b = rep["blocks"][lab]
        e, x = b["ecp5"], b["xc5v"]
        assert e["fits"] and e["fmax_mhz"] >= 125.0 and e["pass"]
        assert e["crit_from"] and e["crit_to"] and e["lut4"] > 0 and e["ff"] > 0
        assert 1 <= x["worst_lut_levels"] <= 8 and x["worst_from"] and x["worst_to"]
        assert x["unregistered_dsp"] == [] and x["unregistered_bram"] == []
        assert x["est_ns"] > 0 and b["pass"]
    md = (timing.OUT / "smoke_TIMING.md").read_text()
    assert all(f"| {lab} |" in md for lab in smoke)
