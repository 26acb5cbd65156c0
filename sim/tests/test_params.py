"""The parameter source of truth: tone-plan validation and the generated header."""
import pytest

from fmt import params


def test_default_matches_brief():
    c = params.DEFAULT
    assert (c.rows, c.cols, c.n_fft, c.bin_lo, c.bin_hi) == (30, 40, 256, 33, 62)
    assert c.tone_hz[0] == pytest.approx(5.371e6, rel=1e-3)
    assert c.tone_hz[-1] == pytest.approx(10.091e6, rel=1e-3)
    assert c.bin_hz == pytest.approx(162.76e3, rel=1e-4)
    assert c.window_s == pytest.approx(6.144e-6, rel=1e-6)


def test_tuning_words_are_exact_bins():
    c = params.DEFAULT
    for k in c.bins:
        w = c.tuning_word(k)
        assert w % (1 << (c.phase_bits - c.log2_n)) == 0
        assert w * c.n_fft == k << c.phase_bits  # exactly k cycles per window


@pytest.mark.parametrize("kw,msg", [
    (dict(bin_step=0), "below 1/tau"),
    (dict(bin_lo=20), "2 x lowest"),           # 30 rows from bin 20 reach bin 49 >= 40
    (dict(bin_lo=110), "Nyquist"),
    (dict(n_fft=100), "power of two"),
    (dict(bin_lo=0), "DC"),
])
def test_invalid_tone_plans_are_refused(kw, msg):
    with pytest.raises(params.ToneplanError, match=msg):
        params.DEFAULT.replace(**kw)


def test_generated_header_is_current():
    assert params.VH_PATH.read_text() == params.render_vh(), (
        "rtl/fmt_defaults.vh is stale: run `python -m fmt.generate`")
