"""Move multiplier operand and product flip-flops into the ECP5 MULT18X18D's own registers.

Yosys's `synth_ecp5` maps every multiplier to a MULT18X18D with its input, pipeline and
output registers off (REG_*_CLK = "NONE"); the registers the RTL writes around each
multiplier (fmt_fft_twiddle, fmt_magnitude, fmt_dds_chan, fmt_rx_array: registered
operands and a registered product, the form XST packs into a DSP48E) stay in the fabric.
nextpnr then times operand register -> route to the DSP column -> the multiplier's
combinational array (about 3 ns on -8) -> route back -> product register in one cycle, and
the result depends on where the placer puts the flip-flops.  Lattice's own synthesis packs
such registers into the block, and the xc5v check of `scripts/timing.py` assumes XST does
the same for DSP48E; this pass does it on the ECP5 netlist between Yosys and nextpnr, so
that the ECP5 figure measures the same structure.

Rules (the netlist is Yosys's JSON, the top module only):
* operands: every non-constant bit of A0..A17 and of B0..B17 comes from the Q of a
  TRELLIS_FF; those flip-flops share one clock (CLKMUX "CLK"), one clock enable (CEMUX
  "CE" with the same net, or "1": none) per operand, no set / reset (LSR constant 0) and
  GSR "DISABLED", and none is loaded straight from a RAM's read data (a block RAM's
  clock-to-out, ~4.1 ns without its output register, and the route to the DSP column
  would then share one cycle: the flip-flop stays, as the RAM's output register).  Then
  the pins take the flip-flops' D nets and REG_INPUTA_* /
  REG_INPUTB_* use CLK0 and CE0 / CE1; a flip-flop whose Q is left without a user is
  deleted (one shared by several multipliers is thus copied into each of them, as a
  vendor tool does).  nextpnr's timing model has a class for both operands registered,
  not for one: both operands are packed or neither.
* product: every used bit of P0..P35 drives exactly one thing, the D input of a
  TRELLIS_FF with the operands' clock, one clock enable, no set / reset, GSR "DISABLED".
  The flip-flops are deleted, their Q nets are driven by the P pins, and REG_OUTPUT_* use
  CLK0 and CE2.
* an operand of constant bits only counts as registered (its register holds the
  constant from the first clock edge on, one cycle of power-up state aside).
* SIGNEDA, SIGNEDB, SOURCEA and SOURCEB must be constants (a registered operand's sign
  would need its own register); the block's RST0 is tied to 0 and RESETMODE is "SYNC".
A multiplier that meets none of the rules is left as it is.

Functional check: tb/timing/test_ecp5_dsp_pack.py simulates a netlist before and after the
pass against its RTL (with a behavioural MULT18X18D model of tb/timing, not Lattice's).
"""
from __future__ import annotations

import argparse
import json
import sys
from collections import defaultdict
from pathlib import Path

A_BITS = [f"A{i}" for i in range(18)]
B_BITS = [f"B{i}" for i in range(18)]
P_BITS = [f"P{i}" for i in range(36)]
RAM_TYPES = ("DP16KD", "PDPW16KD", "TRELLIS_DPR16X4")


def _s(v) -> str:
    """A Yosys JSON string parameter (strings of only 0/1 carry a trailing space)."""
    return str(v).strip()


def _ff_ok(c: dict) -> bool:
    """A plain flip-flop: rising clock, no set / reset in use, no GSR."""
    if c["type"] != "TRELLIS_FF":
        return False
    p = c.get("parameters", {})
    return (_s(p.get("CLKMUX", "CLK")) == "CLK" and _s(p.get("GSR", "ENABLED")) == "DISABLED"
            and _s(p.get("CEMUX", "1")) in ("1", "CE")
            and c["connections"].get("LSR", ["0"]) in (["0"], [0]))


def _ff_clk_ce(c: dict):
    """(clock net, clock-enable net or '1') of a flip-flop."""
    p = c.get("parameters", {})
    ce = c["connections"].get("CE", ["1"])[0] if _s(p.get("CEMUX", "1")) == "CE" else "1"
    return c["connections"]["CLK"][0], ce


