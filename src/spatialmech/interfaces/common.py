"""Helpers shared by the command modules: one-line user errors, JSON output, the --json flag."""

from __future__ import annotations

import json

import click

from ..serialize import json_default


class UserError(click.ClickException):
    """One-line error, exit code 2."""

    exit_code = 2

    def show(self, file=None):
        click.echo(f"error: {self.format_message()}", err=True, file=file)


def emit_json(data) -> None:
    click.echo(json.dumps(data, indent=2, default=json_default, allow_nan=False))


json_option = click.option("--json", "as_json", is_flag=True, help="Print machine-readable JSON.")
