"""cocotb testbench of rtl/fmt_sorted_list.v against a Python list model.

Random operations every cycle (insert, pop, clear, idle, an occasional reset) with keys
and tie keys from small ranges, so equal keys and entries equal in both keys occur
(an inserted entry goes ahead of its equals).  After every cycle the valid flags, the
keys and tie keys of the valid entries, the payloads and drop_pay_o must equal the
model's.  With PAY_RST_IDX = 1 the test inserts with ins_pay_i = drop_pay_o (the free
slot, as fmt_blob does) and checks that the payloads and drop_pay_o stay a permutation
of 0..K.  Parametrized over K (1, 3, 8), PAY_W = 0 (no payload: outputs 0) and
HAS_POP = 0 (pop_i is driven and must be ignored), and EARLY = 1 (nxt_key_i / nxt_tie_i
carry the next cycle's insert key a cycle ahead; an insert always takes them), with
nxt_key_i in NXT_CP copies (1, 2 and 4), and AHEAD_IN = 1 (ins_ahead_i carries the insert's
comparison with the next insert, as the testbench computes it from the two keys).
"""
from __future__ import annotations

import random
from pathlib import Path

import cocotb
import pytest
from cocotb.triggers import FallingEdge, RisingEdge

from common.runner import run_cocotb, sources
from common.tb_util import ClockedTB, env_int


class Entry:
    __slots__ = ("valid", "key", "tie", "pay")

    def __init__(self, valid=False, key=None, tie=None, pay=None):
        self.valid, self.key, self.tie, self.pay = valid, key, tie, pay

    def copy(self):
        return Entry(self.valid, self.key, self.tie, self.pay)


class SortedListModel:
    """Reference: entry 0 first; keys descending, ties ascending, a new entry ahead of
    its equals; None = not known (never written since the start)."""

    def __init__(self, k: int, pay_rst_idx: bool):
        self.k, self.pay_rst_idx = k, pay_rst_idx
        self.e = [Entry() for _ in range(k)]
        self.drop = None

    def reset(self):
        for i, e in enumerate(self.e):
            e.valid = False
            if self.pay_rst_idx:
                e.pay = i
        if self.pay_rst_idx:
            self.drop = self.k

    def clear(self):
        for e in self.e:
            e.valid = False

    def insert(self, key, tie, pay):
        def ahead(e):
            return e.valid and (e.key > key or (e.key == key and e.tie < tie))
        pos = next((i for i, e in enumerate(self.e) if not ahead(e)), self.k)
        if pos == self.k:
            self.drop = pay                          # ranks below every entry
        else:
            self.drop = self.e[-1].pay
            self.e = self.e[:pos] + [Entry(True, key, tie, pay)] + self.e[pos:-1]
        return pos

    def pop(self):
        last = self.e[-1].copy()
        last.valid = False
        last.pay = self.e[0].pay                     # the payloads stay a permutation
        self.e = self.e[1:] + [last]


def fields(value, n: int, w: int):
    """The n fields of w bits of a flattened vector (field i at [i*w +: w]); None for a
    field with X/Z bits."""
    s = str(value)
    out = []
    for i in range(n):
        seg = s[len(s) - (i + 1) * w: len(s) - i * w]
        out.append(int(seg, 2) if set(seg) <= {"0", "1"} else None)
    return out


class TB(ClockedTB):
    def __init__(self, dut):
        super().__init__(dut)
        self.k = env_int("K", 8)
        self.kw, self.tw, self.pw = env_int("KEY_W", 4), env_int("TIE_W", 3), env_int("PAY_W", 4)
        self.pri = bool(env_int("PAY_RST_IDX", 0))
        self.has_pop = bool(env_int("HAS_POP", 1))
        self.m = SortedListModel(self.k, self.pri)
        for s in ("clear_i", "ins_i", "ins_key_i", "ins_tie_i", "ins_pay_i", "pop_i"):
            getattr(dut, s).value = 0

    def check(self):
        d, m, k = self.dut, self.m, self.k
        valid = fields(d.valid_o.value, k, 1)
        keys = fields(d.key_o.value, k, self.kw)
        ties = fields(d.tie_o.value, k, self.tw)
        if self.pw == 0:                              # no payload: one 0 bit per entry
            assert str(d.pay_o.value) == "0" * k and str(d.drop_pay_o.value) == "0"
            pays = [None] * k
        else:
            pays = fields(d.pay_o.value, k, self.pw)
        for i, e in enumerate(m.e):
            assert valid[i] == int(e.valid), f"entry {i}: valid {valid[i]}, expected {int(e.valid)}"
            if e.valid:
                assert (keys[i], ties[i]) == (e.key, e.tie), \
                    f"entry {i}: key/tie {keys[i], ties[i]}, expected {e.key, e.tie}"
            if e.pay is not None and self.pw:
                assert pays[i] == e.pay, f"entry {i}: payload {pays[i]}, expected {e.pay}"
        if m.drop is not None and self.pw:
            drop = fields(d.drop_pay_o.value, 1, self.pw)[0]
            assert drop == m.drop, f"drop_pay_o {drop}, expected {m.drop}"
        if self.pri:                                  # the payloads are slot numbers
            assert sorted(pays + [drop]) == list(range(k + 1)), f"not a permutation: {pays} + {drop}"


