"""fmtctl tuio against the simulated core (Verilator only): ``python -m bench.core.run_sim_rtl
--serve`` at the small sensor (sim/scenes/small.json: a still finger and a drag, events
every frame; the serve test's Server of tb/fmt_core, its own build tag), ``--serve-once``;
fmtctl tuio (--hold-frames 0) sends 6 reports to a python-osc receiver in the test; every
received bundle's session IDs and positions are the core's own events of that frame
(ev.log of the bench's loggers: new/move events, normalised to the sensor), and both
fingers arrive.  The UART drops an event that arrives while it is busy, so a report
holds a subset of its frame's events."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from bench.core import run_sim_rtl as rsr
from fmt import params
from fmt.host import events as E
from fmt_core.test_fmt_core_serve import CPS, Server

HERE = Path(__file__).parent
ROOT = HERE.parents[1]
FMTCTL = ROOT / "scripts" / "fmtctl"
sys.path.insert(0, str(HERE))

from test_host_tuio import Receiver  # noqa: E402

TAG = "tb_tuio"


@pytest.mark.verilator_only
def test_tuio_from_the_simulated_core(sim, tmp_path):
    assert sim == "verilator"
    cfg = params.SMALL
    srv = Server(tmp_path, "--serve-once", "--serve-seconds", "300", "--tag", TAG)
    rx = Receiver()
    try:
        port = srv.wait_serving(wall_s=900)
        r = subprocess.run([sys.executable, str(FMTCTL), "--port", port, "tuio", "--port", str(rx.port),
                            "--count", "6", "--hold-frames", "0", "--event-timeout", "60"],
                           capture_output=True, text=True, timeout=300)
        rc, text = srv.finish()
    finally:
        srv.kill()
        rx.close()
    assert r.returncode == 0 and "6 bundles" in r.stdout, r.stderr
    assert rc == 0 and "golden mismatches 0" in text, text
    _hm, _eof, evs, _fend = rsr.parse_logs(rsr.job_dir(cfg, CPS, TAG), cfg)
    s = E.Sensor(cfg.rows, cfg.cols)
    logged = {}
    for e in evs:
        if e["type"] in ("new", "move"):
            logged.setdefault(e["frame"], {})[e["id"]] = s.norm(e["x_q"], e["y_q"])
    got, cur, alive = {}, {}, []
    for addr, args in rx.msgs:
        if addr != "/tuio/2Dcur":
            continue
        if args[0] == "alive":
            alive, cur = args[1:], {}
        elif args[0] == "set":
            cur[args[1]] = tuple(args[2:4])
        elif args[0] == "fseq":
            assert sorted(cur) == sorted(alive)
            got[args[1]] = cur
    assert len(got) == 6, got
    # the UART drops an event that arrives while it is sending (docs/blocks/ctrl_port.md):
    # a report holds a subset of its frame's events, each exactly as the core made it
    for f, d in got.items():
        assert f in logged and d and set(d) <= set(logged[f]), (f, d, logged.get(f))
        for i, xy in d.items():
            assert xy == pytest.approx(logged[f][i], abs=1e-6), (f, i)
    assert set().union(*got.values()) == set().union(*(set(d) for d in logged.values()))  # both fingers
