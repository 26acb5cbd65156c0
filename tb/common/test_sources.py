"""The source lists (rtl/filelists/*.f) against the instance hierarchy of the RTL."""
from common import sources as S


def test_filelists_match_the_rtl():
    problems = S.check_filelists()
    assert not problems, "rtl/filelists out of date:\n" + "\n".join(problems)


def test_every_rtl_file_is_listed_or_a_leaf():
    files, children = S.hierarchy()
    listed = {p for top in S.tops() for p in S.sources(top)}
    for f in S.rtl_files():
        mods = [m for m, p in files.items() if p == f]
        assert mods, f"{f}: no module"
        assert f in listed or not any(children[m] for m in mods), f"{f}: in no list and not a leaf"


def test_sources_of_a_leaf_and_a_list():
    assert S.sources("fmt_div") == [S.RTL / "fmt_div.v"]
    core = S.sources("fmt_core")
    assert core[0] == S.RTL / "fmt_core.v" and len(core) == len(set(core))
    assert set(S.sources("fmt_touch")) <= set(core)
    assert S.rom_define() == f'-DFMT_ROM_DIR="{S.RTL}/"'


def test_check_reports_a_missing_file(tmp_path, monkeypatch):
    """A copy of the tree with one file left out of fmt_tracker.f."""
    rtl = tmp_path / "rtl"
    for d in ("", "ref", "filelists"):
        (rtl / d).mkdir(exist_ok=True)
        for f in (S.RTL / d).glob("*.[vf]"):
            (rtl / d / f.name).write_text(f.read_text())
    t = rtl / "filelists" / "fmt_tracker.f"
    t.write_text(t.read_text().replace("rtl/fmt_tracker_vel.v\n", ""))
    for k, v in (("ROOT", tmp_path), ("RTL", rtl), ("REF", rtl / "ref"), ("FILELISTS", rtl / "filelists")):
        monkeypatch.setattr(S, k, v)
    problems = S.check_filelists()
    assert "rtl/filelists/fmt_tracker.f: missing rtl/fmt_tracker_vel.v" in problems, problems
    assert all("fmt_tracker" in p for p in problems), problems
