"""``cmdragons`` command line: play | sim | vision | bench | node | replay | log.

Every command takes ``--config DIR`` (default ``./configs``) and repeatable
``--set concern.key.path=value`` overrides. ``commands`` holds the embedded commands, ``runtime`` the
distributed ones (zenoh is loaded only when one of them runs), ``vision`` the camera tools,
``progress`` the progress bar they share.
"""

from cmdragons.cli.commands import build_parser, main

__all__ = ["build_parser", "main"]
