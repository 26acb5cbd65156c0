"""Source lists of the RTL tops: the one place that says which files build a module.

``rtl/filelists/<top>.f`` lists the files of ``<top>`` (one path per line, relative to
the repository root; ``-f rtl/filelists/<child>.f`` includes a child's list;
``+incdir+rtl``; ``//`` comments).  A module that instantiates nothing needs no list:
its own file (``rtl/<top>.v`` or ``rtl/ref/<top>.v``) is its list.

Everything that builds RTL uses :func:`sources`: the cocotb runner, ``scripts/lint.sh``,
``scripts/synth.py`` and the ``make sim`` bench (``bench/core``).
:func:`check_filelists` compares every list with the instance hierarchy found in the
RTL (tb/common/test_sources.py runs it).

    python tb/common/sources.py TOP        the files of TOP, one per line
    python tb/common/sources.py --tops     the tops that have a list
    python tb/common/sources.py --check    compare the lists with the RTL (exit 1 on a mismatch)
"""
from __future__ import annotations

import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
RTL = ROOT / "rtl"
REF = RTL / "ref"
FILELISTS = RTL / "filelists"
INCLUDE_DIRS: list[Path] = [RTL]


def rom_define() -> str:
    """The define that points every ``$readmemh`` of rtl/ at the ROM files:
    ``-DFMT_ROM_DIR="<abs>/rtl/"`` (Verilator and Icarus build argument)."""
    return f'-DFMT_ROM_DIR="{RTL}/"'


def filelist(top: str) -> Path:
    return FILELISTS / f"{top}.f"


def module_file(name: str) -> Path:
    """rtl/<name>.v or rtl/ref/<name>.v."""
    for d in (RTL, REF):
        p = d / f"{name}.v"
        if p.exists():
            return p
    raise FileNotFoundError(f"no rtl/{name}.v or rtl/ref/{name}.v")


def _parse(path: Path, files: list, incdirs: list, seen: set) -> None:
    if path in seen:
        raise ValueError(f"{path}: included twice in one list (a cycle?)")
    seen = seen | {path}
    for n, raw in enumerate(path.read_text().splitlines(), 1):
        line = raw.split("//", 1)[0].strip()
        if not line:
            continue
        where = f"{path.relative_to(ROOT)}:{n}"
        if line.startswith("-f"):
            inc = ROOT / line[2:].strip()
            if not inc.exists():
                raise FileNotFoundError(f"{where}: {inc} does not exist")
            _parse(inc, files, incdirs, seen)
        elif line.startswith("+incdir+"):
            for d in line[len("+incdir+"):].split("+"):
                if d:
                    incdirs.append(ROOT / d)
        elif line.startswith(("-", "+")):
            raise ValueError(f"{where}: unsupported option {line!r}")
        else:
            p = ROOT / line
            if not p.exists():
                raise FileNotFoundError(f"{where}: {p} does not exist")
            files.append(p)


def _dedup(items) -> list:
    out, seen = [], set()
    for p in items:
        if p not in seen:
            seen.add(p)
            out.append(p)
    return out


def sources(top: str) -> list[Path]:
    """Absolute paths of the files of ``top`` (de-duplicated, list order kept)."""
    f = filelist(top)
    if not f.exists():
        return [module_file(top)]
    files: list = []
    _parse(f, files, [], set())
    return _dedup(files)


def include_dirs(top: str) -> list[Path]:
    """The ``+incdir+`` directories of ``top``'s list (INCLUDE_DIRS when it has none)."""
    f = filelist(top)
    dirs: list = []
    if f.exists():
        _parse(f, [], dirs, set())
    return _dedup(dirs) or list(INCLUDE_DIRS)


def tops() -> list[str]:
    """The modules that have a list."""
    return sorted(p.stem for p in FILELISTS.glob("*.f"))


# ---- check against the RTL -----------------------------------------------------------
def rtl_files() -> list[Path]:
    return sorted(RTL.glob("*.v")) + sorted(REF.glob("*.v"))


def _strip_comments(text: str) -> str:
    text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
    return re.sub(r"//[^\n]*", "", text)


def hierarchy() -> tuple[dict[str, Path], dict[str, set[str]]]:
    """(module -> file, module -> modules it instantiates) of rtl/*.v and rtl/ref/*.v.
    An instantiation is a known module name at the start of a statement followed by
    ``#(`` or an instance name and ``(``; generate branches count (a list holds every
    module a parameter may select)."""
    files, text = {}, {}
    for f in rtl_files():
        t = _strip_comments(f.read_text())
        for m in re.findall(r"^\s*module\s+(\w+)", t, re.M):
            if m in files:
                raise ValueError(f"module {m} defined in {files[m]} and {f}")
            files[m] = f
            text[m] = t
    inst_re = re.compile(r"(?:^|[;\s])(\w+)\s*(?:#\s*\(|\w+\s*\()", re.M)
    children = {}
    for m, t in text.items():
        children[m] = {n for n in inst_re.findall(t) if n in files and n != m}
    return files, children


def closure(top: str, files: dict, children: dict) -> set[Path]:
    out, todo = set(), [top]
    while todo:
        m = todo.pop()
        if files[m] in out:
            continue
        out.add(files[m])
        todo.extend(children[m])
    return out


def check_filelists() -> list[str]:
    """Problems of the lists, one line each (empty: every list matches the RTL):
    a list whose files differ from its top's instance closure (missing / extra), a list
    without a module, a module with submodules but no list, and an RTL file that no list
    reaches and that is not a leaf."""
    files, children = hierarchy()
    rel = lambda p: str(p.relative_to(ROOT))
    problems = []
    listed: set = set()
    for top in tops():
        if top not in files:
            problems.append(f"rtl/filelists/{top}.f: no module {top} in rtl/ or rtl/ref/")
            continue
        try:
            got = sources(top)
        except (OSError, ValueError) as e:
            problems.append(f"rtl/filelists/{top}.f: {e}")
            continue
        listed.update(got)
        want = closure(top, files, children)
        for p in sorted(want - set(got)):
            problems.append(f"rtl/filelists/{top}.f: missing {rel(p)}")
        for p in sorted(set(got) - want):
            problems.append(f"rtl/filelists/{top}.f: extra {rel(p)}")
        if got and got[0] != files[top]:
            problems.append(f"rtl/filelists/{top}.f: the first file is not {rel(files[top])}")
    have = set(tops())
    for m in sorted(files):
        if children[m] and m not in have:
            problems.append(f"{rel(files[m])}: {m} instantiates {', '.join(sorted(children[m]))} "
                            f"but has no rtl/filelists/{m}.f")
    for f in rtl_files():
        mods = [m for m, p in files.items() if p == f]
        if f not in listed and any(children[m] for m in mods):
            problems.append(f"{rel(f)}: in no list and not a leaf")
    return problems


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if argv == ["--check"]:
        problems = check_filelists()
        for p in problems:
            print(p)
        return 1 if problems else 0
    if argv == ["--tops"]:
        print("\n".join(tops()))
        return 0
    if len(argv) == 1 and not argv[0].startswith("-"):
        print("\n".join(str(p) for p in sources(argv[0])))
        return 0
    print("usage: sources.py TOP | --tops | --check", file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main())
