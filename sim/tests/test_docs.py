"""The documentation is true to the tree: README size and commands, the module lists and
the instance hierarchy of rtl/README.md and docs/ARCHITECTURE.md, relative links.

Everything is computed from the files (the RTL sources, the Makefile), never from a list
written here, so adding, removing or renaming a module makes this fail until the two
documents follow.
"""
from __future__ import annotations

import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
README = ROOT / "README.md"
RTL_README = ROOT / "rtl" / "README.md"
ARCH = ROOT / "docs" / "ARCHITECTURE.md"
README_MAX_BYTES = 12_000
TOP = "fmt_core"
# folders searched for files and modules a document may name (build output excluded)
SEARCH_DIRS = ("rtl", "bench", "tb", "sim", "scripts", "formal", "constraints", "docs")
SKIP_PARTS = {"__pycache__", "sim_build", "build", ".venv"}

MODULE_RE = re.compile(r"^\s*module\s+(\w+)", re.M)


def _strip_comments(text: str) -> str:
    text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
    return re.sub(r"//[^\n]*", "", text)


def _files(pattern: str = "*"):
    for d in SEARCH_DIRS:
        base = ROOT / d
        if not base.is_dir():
            continue
        for f in base.rglob(pattern):
            if f.is_file() and not SKIP_PARTS.intersection(f.relative_to(ROOT).parts):
                yield f


def rtl_modules() -> dict[str, Path]:
    """Every module defined in rtl/*.v and rtl/ref/*.v: name -> file."""
    mods: dict[str, Path] = {}
    for d in (ROOT / "rtl", ROOT / "rtl" / "ref"):
        for f in sorted(d.glob("*.v")):
            for name in MODULE_RE.findall(_strip_comments(f.read_text())):
                mods[name] = f
    return mods


def all_modules() -> set[str]:
    """Every Verilog module anywhere in the searched folders (simulation tops too)."""
    return {n for f in _files("*.v") for n in MODULE_RE.findall(_strip_comments(f.read_text()))}


def _skip_parens(t: str, i: int) -> int:
    depth = 0
    while i < len(t):
        if t[i] == "(":
            depth += 1
        elif t[i] == ")":
            depth -= 1
            if depth == 0:
                return i + 1
        i += 1
    return i


def instantiated(text: str, known) -> set[str]:
    """Modules of `known` instantiated in `text`: NAME [#( ... )] INST [range] ( ."""
    t = _strip_comments(text)
    found = set()
    for m in re.finditer(r"\b([A-Za-z_]\w*)\b", t):
        name = m.group(1)
        if name not in known or t[:m.start()].rstrip().endswith("module"):
            continue
        i = m.end()
        while i < len(t) and t[i].isspace():
            i += 1
        if t.startswith("#", i):
            i += 1
            while i < len(t) and t[i].isspace():
                i += 1
            if not t.startswith("(", i):
                continue
            i = _skip_parens(t, i)
        if re.match(r"\s*[A-Za-z_]\w*\s*(\[[^\]]*\])?\s*\(", t[i:]):
            found.add(name)
    return found


def real_paths(top: str = TOP) -> set[str]:
    """The instance tree under `top` as a set of paths 'fmt_core/fmt_tx/...'."""
    mods = rtl_modules()
    paths: set[str] = set()

    def walk(name: str, prefix: str, seen: tuple):
        path = f"{prefix}/{name}" if prefix else name
        paths.add(path)
        assert name not in seen, f"recursive instantiation at {path}"
        for child in sorted(instantiated(mods[name].read_text(), mods)):
            walk(child, path, seen + (name,))

    walk(top, "", ())
    return paths


def doc_tree_block(md: Path) -> str:
    """The first fenced block after a heading that contains 'hierarchy'."""
    text = md.read_text()
    m = re.search(r"^#+ [^\n]*hierarchy[^\n]*\n(.*?)^```[^\n]*\n(.*?)^```", text, re.M | re.S | re.I)
    assert m, f"{md.relative_to(ROOT)}: no fenced block under a heading with 'hierarchy'"
    return m.group(2)


def doc_paths(md: Path) -> set[str]:
    """The tree of a document: one module per line, children indented under parents;
    the first word of a line is the module, the rest is commentary."""
    paths: set[str] = set()
    stack: list[tuple[int, str]] = []
    for line in doc_tree_block(md).splitlines():
        m = re.match(r"^(\s*)(fmt_\w+)", line)
        if not m:
            continue
        indent, name = len(m.group(1).expandtabs()), m.group(2)
        while stack and stack[-1][0] >= indent:
            stack.pop()
        path = "/".join([s[1] for s in stack] + [name])
        paths.add(path)
        stack.append((indent, path.split("/")[-1]))
    return paths


# ---------------------------------------------------------------------------------------

def test_readme_size():
    size = len(README.read_bytes())
    assert size <= README_MAX_BYTES, f"README.md is {size} bytes (limit {README_MAX_BYTES})"


