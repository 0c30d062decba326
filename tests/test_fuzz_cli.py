"""Fuzz sample of command-line values (issue 17; the full run: benchmarks/fuzz_all.py --surface cli).
Every case ends in exit 0 or a clear error naming the flag (or the missing file), never a traceback,
never a known-invalid value accepted."""
import fuzz_cases as fz


def test_fuzz_cli_values(tmp_path):
    results = [(fz.run_case(argv, names, invalid), argv) for argv, names, invalid in fz.cli_cases(60, 1, tmp_path)]
    bad = [(r, argv) for r, argv in results if r[0] not in ("ok", "clear")]
    assert not bad, bad[:5]
    counts = fz.tally(r for r, _ in results)
    assert counts["clear"] >= 30        # the sample does exercise refusals
