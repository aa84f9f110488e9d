"""The ``gearwear`` command line: one module per command (its arguments, its run and its
printout) on one shared skeleton.

Nothing heavy is imported here: the signal handlers are installed first thing in
:func:`main`, and every command imports its numerical modules when it runs."""

from gearwear.cli.app import build_parser, main

__all__ = ["build_parser", "main"]
