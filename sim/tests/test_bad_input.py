"""Bad input at the entry points (issue #15 item 1): every case gives one line on stderr
and a non-zero exit, no traceback, and never reports an old output as new.

scripts/replay_touch.py, scripts/replay_rx.py (input checks before any build; the
simulation replaced by a stand-in where a test needs its result), scene and settings
files, ``python -m fmt.run_sim`` and ``python -m bench.core.run_sim_rtl`` (arguments,
and the verdict of a run: no frame, dropped frames, golden mismatches), plus
property-based tests (hypothesis) with random bad arrays."""
from __future__ import annotations

import importlib.util
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from fmt import params
from fmt import scene as S
from fmt import settings as _settings
from fmt.inputs import InputError

ROOT = Path(__file__).resolve().parents[2]
SMALL = params.SMALL
# examples per property test (FMT_HYPOTHESIS_EXAMPLES=2000 for a longer search by hand)
N_EX = int(os.environ.get("FMT_HYPOTHESIS_EXAMPLES", "0")) or None


def _script(name):
    spec = importlib.util.spec_from_file_location(f"_bad_{name}", ROOT / "scripts" / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


replay_touch = _script("replay_touch")
replay_rx = _script("replay_rx")


def one_line(capsys) -> str:
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and "Traceback" not in err, err
    return lines[0]


@pytest.fixture
def no_sim(monkeypatch):
    """Fail if a bad input reaches the simulation."""
    import common.runner as R

    def boom(**kw):
        raise AssertionError("bad input reached the simulation")
    monkeypatch.setattr(R, "run_cocotb", boom)


# ---- scripts/replay_touch.py ---------------------------------------------------------------
def _maps(dtype=np.int32, frames=3):
    return np.full((frames, SMALL.rows, SMALL.cols), 100, dtype=dtype)


def _touch(tmp_path, arr, *extra):
    inp = tmp_path / "hm.npy"
    np.save(inp, arr)
    return replay_touch.main(["--in", str(inp), "--out", str(tmp_path / "ev.jsonl"),
                              "--config", "small", *extra])


@pytest.mark.parametrize("value", [-5, 70000])
def test_touch_out_of_range(tmp_path, capsys, no_sim, value):
    hm = _maps()
    hm[0, 1, 2] = 5000
    hm[0, 1, 3] = value
    assert _touch(tmp_path, hm, "--check") == 2
    assert f"value {value} at (0, 1, 3)" in one_line(capsys)
    assert not (tmp_path / "ev.jsonl").exists()


def test_touch_float_refused(tmp_path, capsys, no_sim):
    assert _touch(tmp_path, np.full((2, SMALL.rows, SMALL.cols), 2500.7)) == 2
    assert "dtype float64" in one_line(capsys)


@pytest.mark.parametrize("shape", [(2, 5, 6), (4, 6), (2, 4, 6, 1), (0, 4, 6)])
def test_touch_bad_shape(tmp_path, capsys, no_sim, shape):
    assert _touch(tmp_path, np.zeros(shape, dtype=np.uint16)) == 2
    assert "shape" in one_line(capsys) or "empty" in one_line(capsys)


def test_touch_no_file_and_not_npy(tmp_path, capsys, no_sim):
    assert replay_touch.main(["--in", str(tmp_path / "none.npy"), "--out", str(tmp_path / "e")]) == 2
    one_line(capsys)
    (tmp_path / "junk.npy").write_text("not an array")
    assert replay_touch.main(["--in", str(tmp_path / "junk.npy"), "--out", str(tmp_path / "e")]) == 2
    assert "not a readable" in one_line(capsys)


@pytest.mark.parametrize("st_json, key", [
    ({"threshhold": 100}, "threshhold"), ({"threshold": "high"}, "threshold"),
    ({"threshold": 70000}, "threshold"), ({"neighbourhood": "hex"}, "neighbourhood"),
    ({"position_noise_mm": -1.0}, "position_noise_mm"), ({"blobs": 1}, "blobs"), ([1, 2], "expected an object")])
def test_touch_bad_settings(tmp_path, capsys, no_sim, st_json, key):
    p = tmp_path / "st.json"
    p.write_text(json.dumps(st_json))
    assert _touch(tmp_path, _maps(), "--settings", str(p)) == 2
    assert key in one_line(capsys)


def _fake_touch_sim(events):
    def run(**kw):
        with open(kw["extra_env"]["REPLAY_OUT"], "w") as f:
            for e in events:
                f.write(json.dumps(e) + "\n")
    return run


def test_touch_check_mismatch_and_model_error(tmp_path, capsys, monkeypatch):
    import common.runner as R
    import fmt.touch as T
    ev = {"frame": 0, "id": 1, "type": "new", "x_q": 1, "y_q": 1, "strength": 9, "axis_major_q": 0,
          "axis_minor_q": 0, "angle": 0, "flags": 0, "cycle": 5}
    monkeypatch.setattr(R, "run_cocotb", _fake_touch_sim([ev]))
    assert _touch(tmp_path, _maps(), "--check") == 1
    assert "MISMATCH" in capsys.readouterr().err
    monkeypatch.setattr(T, "process_frames", lambda *a, **k: (_ for _ in ()).throw(ValueError("bad\nrow")))
    assert _touch(tmp_path, _maps(), "--check") == 1
    assert "the model failed (bad row)" in one_line(capsys)


def test_touch_failed_sim_keeps_old_output_unreported(tmp_path, capsys, monkeypatch):
    import common.runner as R
    out = tmp_path / "ev.jsonl"
    out.write_text("old\n")

    def fail(**kw):
        raise R.SimulationFailed("fmt_touch: 1 of 1 cocotb tests failed")
    monkeypatch.setattr(R, "run_cocotb", fail)
    assert _touch(tmp_path, _maps()) == 1
    assert "not written" in one_line(capsys)
    assert out.read_text() == "old\n" and not list(tmp_path.glob(".ev.jsonl*"))
    monkeypatch.setattr(R, "run_cocotb", lambda **kw: None)      # ran, wrote nothing
    assert _touch(tmp_path, _maps()) == 1
    assert "not written" in one_line(capsys) and out.read_text() == "old\n"
    monkeypatch.setattr(R, "run_cocotb", _fake_touch_sim([]))    # success: renamed into place
    assert _touch(tmp_path, _maps()) == 0
    assert out.read_text() == "" and not list(tmp_path.glob(".ev.jsonl*"))


# ---- scripts/replay_rx.py ------------------------------------------------------------------
def _rx(tmp_path, arr, *extra, sign=None):
    inp = tmp_path / "cap.npy"
    np.save(inp, arr)
    args = ["--in", str(inp), "--out", str(tmp_path / "hm.npy"), "--config", "small", *extra]
    if sign is not None:
        np.save(tmp_path / "sign.npy", sign)
        args += ["--sign", str(tmp_path / "sign.npy")]
    return replay_rx.main(args)


def _cap(n=SMALL.n_fft, dtype=np.int16):
    return np.zeros((n, SMALL.cols), dtype=dtype)


@pytest.mark.parametrize("arr, text", [
    (np.full((64, 6), 2048, dtype=np.int32), "value 2048"),
    (np.full((64, 6), -2049, dtype=np.int32), "value -2049"),
    (np.full((64, 6), 2500.7), "dtype float64"),
    (np.zeros((64, 7), dtype=np.int16), "shape (64, 7)"),
    (np.zeros((64,), dtype=np.int16), "shape (64,)"),
    (np.zeros((63, 6), dtype=np.int16), "less than one frame"),
    (np.zeros((64, 6), dtype=bool), "dtype bool")])
def test_rx_bad_capture(tmp_path, capsys, no_sim, arr, text):
    assert _rx(tmp_path, arr) == 2
    assert text in one_line(capsys)


def test_rx_bad_sign_and_args(tmp_path, capsys, no_sim):
    assert _rx(tmp_path, _cap(), sign=np.full(SMALL.n_fft, 2, dtype=np.uint8)) == 2
    assert "--sign" in one_line(capsys)
    assert _rx(tmp_path, _cap(), sign=np.zeros(5, dtype=np.uint8)) == 2
    assert "shape (5,)" in one_line(capsys)
    with pytest.raises(SystemExit) as e:
        _rx(tmp_path, _cap(), "--m", "300")
    assert e.value.code == 2 and "--m" in one_line(capsys)
    assert _rx(tmp_path, _cap(), "--m", "2") == 2                  # 64 samples < 2 windows
    one_line(capsys)


def test_rx_failed_sim_keeps_old_output_unreported(tmp_path, capsys, monkeypatch):
    import common.runner as R
    out = tmp_path / "hm.npy"
    np.save(out, np.full((1, 4, 6), 7, dtype=np.uint32))
    (tmp_path / "hm.npy.json").write_text('{"old": 1}')

    def fail(**kw):                     # as the cocotb side fails on a bad capture
        raise SystemExit(1)
    monkeypatch.setattr(R, "run_cocotb", fail)
    assert _rx(tmp_path, _cap()) == 1
    assert "not written" in one_line(capsys)
    assert np.load(out)[0, 0, 0] == 7 and not list(tmp_path.glob(".hm.npy*"))
    monkeypatch.setattr(R, "run_cocotb", lambda **kw: None)      # left no output at all
    assert _rx(tmp_path, _cap()) == 1
    assert "not written" in one_line(capsys) and np.load(out)[0, 0, 0] == 7

    def ok(**kw):
        p = kw["extra_env"]["REPLAY_OUT"]
        np.save(p, np.zeros((1, 4, 6), dtype=np.uint32))
        Path(str(p) + ".json").write_text('{"frames": 1}')
    monkeypatch.setattr(R, "run_cocotb", ok)
    assert _rx(tmp_path, _cap(), "--check") == 0                   # zeros in, zeros out
    assert np.load(out)[0, 0, 0] == 0 and json.loads((tmp_path / "hm.npy.json").read_text()) == {"frames": 1}
    assert not list(tmp_path.glob(".hm.npy*"))


def test_scripts_one_line_in_a_subprocess(tmp_path):
    """As a user runs them: the issue's inputs, one line on stderr, no traceback."""
    hm = _maps()
    hm[0, 1, 2], hm[0, 1, 3] = 5000, -5
    np.save(tmp_path / "neg.npy", hm)
    np.save(tmp_path / "shape.npy", np.zeros((2, 30, 41), dtype=np.uint16))
    np.save(tmp_path / "float.npy", np.full((64, 6), 2500.7))
    runs = [("replay_touch", "neg.npy", ["--config", "small", "--check"]),
            ("replay_touch", "shape.npy", []),
            ("replay_rx", "float.npy", ["--config", "small"])]
    for script, fn, extra in runs:
        r = subprocess.run([sys.executable, str(ROOT / "scripts" / f"{script}.py"), "--in",
                            str(tmp_path / fn), "--out", str(tmp_path / "o.npy"), *extra],
                           capture_output=True, text=True, timeout=120)
        assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, (script, fn, r.stderr)
        assert "Traceback" not in r.stderr


# ---- scene and settings files ----------------------------------------------------------------
def _scene_dict(**kw):
    d = json.loads((S.SCENES_DIR / "small.json").read_text())
    d.update(kw)
    return d


@pytest.mark.parametrize("change, key", [
    ({"frame": 10}, "'frame'"), ({"frames": "ten"}, "'frames'"), ({"frames": 0}, "'frames'"),
    ({"m": 256}, "'m'"), ({"sensor": "huge"}, "'sensor'"), ({"seed": 1.5}, "'seed'"),
    ({"effects": {"nois": {}}}, "'effects'"), ({"effects": []}, "'effects'"),
    ({"contacts": [{"path": [[0, 1, 2]], "diameter_mm": -3}]}, "contacts[0]: key 'diameter_mm'"),
    ({"contacts": [{"path": [[0, 1, 2]], "colour": "red"}]}, "contacts[0]: unknown key 'colour'"),
    ({"contacts": [{"path": [[0, "a", 2]]}]}, "contacts[0]: key 'path'"),
    ({"contacts": [{"diameter_mm": 8}]}, "contacts[0]: key 'path' missing"),
    ({"contacts": [{"path": [[0, 1, 2]], "profile": "square"}]}, "'profile'"),
    ({"contacts": [{"path": [[1, 1, 2], [0, 1, 2]]}]}, "times must not decrease")])
def test_scene_bad_keys(tmp_path, change, key):
    p = tmp_path / "s.json"
    p.write_text(json.dumps(_scene_dict(**change)))
    with pytest.raises(InputError) as e:
        S.load(p)
    msg = str(e.value)
    assert key in msg and str(p) in msg and "\n" not in msg


def test_scene_bad_files(tmp_path):
    for name, text in [("a.json", "{"), ("b.yaml", "a: [1"), ("c.json", "[1, 2]")]:
        (tmp_path / name).write_text(text)
        with pytest.raises(InputError):
            S.load(tmp_path / name)
    with pytest.raises(InputError, match="No such file"):
        S.load(tmp_path / "none.json")


def test_settings_load(tmp_path):
    p = tmp_path / "st.json"
    p.write_text(json.dumps({"threshold": 1500, "neighbourhood": "vn", "max_touches": None}))
    assert _settings.load(p).threshold == 1500
    for bad, key in [({"treshold": 1}, "treshold"), ({"max_touches": 0}, "max_touches"),
                     ({"bias_correction": "yes"}, "bias_correction"), ({"hold_off_us": float("nan")}, "hold_off_us")]:
        p.write_text(json.dumps(bad))
        with pytest.raises(InputError, match=key):
            _settings.load(p)
    p.write_text("{,}")
    with pytest.raises(InputError, match="not valid JSON"):
        _settings.load(p)


# ---- python -m fmt.run_sim, python -m bench.core.run_sim_rtl ----------------------------------
@pytest.mark.parametrize("mod", ["fmt.run_sim", "bench.core.run_sim_rtl"])
@pytest.mark.parametrize("args", [["--frames", "0"], ["--frames", "x"], ["--bogus"], ["--quiet", "extra"]])
def test_run_sim_bad_arguments(capsys, mod, args):
    m = importlib.import_module(mod)
    with pytest.raises(SystemExit) as e:
        m.main(args)
    assert e.value.code == 2
    assert "error:" in one_line(capsys)


@pytest.mark.parametrize("mod", ["fmt.run_sim", "bench.core.run_sim_rtl"])
def test_run_sim_bad_scene(tmp_path, capsys, mod):
    m = importlib.import_module(mod)
    p = tmp_path / "s.json"
    p.write_text(json.dumps(_scene_dict(frames=-1)))
    assert m.main(["--scene", str(p)]) == 2
    assert "key 'frames'" in one_line(capsys)
    assert m.main(["--scene", str(tmp_path / "none.json")]) == 2
    one_line(capsys)


def test_bench_model_bad_scene(tmp_path, capsys):
    bm = _script("bench_model")
    assert bm.main(["--scene", str(tmp_path / "none.json")]) == 2
    one_line(capsys)
    assert bm.main(["--frames", "0"]) == 2
    one_line(capsys)


def test_run_sim_rtl_bad_cps_and_serve(capsys):
    from bench.core import run_sim_rtl as rsr
    with pytest.raises(SystemExit) as e:
        rsr.main(["--cps", "0"])
    assert e.value.code == 2
    one_line(capsys)
    assert rsr.main(["--serve", "0", "--engine", "cocotb"]) == 2
    assert "--serve" in one_line(capsys)


@pytest.mark.parametrize("rep, code, text", [
    ({"frames": 0, "frames_requested": 10, "frames_dropped": 10, "golden_mismatches": 0}, 1, "no frame"),
    ({"frames": 8, "frames_requested": 10, "frames_dropped": 2, "golden_mismatches": 0}, 1, "2 frames dropped"),
    ({"frames": 10, "frames_requested": 10, "frames_dropped": 0, "golden_mismatches": 3,
      "golden_detail": {"first": "heat map of frame 4"}}, 1, "3 golden mismatches, first: heat map of frame 4"),
    ({"frames": 10, "frames_requested": 10, "frames_dropped": 0, "golden_mismatches": 0}, 0, "")])
def test_run_sim_rtl_verdict(tmp_path, capsys, monkeypatch, rep, code, text):
    """make sim fails (one line on stderr) on no frame, a dropped frame or a golden mismatch."""
    from bench.core import run_sim_rtl as rsr
    assert rsr.verdict(rep)[0] == code and text in rsr.verdict(rep)[1]
    monkeypatch.setattr(rsr, "run", lambda *a, **k: dict(rep, report=str(tmp_path / "r.json")))
    monkeypatch.setattr(rsr, "_summary", lambda r: "summary")
    assert rsr.main(["--scene", str(S.SCENES_DIR / "small.json"), "--quiet"]) == code
    err = capsys.readouterr().err
    if code:
        assert err.strip().splitlines() == [rsr.verdict(rep)[1]]
    else:
        assert err == ""


# ---- property-based: random bad arrays never pass and never end in a traceback ---------------
_FLOATS = st.sampled_from([np.float16, np.float32, np.float64])
_INTS = st.sampled_from([np.int8, np.int16, np.int32, np.int64, np.uint16, np.uint32, np.uint64])


@st.composite
def bad_heatmaps(draw):
    kind = draw(st.sampled_from(["float", "range", "shape", "bool", "complex"]))
    frames = draw(st.integers(1, 4))
    shape = (frames, SMALL.rows, SMALL.cols)
    if kind == "shape":
        shape = tuple(draw(st.lists(st.integers(0, 8), min_size=1, max_size=4)))
        if len(shape) == 3 and shape[1:] == (SMALL.rows, SMALL.cols) and shape[0] > 0:
            shape = (shape[0], SMALL.rows + 1, SMALL.cols)
        return np.zeros(shape, dtype=draw(_INTS))
    if kind == "float":
        v = draw(st.floats(allow_nan=True, allow_infinity=True, width=16))
        return np.full(shape, v, dtype=draw(_FLOATS))
    if kind == "bool":
        return np.zeros(shape, dtype=bool)
    if kind == "complex":
        return np.zeros(shape, dtype=np.complex64)
    dt = draw(st.sampled_from([np.int32, np.int64, np.uint32, np.uint64]))
    lim = np.iinfo(dt)
    lo = max(int(lim.min), -(1 << 40))
    bad = draw(st.one_of(st.integers(65536, int(lim.max)), st.integers(min(lo, -1), -1)) if lim.min < 0
               else st.integers(65536, int(lim.max)))
    a = np.full(shape, draw(st.integers(0, 65535)), dtype=dt)
    idx = tuple(draw(st.integers(0, n - 1)) for n in shape)
    a[idx] = bad
    return a


@settings(max_examples=N_EX or 60, deadline=None, database=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(arr=bad_heatmaps())
def test_property_replay_touch_refuses(tmp_path, capsys, no_sim, arr):
    code = _touch(tmp_path, arr)
    assert code == 2
    one_line(capsys)


@st.composite
def bad_captures(draw):
    kind = draw(st.sampled_from(["float", "range", "shape", "short"]))
    n = draw(st.integers(SMALL.n_fft, 3 * SMALL.n_fft))
    if kind == "shape":
        shape = tuple(draw(st.lists(st.integers(0, 80), min_size=1, max_size=3)))
        if len(shape) == 2 and shape[1] == SMALL.cols:
            shape = (shape[0], SMALL.cols + 1)
        return np.zeros(shape, dtype=np.int16)
    if kind == "short":
        return np.zeros((draw(st.integers(0, SMALL.n_fft - 1)), SMALL.cols), dtype=np.int16)
    if kind == "float":
        return np.full((n, SMALL.cols), draw(st.floats(-4096, 4096, width=32)), dtype=draw(_FLOATS))
    a = np.zeros((n, SMALL.cols), dtype=np.int32)
    a[draw(st.integers(0, n - 1)), draw(st.integers(0, SMALL.cols - 1))] = draw(
        st.one_of(st.integers(2048, 2**31 - 1), st.integers(-2**31, -2049)))
    return a


@settings(max_examples=N_EX or 60, deadline=None, database=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(arr=bad_captures())
def test_property_replay_rx_refuses(tmp_path, capsys, no_sim, arr):
    assert _rx(tmp_path, arr) == 2
    one_line(capsys)


# ---- property-based: random scene and settings objects load or give one InputError ----------
_JSON = st.recursive(st.none() | st.booleans() | st.integers(-2**40, 2**40)
                     | st.floats(allow_nan=True, allow_infinity=True) | st.text(max_size=6),
                     lambda ch: st.lists(ch, max_size=3) | st.dictionaries(st.text(max_size=6), ch, max_size=3),
                     max_leaves=6)
_SCENE_KEYS = ["name", "sensor", "frames", "m", "seed", "duration_s", "effects", "contacts", "bogus"]
_CONTACT_KEYS = ["path", "name", "diameter_mm", "strength", "profile", "minor_diameter_mm",
                 "angle_deg", "active", "active_units", "bogus"]


@settings(max_examples=N_EX or 150, deadline=None, database=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(key=st.sampled_from(_SCENE_KEYS), ckey=st.sampled_from(_CONTACT_KEYS), value=_JSON,
       where=st.sampled_from(["scene", "contact"]))
def test_property_scene_loads_or_one_input_error(tmp_path, key, ckey, value, where):
    d = _scene_dict(frames=2)
    if where == "scene":
        d[key] = value
    else:
        d["contacts"][0][ckey] = value
    p = tmp_path / "s.json"
    try:
        p.write_text(json.dumps(d))
    except ValueError:
        return
    try:
        sc = S.load(p)
    except InputError as e:
        assert "\n" not in str(e) and str(p) in str(e)
        return
    for t in sc.frame_centre_s(range(min(sc.frames, 2))):   # a loaded scene is usable
        sc.truth(t)
    sc.onset_samples()


@settings(max_examples=N_EX or 150, deadline=None, database=None,
          suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(key=st.sampled_from(list(_settings.TouchSettings().as_dict()) + ["bogus"]), value=_JSON)
def test_property_settings_load_or_one_input_error(tmp_path, key, value):
    p = tmp_path / "st.json"
    p.write_text(json.dumps({key: value}))
    try:
        st_ = _settings.load(p)
    except InputError as e:
        assert "\n" not in str(e) and key in str(e)
        return
    st_.converted(SMALL, SMALL.window_s)                  # a loaded setting is usable


def test_touch_check_passes_when_the_sim_equals_the_model(tmp_path, capsys, monkeypatch):
    """The good path through the checks: scene heat maps, a stand-in simulation that
    writes the model's events, --check passes, the output is renamed into place."""
    import common.runner as R
    from fmt.settings import TouchSettings
    from fmt.touch import process_frames
    from fmt_touch.touch_driver import scene_maps
    maps = scene_maps(SMALL, 8, (1 << SMALL.hm_width) - 1, np.random.default_rng(5)).astype(np.uint16)
    exp = process_frames(maps.astype(np.int64), SMALL, TouchSettings(), fixed=True,
                         frame_period_s=SMALL.window_s)
    evs = [{"frame": e.frame, "id": e.id, "type": e.type, "x_q": e.x_q, "y_q": e.y_q,
            "strength": e.strength, "axis_major_q": e.axis_major_q, "axis_minor_q": e.axis_minor_q,
            "angle": e.angle, "flags": e.flags, "cycle": 0} for fr in exp for e in fr]
    assert evs
    monkeypatch.setattr(R, "run_cocotb", _fake_touch_sim(evs))
    assert _touch(tmp_path, maps, "--check") == 0
    out = capsys.readouterr().out
    assert "bit-exact" in out and f"{len(evs)} events from 8 heat maps" in out
    assert len((tmp_path / "ev.jsonl").read_text().splitlines()) == len(evs)
