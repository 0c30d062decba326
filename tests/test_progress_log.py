"""Progress written to a log (stderr redirected to a file or a pipe) is plain lines: no carriage return, no cursor
move, a bounded number of lines, the final state last; on a terminal it stays tqdm's one refreshed line."""
import io
import subprocess
import sys

from rwadist import progress


class _Terminal(io.StringIO):
    def isatty(self):
        return True


def test_a_counted_bar_in_a_log_is_its_first_and_final_state(capsys):
    bar = progress.steps(40, "writing the report")
    for _ in range(40):
        bar.update()
    bar.close()
    err = capsys.readouterr().err
    assert "\r" not in err and "\x1b" not in err
    lines = err.splitlines()
    assert len(lines) == 2                              # 40 updates within LOG_INTERVAL_S: the start and the end
    assert "0/40" in lines[0] and "40/40" in lines[1]


def test_an_elapsed_line_in_a_log_is_bounded_by_the_interval(capsys, monkeypatch):
    monkeypatch.setattr(progress, "LOG_INTERVAL_S", 0.2)
    with progress.working("searching", interval_s=0.01):
        import time
        time.sleep(0.7)                                 # ~70 refreshes; at most one line per 0.2 s is written
    err = capsys.readouterr().err
    lines = err.splitlines()
    assert "\r" not in err and 3 <= len(lines) <= 6, lines
    assert all(ln.startswith("searching: ") and ln.endswith(" elapsed") for ln in lines)


def test_on_a_terminal_the_bar_refreshes_one_line():
    stream = _Terminal()
    bar = progress.steps(3, "x")
    bar.close()
    bar = progress.tqdm(total=3, desc="x", file=stream, mininterval=0, leave=False)
    for _ in range(3):
        bar.update()
    bar.close()
    assert stream.getvalue().count("\r") >= 3 and "\n" not in stream.getvalue()


def test_a_command_redirected_to_a_file_writes_no_carriage_return(tmp_path):
    data, log = tmp_path / "e", tmp_path / "console.txt"
    cmd = [sys.executable, "-m", "rwadist"]
    subprocess.run(cmd + ["simulate-test", "--preset", "ithaco-e", str(data), "--speeds-rpm", "600:2400",
                          "--n-speeds", "6", "--samples", "2048", "--sample-rate", "1920", "--no-modes"],
                   check=True, capture_output=True)
    with open(log, "w") as stderr:
        done = subprocess.run(cmd + ["fit", str(data), "-o", str(tmp_path / "m.json")], stderr=stderr,
                              stdout=subprocess.DEVNULL)
    text = log.read_bytes().decode()                 # bytes: reading text would turn a carriage return into \n
    assert done.returncode == 0, text
    assert "\r" not in text and "\x1b" not in text and "\n\n" not in text
    assert "rwadist fit" in text and "writing the report" in text     # progress is still there, line by line
