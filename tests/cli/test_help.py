"""The commands' help as a user reads it: text as written (a config's [catalog] section is not
eaten as markup) and switches shown as the switches they are."""

from __future__ import annotations

from tests.cli_runner import run_cli


def test_help_keeps_a_config_sections_brackets() -> None:
    done = run_cli("sgdata", "assets", "add", "--help")
    assert done.returncode == 0
    assert "([catalog] files of a" in done.stdout


def test_a_switch_is_shown_with_its_off_form_not_as_a_bool_value() -> None:
    done = run_cli("sgdata", "generate", "--help")
    assert "--resume / --no-resume" in done.stdout and "<bool>" not in done.stdout
    spec = run_cli("seannet", "compare", "--help").stdout
    assert "NAME[@net][+imagenet]" in spec.replace("\n", " ").replace("  ", " ")