def _makefile_targets() -> set[str]:
    return set(re.findall(r"^([A-Za-z][\w-]*)\s*:(?!=)", (ROOT / "Makefile").read_text(), re.M))


def test_readme_make_targets_exist():
    targets = _makefile_targets()
    named = set(re.findall(r"`make ([A-Za-z][\w-]*)", README.read_text()))
    assert named, "the README names no make target"
    assert not named - targets, f"README names make targets the Makefile lacks: {sorted(named - targets)}"


def test_readme_figures_name_their_command():
    """Every row of the headline-figures table (the table under the heading with
    'figures') names the command that gives it: a backticked make or python command."""
    text = README.read_text()
    m = re.search(r"^#+ [^\n]*figures[^\n]*\n(.*?)(?=^#)", text, re.M | re.S | re.I)
    assert m, "README: no section with 'figures' in its heading"
    rows = [r for r in m.group(1).splitlines() if r.startswith("|")][2:]
    assert len(rows) >= 4
    for row in rows:
        assert re.search(r"`(make |python |scripts/)[^`]*`", row), f"figure without its command: {row}"


@pytest.mark.parametrize("doc", [RTL_README, ARCH], ids=lambda p: str(p.relative_to(ROOT)))
def test_doc_names_every_module(doc):
    text = doc.read_text()
    missing = sorted(n for n in rtl_modules() if not re.search(rf"\b{n}\b", text))
    assert not missing, f"{doc.relative_to(ROOT)} does not name: {missing}"


def test_rtl_readme_names_every_include():
    text = RTL_README.read_text()
    missing = sorted(f.name for f in (ROOT / "rtl").glob("*.vh") if f.name not in text)
    assert not missing, f"rtl/README.md does not name: {missing}"


@pytest.mark.parametrize("doc", [RTL_README, ARCH], ids=lambda p: str(p.relative_to(ROOT)))
def test_doc_invents_no_module(doc):
    """Every backticked fmt_* name is a Verilog module, or with an extension (or a '*'
    glob) an existing file."""
    modules = all_modules()
    files = {f.name for f in _files()}
    bad = []
    for span in re.findall(r"`([^`\n]+)`", doc.read_text()):
        for m in re.finditer(r"(?<![\w.])(fmt_\w*)(\*)?(\.[A-Za-z]\w*)?", span):
            name, glob, ext = m.groups()
            if glob:
                ok = any(f.startswith(name) and (not ext or f.endswith(ext)) for f in files)
            elif ext:
                ok = name + ext in files
            else:
                ok = name in modules
            if not ok:
                bad.append(m.group(0))
    assert not bad, f"{doc.relative_to(ROOT)} names what does not exist: {sorted(set(bad))}"


@pytest.mark.parametrize("doc", [RTL_README, ARCH], ids=lambda p: str(p.relative_to(ROOT)))
def test_doc_instance_tree_is_the_real_one(doc):
    real, documented = real_paths(), doc_paths(doc)
    missing, invented = sorted(real - documented), sorted(documented - real)
    assert not missing and not invented, (
        f"{doc.relative_to(ROOT)} instance tree differs from the RTL:\n"
        f"  missing: {missing}\n  invented: {invented}")


DOCS = [README, RTL_README, *sorted((ROOT / "docs").rglob("*.md"))]


def _anchors(md: Path) -> set[str]:
    """GitHub's heading anchors: lower case, punctuation dropped, spaces -> '-'."""
    heads = re.findall(r"^#+\s+(.*?)\s*$", md.read_text(), re.M)
    return {re.sub(r"[^\w\- ]", "", h.lower()).replace(" ", "-") for h in heads}


@pytest.mark.parametrize("doc", DOCS, ids=lambda p: str(p.relative_to(ROOT)))
def test_relative_links_resolve(doc):
    bad = []
    for target in re.findall(r"\]\(([^)\s]+)\)", doc.read_text()):
        if re.match(r"[a-z]+:", target):
            continue
        path, _, anchor = target.partition("#")
        dest = doc.parent / path if path else doc
        if not dest.exists():
            bad.append(target)
        elif anchor and dest.suffix == ".md" and anchor not in _anchors(dest):
            bad.append(target)
    assert not bad, f"{doc.relative_to(ROOT)}: broken links {bad}"


def test_instance_scan():
    """The scan finds instances with and without parameters (nested parentheses) and
    instance arrays, and ignores comments, declarations and unknown names."""
    known = {"fmt_a", "fmt_b", "fmt_c", "fmt_d"}
    text = """
    module fmt_a #(parameter W = 4) (input wire clk);
    // fmt_d u_commented (.x());
    /* fmt_d u_block_comment (.x()); */
    fmt_b #(.W($clog2(W) + (W - 1))) u_b (.clk(clk));
    fmt_c u_c [3:0] (.clk(clk));
    fmt_missing_module u_err ();
    endmodule
    """
    assert instantiated(text, known) == {"fmt_b", "fmt_c"}
