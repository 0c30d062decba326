"""Every option is documented in the repository (issue 36): each option and positional of every command of the
parser, each `--inject` kind and parameter, is described in docs/cli.md in its command's section; the NASTRAN
conventions are in docs/nastran.md; the README links both."""
from __future__ import annotations

import argparse
import re
from pathlib import Path

from rwadist.cli import build_parser
from rwadist.inject import kinds

ROOT = Path(__file__).resolve().parents[1]
DOC = (ROOT / "docs" / "cli.md").read_text()


def _commands(parser, name=""):
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for sub_name, sub in action.choices.items():
                yield from _commands(sub, f"{name} {sub_name}".strip())
    if name:
        yield name, parser


def _section(command: str) -> str:
    """The text of docs/cli.md under the heading that names ``rwadist <command>``."""
    parts = re.split(r"^## ", DOC, flags=re.M)
    hits = [p for p in parts if p.startswith(f"`rwadist {command}") or
            f"`rwadist {command} " in p.splitlines()[0] or f"`rwadist {command}`" in p.splitlines()[0]]
    assert hits, f"no section of docs/cli.md for rwadist {command}"
    return hits[0]


def test_every_option_of_every_command_is_described_in_its_section():
    missing = []
    for command, parser in _commands(build_parser()):
        text = _section(command)
        for action in parser._actions:
            if isinstance(action, (argparse._HelpAction, argparse._SubParsersAction)):
                continue
            names = action.option_strings or [action.dest.upper()]
            for name in names:
                row = re.search(rf"^\| [^|]*`{re.escape(name)}`[^|]* \| (.+) \|$", text, flags=re.M)
                if row is None or len(row.group(1).strip()) < 10:
                    missing.append(f"{command} {name}")
    assert not missing, missing


def test_every_inject_kind_and_parameter_is_described():
    section = DOC.split("### `--inject` kinds and parameters", 1)[1].split("\n## ", 1)[0]
    for kind, cls in kinds().items():
        assert f"`{kind}`" in section, kind
        for param in cls.INJECT:
            assert f"`{param}`" in section, (kind, param)


def test_nastran_conventions_and_links():
    nastran = (ROOT / "docs" / "nastran.md").read_text()
    for term in ("subcase", "SID", "TABRND1", "RANDPS", "TID", "real", "imaginary", "X = 1.0", "Y = 1.0",
                 "--nastran-auto-only", "coherence"):
        assert term in nastran, term
    readme = (ROOT / "README.md").read_text()
    assert "docs/nastran.md" in readme and "docs/cli.md" in readme
