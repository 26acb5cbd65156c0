"""Random-scene regression (issue #15 item 4), the short sample in ``make test``:
``scripts/random_scenes.py`` draws scenes (contacts, motion, effects, settings), runs the
fixed-point twin of the RTL path and checks invariants.  ``make random-scenes`` runs
10^4 of them (also part of ``make test-long``).

Here: 200 scenes must run clean and exercise what the invariants are about (lifts,
blobs, several contacts, effects), and the checker must flag doctored event streams
(a check that cannot fail would prove nothing)."""
from __future__ import annotations

import dataclasses
import importlib.util
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="module")
def rs():
    spec = importlib.util.spec_from_file_location("_random_scenes", ROOT / "scripts" / "random_scenes.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_random_scenes_clean_and_varied(rs):
    n = 200
    kinds, blob_ev, multi, effects, frames = set(), 0, 0, set(), 0
    for i in range(n):
        sc, st = rs.random_scene(11, i, "mixed")
        ref = rs.run_model(sc, st)
        bad = rs.check(sc, st, ref)
        assert not bad, f"scene {i}: {bad[:3]}"
        frames += sc.frames
        for evs in ref.events:
            kinds.update(e.type for e in evs)
            blob_ev += sum(e.type == "blob" for e in evs)
            multi += sum(e.type in ("new", "move") for e in evs) >= 2
        effects.update(sc.effects)
    assert {"new", "move", "lift", "blob"} <= kinds, kinds
    assert blob_ev > 0 and multi > 50, (blob_ev, multi)
    assert {"noise", "interferer", "enob", "dc_lsb", "delay_samples", "pn"} <= effects, effects


def _clean_run(rs):
    for i in range(200):
        sc, st = rs.random_scene(3, i, "small")
        ref = rs.run_model(sc, st)
        evs = [e for f in ref.events for e in f if e.type in ("new", "move")]
        if len(evs) >= 3 and not rs.check(sc, st, ref):
            return sc, st, ref
    pytest.fail("no clean scene with events among 200")


def test_checker_flags_doctored_events(rs):
    sc, st, ref = _clean_run(rs)
    cfg = sc.cfg
    f0 = next(f for f, evs in enumerate(ref.events) if any(e.type in ("new", "move") for e in evs))
    e0 = next(e for e in ref.events[f0] if e.type in ("new", "move"))

    def doctored(frame_events):
        return dataclasses.replace(ref, events=frame_events)

    def with_frame(f, evs):
        out = [list(x) for x in ref.events]
        out[f] = evs
        return out

    cases = {
        "duplicate ID": with_frame(f0, ref.events[f0] + [e0]),
        "outside the sensor": with_frame(f0, [dataclasses.replace(e0, x_q=(cfg.cols - 1) * 256 + 1)]),
        "below the threshold": with_frame(f0, [dataclasses.replace(e0, strength=st.threshold - 1)]),
        "move of a dead ID": with_frame(f0, [dataclasses.replace(e0, type="move", id=250)]),
        "wrong frame number": with_frame(f0, [dataclasses.replace(e0, frame=f0 + 1)]),
        "blob with blobs off": with_frame(f0, [dataclasses.replace(e0, type="blob", id=0xFF)]),
    }
    st_off = dataclasses.replace(st, blobs=False)
    for name, evs in cases.items():
        bad = rs.check(sc, st_off if "blob" in name else st, doctored(evs))
        assert bad, f"the checker missed: {name}"
    hm = np.array(ref.heatmaps)
    hm[0, 0, 0] = 1 << cfg.hm_width
    assert rs.check(sc, st, dataclasses.replace(ref, heatmaps=hm)), "the checker missed a wide cell"
    assert rs.check(sc, st, dataclasses.replace(ref, events=ref.events[:-1])), "missed a lost frame"


def test_random_scenes_cli_reports_a_failure(rs, tmp_path, monkeypatch, capsys):
    """A violation makes the script exit 1 with one line and the scene written out."""
    monkeypatch.setattr(rs, "check", lambda sc, st, ref: ["doctored"])
    assert rs.main(["--count", "1", "--seed", "5", "--fail-dir", str(tmp_path)]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "FAIL seed 5 index 0" in err[0]
    saved = list(tmp_path.glob("random_5_0*.json"))
    assert len(saved) == 2
