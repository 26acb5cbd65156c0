"""fmt.progress (issue #15 item 7): on a terminal the progress line is rewritten in place;
in a log (not a terminal) whole lines, at most one per 10 % or 10 s, plus the last."""
import io

from fmt.progress import Progress


class Clock:
    def __init__(self):
        self.t = 0.0

    def __call__(self):
        return self.t


def test_log_gets_whole_lines_every_10_percent():
    s = io.StringIO()
    clk = Clock()
    p = Progress(10000, stream=s, clock=clk)
    assert not p.tty                                   # a StringIO is no terminal
    for i in range(1, 10001):
        clk.t += 0.0001
        p.update(i, f"\r  frame {i}/10000   ")
    p.close()
    text = s.getvalue()
    lines = text.splitlines()
    assert "\r" not in text and text.endswith("\n")
    assert len(lines) == 10 and lines[-1] == "frame 10000/10000"
    assert lines[0] == "frame 1000/10000"


def test_log_gets_a_line_every_10_seconds_when_slow():
    s = io.StringIO()
    clk = Clock()
    p = Progress(1000, stream=s, clock=clk)
    for i in range(1, 51):                             # 5 % of the work in 50 s
        clk.t += 1.0
        p.update(i, f"frame {i}")
    p.close()
    lines = s.getvalue().splitlines()
    assert lines == ["frame 10", "frame 20", "frame 30", "frame 40", "frame 50"]


def test_close_prints_the_last_state_once():
    s = io.StringIO()
    p = Progress(100, stream=s, clock=Clock())
    p.update(3, "frame 3")
    p.close()
    p.close()
    assert s.getvalue() == "frame 3\n"


def test_terminal_rewrites_one_line():
    s = io.StringIO()
    p = Progress(100, stream=s, tty=True)
    for i in range(1, 101):
        p.update(i, f"frame {i}")
    p.close()
    text = s.getvalue()
    assert text.count("\r") == 100 and text.count("\n") == 1 and text.endswith("frame 100\n")
