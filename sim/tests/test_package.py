"""The installable package (pyproject.toml): `pip install -e .` into a fresh venv gives a
working `fmtctl` console script, scripts/fmtctl still works as a wrapper, and the pinned
environment names the host packages."""
from __future__ import annotations

import os
import re
import site
import subprocess
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_pyproject_names_the_packages_and_the_script():
    pp = tomllib.loads((ROOT / "pyproject.toml").read_text())
    assert pp["project"]["scripts"]["fmtctl"] == "fmt.host.cli:main"
    assert pp["tool"]["setuptools"]["package-dir"] == {"": "sim"}
    for pkg in pp["tool"]["setuptools"]["packages"]:
        assert (ROOT / "sim" / pkg.replace(".", "/") / "__init__.py").is_file(), pkg
    from fmt.host import cli
    assert callable(cli.main)


def test_requirements_pin_the_host_packages():
    pins = dict(re.findall(r"^([A-Za-z0-9_.-]+)==(\S+)$", (ROOT / "requirements.txt").read_text(), re.M))
    for name in ("python-osc", "evdev", "imageio", "fusesoc", "numpy", "pyserial", "matplotlib"):
        assert name in pins, name
    mk = (ROOT / "Makefile").read_text()
    assert "pip install -q --disable-pip-version-check --no-deps -e ." in mk


def test_scripts_fmtctl_wrapper():
    r = subprocess.run([sys.executable, str(ROOT / "scripts" / "fmtctl"), "regs"],
                       capture_output=True, text=True, timeout=60, env=dict(os.environ, PYTHONPATH=""))
    assert r.returncode == 0 and r.stdout.startswith("0x000 ID"), r.stderr


def test_pip_install_editable(tmp_path):
    """A fresh venv that sees this environment's packages (a .pth line), then
    pip install -e . as make setup does it (pip fetches the build backend, setuptools)."""
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(venv)], check=True, timeout=120)
    py = venv / "bin" / "python"
    sp = subprocess.run([str(py), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                        capture_output=True, text=True, check=True).stdout.strip()
    Path(sp, "zz_parent.pth").write_text("\n".join(site.getsitepackages()) + "\n")
    r = subprocess.run([str(py), "-m", "pip", "install", "-q", "--disable-pip-version-check",
                        "--no-deps", "-e", str(ROOT)],
                       capture_output=True, text=True, timeout=300, cwd=tmp_path)
    assert r.returncode == 0, r.stdout + r.stderr
    env = dict(os.environ, PYTHONPATH="")
    r = subprocess.run([str(venv / "bin" / "fmtctl"), "regs"], capture_output=True, text=True,
                       timeout=60, env=env, cwd=tmp_path)
    assert r.returncode == 0 and "SNAP_STATUS" in r.stdout, r.stderr
    r = subprocess.run([str(py), "-c", "import fmt; print(fmt.__file__)"], capture_output=True,
                       text=True, env=env, cwd=tmp_path)
    assert Path(r.stdout.strip()).resolve() == (ROOT / "sim" / "fmt" / "__init__.py").resolve()