@cocotb.test()
async def random_ops(dut):
    tb = TB(dut)
    rng = random.Random(env_int("SEED", 1))
    await tb.reset()
    tb.m.reset()
    counts = {"ins": 0, "pop": 0, "clear": 0, "rst": 0, "drop_new": 0, "equal": 0}
    n_key = min(1 << tb.kw, 6)                         # few keys: many equal ones
    n_tie = min(1 << tb.tw, 4)
    early = env_int("EARLY", 0)
    cp = env_int("NXT_CP", 1)

    def nxt(k):                                        # nxt_key_i: cp copies of the key
        return sum(k << (c * tb.kw) for c in range(cp))
    ahead_in = env_int("AHEAD_IN", 0)
    pend = (rng.randrange(n_key), rng.randrange(n_tie))     # the next insert's key and tie
    dut.nxt_key_i.value, dut.nxt_tie_i.value = nxt(pend[0]), pend[1]
    dut.ins_ahead_i.value = 0
    for _ in range(3000):
        await FallingEdge(tb.clk)
        tb.check()
        d = dut
        d.ins_i.value = d.pop_i.value = d.clear_i.value = 0
        cur, pend = pend, (rng.randrange(n_key), rng.randrange(n_tie))
        d.nxt_key_i.value, d.nxt_tie_i.value = nxt(pend[0]), pend[1]
        # the insert (cur) ranks ahead of the next one (pend): key above, or equal key and
        # lower tie; only read with AHEAD_IN = 1 (otherwise driven with noise)
        ahead = cur[0] > pend[0] or (cur[0] == pend[0] and cur[1] < pend[1])
        d.ins_ahead_i.value = int(ahead) if ahead_in else rng.randrange(2)
        r = rng.random()
        if r < 0.005:
            counts["rst"] += 1
            await tb.reset(1)
            tb.m.reset()
            continue
        if r < 0.60:
            key, tie = cur if early else (rng.randrange(n_key), rng.randrange(n_tie))
            if tb.pri:
                pay = fields(d.drop_pay_o.value, 1, tb.pw)[0]
            else:
                pay = rng.randrange(1 << max(tb.pw, 1))
            d.ins_i.value, d.ins_key_i.value, d.ins_tie_i.value, d.ins_pay_i.value = 1, key, tie, pay
            counts["equal"] += any(e.valid and (e.key, e.tie) == (key, tie) for e in tb.m.e)
            counts["drop_new"] += int(tb.m.insert(key, tie, pay) == tb.k)
            counts["ins"] += 1
        elif r < 0.80:
            d.pop_i.value = 1
            if tb.has_pop:
                tb.m.pop()
            counts["pop"] += 1
        if rng.random() < 0.02:                        # also together with insert / pop
            d.clear_i.value = 1
            tb.m.clear()
            counts["clear"] += 1
        await RisingEdge(tb.clk)
    await FallingEdge(tb.clk)
    tb.check()
    dut._log.info(f"K {tb.k}: {counts}")
    assert counts["equal"] > 0 and counts["clear"] > 0 and counts["rst"] > 0
    assert tb.k == 1 or counts["drop_new"] > 0


# ---- pytest entry ------------------------------------------------------------------
@pytest.mark.parametrize("k,pay_w,pay_rst_idx,has_pop,early,cp,ahead",
                         [(1, 4, 1, 1, 0, 1, 0), (3, 4, 0, 1, 0, 1, 0), (8, 4, 1, 1, 0, 1, 0),
                          (5, 0, 0, 1, 0, 1, 0), (4, 3, 1, 0, 0, 1, 0), (1, 4, 1, 1, 1, 1, 0),
                          (8, 4, 1, 1, 1, 1, 0), (5, 3, 0, 1, 1, 1, 0), (8, 4, 1, 1, 1, 4, 0),
                          (5, 3, 0, 1, 1, 2, 0), (8, 4, 1, 1, 1, 4, 1)],
                         ids=["k1_idx", "k3", "k8_idx", "k5_nopay", "k4_idx_nopop",
                              "k1_idx_early", "k8_idx_early", "k5_early", "k8_idx_early_cp4",
                              "k5_early_cp2", "k8_idx_early_cp4_ahead"])
def test_fmt_sorted_list(sim, k, pay_w, pay_rst_idx, has_pop, early, cp, ahead):
    p = {"K": k, "KEY_W": 4, "TIE_W": 3, "PAY_W": pay_w, "PAY_RST_IDX": pay_rst_idx,
         "HAS_POP": has_pop, "EARLY": early, "NXT_CP": cp, "AHEAD_IN": ahead}
    run_cocotb(sim=sim, toplevel="fmt_sorted_list", sources=sources("fmt_sorted_list"),
               test_module="test_fmt_sorted_list", test_dir=Path(__file__).parent,
               parameters=p, extra_env={**p, "SEED": 1})
