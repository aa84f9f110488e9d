"""``gearwear --help`` is the first command a new user types, and every usage error points to
it: it, ``-h`` and every ``gearwear COMMAND --help`` exit 0 and print usage, no traceback.

Regression class: argparse %-formats help strings, so one literal '%' ("95 % intervals")
made ``gearwear --help`` exit 1 with a traceback. The commands are read from the parser, so a
command added later is covered."""

from __future__ import annotations

import argparse
import subprocess
import sys

import pytest

from gearwear.cli import build_parser


def _commands() -> list[str]:
    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    return sorted(sub.choices)


def _run(*args):
    return subprocess.run([sys.executable, "-m", "gearwear.cli", *args], capture_output=True, text=True)


@pytest.mark.parametrize("flag", ["--help", "-h"])
def test_top_level_help(flag):
    r = _run(flag)
    assert r.returncode == 0 and r.stdout.startswith("usage: gearwear") and not r.stderr, r.stderr
    for name in _commands():
        assert name in r.stdout


@pytest.mark.parametrize("command", _commands())
def test_every_command_help(command):
    for flag in ("--help", "-h"):
        r = _run(command, flag)
        assert r.returncode == 0 and r.stdout.startswith(f"usage: gearwear {command}"), r.stderr
        assert "Traceback" not in r.stderr


def test_every_help_string_formats():
    """In process, without a subprocess per command: every action's help of every parser goes
    through argparse's % formatting."""
    parser = build_parser()
    parser.format_help()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    for p in sub.choices.values():
        p.format_help()
