"""DDS bank and despreader model (sim/fmt/dds_bank.py): committed sine tables are current,
the fixed twin stays within its stated bound of the float twin, the comb is exactly
periodic, the output range leaves room for the PN negation, the despreader is exact."""
import numpy as np
import pytest

from fmt import dds_bank, params


@pytest.mark.parametrize("table_addr,sine_bits", dds_bank.HEX_TABLES)
def test_hex_tables_current(table_addr, sine_bits):
    path = dds_bank.RTL / dds_bank.hex_name(table_addr, sine_bits)
    assert path.exists(), f"{path} missing: run python -m fmt.generate"
    assert path.read_text() == dds_bank.render_hex(table_addr, sine_bits), \
        f"{path} is stale: run python -m fmt.generate"


def test_table_symmetric_and_in_range():
    for a, s in dds_bank.HEX_TABLES:
        t = dds_bank.sine_table(a, s)
        n = t.size
        assert t.max() == (1 << (s - 1)) - 1 and t.min() == -t.max()
        assert np.array_equal(t[1:], -t[1:][::-1]), "odd symmetry sin(-x) = -sin(x)"


@pytest.mark.parametrize("cfg", [params.SMALL, params.MEDIUM, params.DEFAULT], ids=lambda c: c.name)
def test_fixed_vs_float_exact_bins(cfg):
    n = 2 * cfg.n_fft
    rng = np.random.default_rng(1)
    amp = rng.integers(0, 1 << cfg.amp_bits, size=cfg.rows)
    sign = rng.integers(0, 2, size=n)
    y = dds_bank.dds_bank_fixed(n, amp=amp, tx_sign=sign, cfg=cfg)
    f = dds_bank.dds_bank_float(n, amp=amp, tx_sign=sign, cfg=cfg)
    b = dds_bank.error_bound(cfg)
    err = np.abs(y - f).max()
    assert err <= b, (err, b)
    assert err > 0.25, "the bound is not vacuous: rounding errors are seen"
    # exact comb: every window identical without PN
    y0 = dds_bank.dds_bank_fixed(3 * cfg.n_fft, cfg=cfg)
    w = y0.reshape(3, cfg.n_fft, cfg.rows)
    assert np.array_equal(w[1], w[0]) and np.array_equal(w[2], w[0])


def test_fixed_vs_float_random_tuning():
    cfg = params.MEDIUM
    n = 500
    rng = np.random.default_rng(2)
    tw = rng.integers(0, 1 << 32, size=(n, cfg.rows))
    amp = rng.integers(0, 256, size=(n, cfg.rows))
    y = dds_bank.dds_bank_fixed(n, tuning=tw, amp=amp, cfg=cfg)
    f = dds_bank.dds_bank_float(n, tuning=tw, amp=amp, cfg=cfg)
    b = dds_bank.error_bound(cfg, exact_bins=False)
    assert np.abs(y - f).max() <= b


def test_range_leaves_room_for_negation():
    for s_bits, a_bits, d_bits in [(16, 8, 12), (10, 8, 18), (16, 8, 24), (12, 8, 9), (16, 4, 5)]:
        dds_bank.check_widths(s_bits, a_bits, d_bits)
        cfg = params.SMALL
        n = 1 << 10
        # tuning of one table step per sample: every table entry is visited
        tw = np.full(cfg.rows, 1 << (cfg.phase_bits - dds_bank.TABLE_ADDR))
        for sign in (0, 1):
            y = dds_bank.dds_bank_fixed(n, tuning=tw, tx_sign=sign, cfg=cfg, sine_bits=s_bits,
                                   dac_bits=d_bits, amp_bits=a_bits)
            assert np.abs(y).max() <= (1 << (d_bits - 1)) - 1
            assert y.max() == -y.min()
    with pytest.raises(ValueError):
        dds_bank.check_widths(16, 8, 25)
    with pytest.raises(ValueError):
        dds_bank.check_widths(16, 8, 6)


def test_disabled_rows_are_zero_and_keep_phase():
    cfg = params.SMALL
    n = 200
    en = np.ones((n, cfg.rows), dtype=np.int64)
    en[50:120, 2] = 0
    y = dds_bank.dds_bank_fixed(n, enable=en, cfg=cfg)
    ref = dds_bank.dds_bank_fixed(n, cfg=cfg)
    assert not y[50:120, 2].any()
    assert np.array_equal(y[120:], ref[120:])


def test_despread():
    x = np.array([-2048, 2047, 0, -1, 5])
    s = np.array([1, 1, 1, 1, 0])
    assert dds_bank.despread_fixed(x, s).tolist() == [2048, -2047, 0, 1, 5]
    assert np.array_equal(dds_bank.despread_float(x, s), dds_bank.despread_fixed(x, s))


def test_tx_sign_alignment():
    from fmt.pn_gen import pn_signs
    cfg = params.SMALL
    y = dds_bank.tx_fixed(300, cfg=cfg, chip_len=3)
    plain = dds_bank.dds_bank_fixed(300, cfg=cfg)
    tx, _ = pn_signs(299, chip_len=3, bits=cfg.pn_bits)
    sgn = np.concatenate([[1], 1 - 2 * tx.astype(np.int64)])
    assert np.array_equal(y, plain * sgn[:, None])
