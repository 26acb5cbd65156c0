"""Model tests of sim/fmt/regmap.py: the generated files are up to date, the map is
consistent, reset values come from the shared parameters/settings, and the register
file model behaves as documented."""
from __future__ import annotations

import re

from fmt import params, regmap
from fmt.settings import TouchSettings
from fmt.tracker import TrackParams


def test_generated_files_fresh():
    stale = regmap.stale_files()
    assert not stale, f"stale generated files {stale}: run `python -m fmt.generate`"


def test_map_consistent():
    regmap.validate()
    names = [r.name for r in regmap.REGISTERS]
    assert len(names) == len(set(names))
    for w in regmap.WINDOWS:
        assert 0 <= w.base and w.base + w.size <= 1 << 16
    assert regmap.WINDOW_BY_NAME["HEATMAP"].size == params.DEFAULT.rows * params.DEFAULT.cols


def test_resets_from_shared_defaults():
    s = TouchSettings()
    cfg = params.DEFAULT
    r = regmap.BY_NAME
    assert r["TOUCH_THRESHOLD"].reset == s.threshold
    assert r["BLOB_THRESHOLD"].reset == s.blob_threshold
    assert r["BLOB_MIN_CELLS"].reset == s.blob_min_cells
    assert r["CONTACT_LIMIT"].reset == cfg.max_touches
    conv = s.converted(cfg, regmap.FRAME_PERIOD_S)
    assert r["TRACK_MAX_JUMP"].reset == conv["max_jump_q"]
    assert r["TRACK_HOLD_OFF"].reset == conv["hold_off_frames"]
    tp = TrackParams.from_settings(cfg, s, regmap.FRAME_PERIOD_S)
    assert (r["TRACK_GATE_STEP"].reset, r["TRACK_VEL_SHIFT"].reset, r["TRACK_MAX_SPEED"].reset) == \
        (tp.gate_step_q, tp.vel_shift, tp.max_speed_v)
    # the report period keeps the event rate to the host at or below 250 Hz
    assert regmap.PROC_CLK_HZ / r["REPORT_PERIOD"].reset <= 250.0


def test_regfile_model():
    m = regmap.RegfileModel()
    a = regmap.BY_NAME
    m.write(a["PN_CHIP_LEN"].addr, 0xFFFFFFFF)
    assert m.read(a["PN_CHIP_LEN"].addr) == 0x3FF               # masked to 10 bits
    m.write(a["ID"].addr, 0)
    assert m.read(a["ID"].addr) == a["ID"].reset                 # const ignores writes
    m.val["STATUS"] = 0x1F
    m.write(a["STATUS"].addr, 0x05)
    assert m.read(a["STATUS"].addr) == 0x1A                      # w1c
    assert m.read(0x7FF) == 0                                    # unmapped
    assert m.read(a["FRAME_COUNT"].addr, {"FRAME_COUNT": 77}) == 77


def test_status_flag_names():
    """One short name per STATUS bit, each bit described in the map, and the core's
    status_set concatenation (rtl/fmt_core.v, read here) has one term per bit."""
    st = regmap.BY_NAME["STATUS"]
    assert len(regmap.STATUS_FLAGS) == st.width == len(set(regmap.STATUS_FLAGS))
    for i in range(st.width):
        assert f"bit {i} " in st.desc
    src = (regmap.ROOT / "rtl" / "fmt_core.v").read_text()
    m = re.search(r"wire \[(\d+):0\] status_set = \{(.*?)\};", src, re.S)
    assert m and int(m.group(1)) == st.width - 1
    terms = [t.strip() for t in m.group(2).split(",")]
    assert len(terms) == st.width
    assert terms[-2] == "rx_fft_ovf" and terms[1] == "rx_sat" and terms[0] == "rx_overrun"
    assert regmap.status_names(0) == []
    assert regmap.status_names(0b110_0000_0010 | 1 << 12) == ["rx_fft_ovf", "rx_sat", "rx_overrun", "bit12"]


def test_regfile_ports_follow_map():
    v = regmap.render_verilog()
    for r in regmap.REGISTERS:
        if r.access == "rw":
            assert f"{r.port}_o" in v
        if r.access == "ro":
            assert f"{r.port}_i" in v
    assert "`default_nettype none" in v and v.rstrip().endswith("`default_nettype wire")