def pack(nl: dict, top: str | None = None) -> dict:
    """Pack in place; returns counts {mults, packed_in, packed_out, ffs_removed}."""
    if top is None:
        top = next((n for n, m in nl.get("modules", {}).items()
                    if int(m.get("attributes", {}).get("top", "0") or 0)), None)
        if top is None:
            raise ValueError("no module marked top in the netlist")
    cells = nl["modules"][top]["cells"]
    drv: dict = {}
    users: dict = defaultdict(list)
    for n, c in cells.items():
        dirs = c.get("port_directions", {})
        for p, bits in c["connections"].items():
            for i, b in enumerate(bits):
                if isinstance(b, str):
                    continue
                if dirs.get(p) == "output":
                    drv[b] = (n, p)
                else:
                    users[b].append((n, p, i))
    stats = {"mults": 0, "packed_in": 0, "packed_out": 0, "ffs_removed": 0}
    maybe_dead = set()
    removed = set()

    def drop(f):
        """Delete flip-flop f; its inputs lose it as a user."""
        for p2, bits in cells[f]["connections"].items():
            for bb in bits:
                if not isinstance(bb, str) and p2 != "Q":
                    users[bb] = [u for u in users[bb] if u[0] != f]
        del cells[f]
        removed.add(f)
        stats["ffs_removed"] += 1

    for n in sorted(cells):
        c = cells.get(n)
        if c is None or c["type"] != "MULT18X18D":
            continue
        stats["mults"] += 1
        par = c.setdefault("parameters", {})
        if any(_s(par.get(k, "NONE")) != "NONE"
               for k in ("REG_INPUTA_CLK", "REG_INPUTB_CLK", "REG_PIPELINE_CLK", "REG_OUTPUT_CLK")):
            continue
        con = c["connections"]
        if any(any(not isinstance(b, str) for b in con.get(k, ["0"]))
               for k in ("SIGNEDA", "SIGNEDB", "SOURCEA", "SOURCEB")):
            continue
        clk = None

        def operand(bits_names):
            nonlocal clk
            ffs, ce = [], None
            for pn in bits_names:
                for b in con.get(pn, []):
                    if isinstance(b, str):
                        continue
                    d = drv.get(b)
                    if d is None or d[1] != "Q" or d[0] in removed or not _ff_ok(cells[d[0]]):
                        return None
                    # a flip-flop loaded from a block RAM's read port stays in the fabric:
                    # moved into the multiplier, the RAM's slow clock-to-out (~4.1 ns, no
                    # output register) and the route to the DSP column would share a cycle
                    dd = drv.get(cells[d[0]]["connections"]["DI"][0])
                    if dd is not None and cells[dd[0]]["type"] in RAM_TYPES:
                        return None
                    fclk, fce = _ff_clk_ce(cells[d[0]])
                    if clk is not None and fclk != clk:
                        return None
                    if ce is not None and fce != ce:
                        return None
                    clk, ce = fclk, fce
                    ffs.append((pn, d[0]))
            # a constant operand (no flip-flop): its register holds the constant from the
            # first clock edge on
            return ffs, (ce if ffs else "1")

        clk_save = clk
        a = operand(A_BITS)
        b = operand(B_BITS) if a is not None else None
        if a is None or b is None or not (a[0] or b[0]):
            a = b = None
            clk = clk_save
        # the product register
        outs, oce = [], None
        ok_out = True
        for pn in P_BITS:
            for bit in con.get(pn, []):
                if isinstance(bit, str):
                    continue
                us = users.get(bit, [])
                if not us:
                    continue
                if len(us) != 1 or us[0][1] != "DI" or not _ff_ok(cells[us[0][0]]):
                    ok_out = False
                    break
                fclk, fce = _ff_clk_ce(cells[us[0][0]])
                if (clk is not None and fclk != clk) or (oce is not None and fce != oce):
                    ok_out = False
                    break
                clk, oce = fclk, fce
                outs.append((pn, us[0][0]))
            if not ok_out:
                break
        if not ok_out or not outs:
            outs = []
            if not a:
                continue
            clk = _ff_clk_ce(cells[(a[0] or b[0])[0][1]])[0]
        dirs = c.setdefault("port_directions", {})

        def wire(port, net):
            con[port] = [net]
            dirs[port] = "input"

        wire("CLK0", clk)
        wire("RST0", "0")
        par["RESETMODE"] = "SYNC"
        par["GSR"] = "DISABLED"
        if a:
            for (ffs, ce), key, cen in ((a, "A", "CE0"), (b, "B", "CE1")):
                for pn, f in ffs:
                    dnet = cells[f]["connections"]["DI"][0]
                    old = con[pn][0]
                    con[pn] = [dnet]
                    users[old] = [u for u in users[old] if u[0] != n]
                    if not isinstance(dnet, str):
                        users[dnet].append((n, pn, 0))
                    maybe_dead.add(f)
                wire(cen, ce)
                par[f"REG_INPUT{key}_CLK"] = "CLK0"
                par[f"REG_INPUT{key}_CE"] = cen
                par[f"REG_INPUT{key}_RST"] = "RST0"
            stats["packed_in"] += 1
        if outs:
            for pn, f in outs:
                q = cells[f]["connections"]["Q"][0]
                dn = cells[f]["connections"]["DI"][0]
                con[pn] = [q]
                drv[q] = (n, pn)
                users.pop(dn, None)
                drop(f)
            wire("CE2", oce)
            par["REG_OUTPUT_CLK"] = "CLK0"
            par["REG_OUTPUT_CE"] = "CE2"
            par["REG_OUTPUT_RST"] = "RST0"
            stats["packed_out"] += 1
    # operand flip-flops left without a user
    for f in sorted(maybe_dead):
        if f in removed or f not in cells:
            continue
        if not users.get(cells[f]["connections"]["Q"][0]):
            drop(f)
    # nets named in netnames but no longer driven are harmless for nextpnr (it builds nets
    # from the cells' connections)
    return stats


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("netlist", help="Yosys JSON netlist (synth_ecp5 -json), rewritten in place")
    ap.add_argument("--out", help="write here instead")
    a = ap.parse_args(argv)
    p = Path(a.netlist)
    try:
        nl = json.loads(p.read_text())
    except (OSError, ValueError) as e:
        print(f"ecp5_dsp_pack: cannot read {p}: {e}", file=sys.stderr)
        return 2
    try:
        st = pack(nl)
    except (ValueError, KeyError, TypeError, AttributeError) as e:
        print(f"ecp5_dsp_pack: {p} is not a synth_ecp5 netlist: {e}", file=sys.stderr)
        return 2
    out = Path(a.out) if a.out else p
    tmp = out.with_suffix(out.suffix + ".tmp")
    tmp.write_text(json.dumps(nl))
    tmp.replace(out)
    print(f"ecp5_dsp_pack: {st['mults']} MULT18X18D, operands packed in {st['packed_in']}, "
          f"products in {st['packed_out']}, {st['ffs_removed']} flip-flops removed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
