"""A small FFT length: ``rwadist fit DATA --nperseg 16`` (also 32, 40; diagnose too) ended in an internal error
(``cannot reshape array of size 117 into shape (13,1,32)``, exit 3) from the noise floor's 32-bin blocks
(:func:`rwadist.empirical.block_floor`), and ``rwadist.fit(dir, nperseg=16)`` raised a plain ValueError.  nperseg
samples give nperseg/2 + 1 frequency bins: below 62 they fill no block; such a value is refused by the one range
check (:data:`rwadist.validate.LIMITS`) naming the flag or parameter, the value and the smallest usable, 62."""
from __future__ import annotations

import numpy as np
import pytest

import rwadist
from rwadist.cli import main
from rwadist.empirical import block_floor


@pytest.fixture(scope="module")
def steady(tmp_path_factory):
    path = tmp_path_factory.mktemp("np") / "w"
    assert main(["simulate-test", str(path), "--preset", "ithaco-e", "--speeds-rpm", "600:3000",
                 "--n-speeds", "5", "--samples", "1024", "--seed", "1"]) == 0
    return path


@pytest.mark.parametrize("command", ["fit", "diagnose"])
@pytest.mark.parametrize("nperseg", [16, 32, 40, 61])
def test_cli_refuses_an_nperseg_below_one_floor_block(steady, tmp_path, capsys, command, nperseg):
    argv = [command, str(steady), "-o", str(tmp_path / ("m.json" if command == "fit" else "dn"))]
    argv += ["--no-report"] if command == "fit" else []
    code = main(argv + ["--nperseg", str(nperseg)])
    err = capsys.readouterr().err
    assert code == 2, err
    assert "internal error" not in err
    assert f"--nperseg: value: {nperseg}: out of range; allowed [62, " in err
    assert "62 is the smallest usable" in err


@pytest.mark.parametrize("call", [rwadist.fit, rwadist.diagnose])
def test_api_refuses_an_nperseg_below_one_floor_block(steady, call):
    with pytest.raises(rwadist.ParameterError) as info:
        call(str(steady), nperseg=16)
    text = str(info.value)
    assert text.startswith("nperseg: 16: out of range; allowed [62, ")
    assert "62 is the smallest usable" in text


def test_the_smallest_usable_nperseg_fits(steady, tmp_path, capsys):
    # taken (not refused, exit 2); on so short a segment the lines may all fall under the threshold (exit 1, the empty
    # model written for inspection)
    code = main(["fit", str(steady), "-o", str(tmp_path / "m.json"), "--no-report", "--nperseg", "62"])
    err = capsys.readouterr().err
    assert code == 0 or (code == 1 and "the model is empty" in err), err
    assert (tmp_path / "m.json").is_file()


def test_block_floor_of_a_spectrum_shorter_than_a_block():
    """A fit's default FFT length (the largest power of 2 in a run) may still be short: one block of every bin."""
    psd = np.tile(np.arange(1.0, 10.0), (3, 1))
    floor = block_floor(psd)
    assert floor.shape == psd.shape
    assert np.allclose(floor, floor[:, :1])
    assert np.all(np.isfinite(floor))


@pytest.mark.parametrize("samples, advice", [
    (50, "record at least 62 samples a run (the fewest a spectrum can use) or drop the run"),
    (100, "pass --nperseg between 62 and 100, or drop the run"),
])
def test_a_run_shorter_than_the_segment_gets_advice_it_can_follow(tmp_path, capsys, samples, advice):
    """A run shorter than the FFT segment was told to "pass a smaller nperseg" even when it held fewer samples than the
    smallest nperseg allowed (62), which that advice then refused (new-user trial 27)."""
    data = tmp_path / "w"
    assert main(["simulate-test", str(data), "--preset", "ithaco-e", "--speeds-rpm", "600:3000", "--n-speeds", "4",
                 "--samples", "1024", "--seed", "1"]) == 0
    run = sorted(data.glob("run_*.csv"))[1]
    lines = run.read_text().splitlines(keepends=True)
    run.write_text("".join(lines[:1 + samples]))
    code = main(["fit", str(data), "-o", str(tmp_path / "m.json"), "--no-report", "--nperseg", "128"])
    err = capsys.readouterr().err
    assert code == 2 and run.name in err and f"{samples} samples" in err, err
    assert advice in err, err
