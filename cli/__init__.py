"""Command-line front ends (installed as the ``sgdata_cli`` package): parse, call, print."""
