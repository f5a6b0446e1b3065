"""Helpers shared by the command modules: one-line user errors, JSON output, the --json flag."""

from __future__ import annotations

import json

import click
import numpy as np


class UserError(click.ClickException):
    """One-line error, exit code 2."""

    exit_code = 2

    def show(self, file=None):
        click.echo(f"error: {self.format_message()}", err=True, file=file)


def _json_default(o):
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, (np.floating, np.integer, np.bool_)):
        return o.item()
    raise TypeError(f"not JSON serialisable: {type(o).__name__}")


def emit_json(data) -> None:
    click.echo(json.dumps(data, indent=2, default=_json_default, allow_nan=False))


json_option = click.option("--json", "as_json", is_flag=True, help="Print machine-readable JSON.")
