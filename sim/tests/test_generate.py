"""sim/fmt/generate.py: every generated file is current, and --check reports a stale one."""
from fmt import generate


def test_generated_files_current():
    st = generate.stale()
    assert not st, f"stale generated files {st}: run python -m fmt.generate"


def test_check_names_a_stale_file(monkeypatch, tmp_path, capsys):
    p = tmp_path / "x.hex"
    p.write_text("00\n")
    monkeypatch.setattr(generate, "generated", lambda: {p: lambda: "01\n"})
    assert generate.main(["--check"]) == 1
    assert capsys.readouterr().out.strip() == f"stale: {p} (run python -m fmt.generate)"
    assert generate.main([]) == 0 and p.read_text() == "01\n"
    assert generate.main(["--check"]) == 0
