"""Checks of user input shared by the entry points (scripts/replay_*.py, ``python -m
fmt.run_sim``, ``python -m bench.core.run_sim_rtl``, scene and settings files).

Every bad input ends in :class:`InputError` (a ValueError) whose text is one line that
names the file, key or argument; the entry points print it to stderr and exit non-zero
(2 for bad input, 1 for a failed run).  Outputs are written under a temporary name and
renamed only when the run succeeded (:func:`temp_output`, :func:`commit_output`), so a
failed run never reports an old file as new.
"""
from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

import numpy as np


class InputError(ValueError):
    """Bad user input: the message is one line."""


class OneLineParser(argparse.ArgumentParser):
    """argparse with a one-line error (``prog: error: ...``, exit 2) instead of the usage
    block followed by the error."""

    def error(self, message):
        sys.stderr.write(f"{self.prog}: error: {' '.join(str(message).split())}\n")
        raise SystemExit(2)


def one_line(e: BaseException) -> str:
    """The text of an exception on one line."""
    return " ".join(str(e).split()) or type(e).__name__


def load_int_array(path, what: str, shape: tuple, lo: int, hi: int,
                   allow_empty: bool = False) -> np.ndarray:
    """Load ``path`` (.npy) and check it: an integer dtype (bool and float refused, never
    truncated), ``len(shape)`` dimensions, each dimension equal to ``shape[i]`` unless that
    is None, every value in ``lo .. hi`` (no wrap).  Returns it as int64."""
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{what} {path}: no such file")
    try:
        a = np.load(path, allow_pickle=False)
    except Exception as e:  # noqa: BLE001 -- any unreadable file is bad input
        raise InputError(f"{what} {path}: not a readable .npy array ({one_line(e)})") from None
    if not isinstance(a, np.ndarray):
        raise InputError(f"{what} {path}: not a single .npy array")
    return check_int_array(a, f"{what} {path}", shape, lo, hi, allow_empty)


def check_int_array(a, what: str, shape: tuple, lo: int, hi: int,
                    allow_empty: bool = False) -> np.ndarray:
    """The checks of :func:`load_int_array` on an array in memory (``what`` names it)."""
    path = what
    a = np.asarray(a)
    if a.dtype == np.bool_ or not np.issubdtype(a.dtype, np.integer):
        raise InputError(f"{path}: dtype {a.dtype}, expected integers "
                         f"(floats are refused, not truncated)")
    want = "(" + ", ".join("any" if s is None else str(s) for s in shape) + ")"
    if a.ndim != len(shape) or any(s is not None and n != s for n, s in zip(a.shape, shape)):
        raise InputError(f"{path}: shape {a.shape}, expected {want}")
    if a.size == 0 and not allow_empty:
        raise InputError(f"{path}: empty, shape {a.shape}")
    if a.size:
        mn, mx = int(a.min()), int(a.max())
        if mn < lo or mx > hi:
            bad = mn if mn < lo else mx
            idx = tuple(int(i) for i in np.argwhere(a == bad)[0])
            raise InputError(f"{path}: value {bad} at {idx} outside {lo} .. {hi}")
    return a.astype(np.int64)


def temp_output(out: Path, suffix: str = "") -> Path:
    """A temporary name next to ``out`` (same directory, so the rename is atomic) that
    ends like ``out`` (``suffix`` overrides the ending, e.g. ``.npy`` for np.save)."""
    out = Path(out)
    end = suffix or out.suffix
    return out.with_name(f".{out.name}.{os.getpid()}.tmp{end}")


def commit_output(tmp: Path, out: Path) -> None:
    """Rename ``tmp`` to ``out`` (atomic on one file system); a missing ``tmp`` means the
    run did not write its output (RuntimeError)."""
    tmp, out = Path(tmp), Path(out)
    if not tmp.is_file():
        raise RuntimeError(f"the run wrote no output ({tmp.name}); {out} not written")
    os.replace(tmp, out)


def remove_quietly(*paths) -> None:
    for p in paths:
        try:
            Path(p).unlink()
        except OSError:
            pass


def check_fields(d, allowed: dict, where: str) -> None:
    """``d`` must be a mapping whose keys are in ``allowed`` (key -> check(value) that
    returns an error text or None)."""
    if not isinstance(d, dict):
        raise InputError(f"{where}: expected an object of keys, got {type(d).__name__}")
    for k, v in d.items():
        if k not in allowed:
            raise InputError(f"{where}: unknown key '{k}' (known: {', '.join(sorted(allowed))})")
        msg = allowed[k](v)
        if msg:
            raise InputError(f"{where}: key '{k}': {msg}, got {v!r}")


# value checks for check_fields: each returns an error text or None
def is_int(lo=None, hi=None, none_ok=False):
    def f(v):
        if v is None and none_ok:
            return None
        if isinstance(v, bool) or not isinstance(v, (int, np.integer)):
            return "must be an integer"
        if lo is not None and v < lo:
            return f"must be >= {lo}" if hi is None else f"must be in {lo} .. {hi}"
        if hi is not None and v > hi:
            return f"must be <= {hi}" if lo is None else f"must be in {lo} .. {hi}"
        return None
    return f


def is_num(lo=None, hi=None, none_ok=False, lo_open=False):
    def f(v):
        if v is None and none_ok:
            return None
        if isinstance(v, bool) or not isinstance(v, (int, float, np.integer, np.floating)):
            return "must be a number"
        if not np.isfinite(v):
            return "must be finite"
        if lo is not None and (v < lo or (lo_open and v == lo)):
            return f"must be {'>' if lo_open else '>='} {lo}"
        if hi is not None and v > hi:
            return f"must be <= {hi}"
        return None
    return f


def is_str(choices=None):
    def f(v):
        if not isinstance(v, str):
            return "must be a string"
        if choices is not None and v not in choices:
            return f"must be one of {', '.join(choices)}"
        return None
    return f


def is_bool(v):
    return None if isinstance(v, bool) else "must be true or false"


def is_type(*types, name=""):
    def f(v):
        return None if isinstance(v, types) else f"must be {name or ' or '.join(t.__name__ for t in types)}"
    return f
