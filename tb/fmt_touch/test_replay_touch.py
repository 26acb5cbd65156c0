"""scripts/replay_touch.py end to end: scene-rendered heat maps of the small sensor
through the RTL touch processing under Verilator, events written as JSON lines and
compared with fmt.touch.process_frames (--check)."""
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from fmt import params
from fmt_touch.touch_driver import scene_maps

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.verilator_only
def test_replay_touch_script(sim, tmp_path):
    cfg = params.SMALL
    maps = scene_maps(cfg, 12, (1 << cfg.hm_width) - 1, np.random.default_rng(5))
    inp, out = tmp_path / "hm.npy", tmp_path / "events.jsonl"
    np.save(inp, maps)
    r = subprocess.run([sys.executable, str(ROOT / "scripts" / "replay_touch.py"), "--in", str(inp),
                        "--out", str(out), "--config", "small", "--check"],
                       capture_output=True, text=True, timeout=900)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr[-3000:]
    events = [json.loads(line) for line in out.read_text().splitlines()]
    assert events and {"frame", "id", "type", "x_q", "y_q"} <= set(events[0])
    assert "bit-exact" in r.stdout
