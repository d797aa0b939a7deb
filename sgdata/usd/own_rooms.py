"""Deprecated home of :mod:`sgdata.usd.user_rooms` (renamed: "user" is the one word for what a
user brings); it re-exports that module for one release."""

from sgdata.deprecation import warn_moved
from sgdata.usd.user_rooms import *  # noqa: F403
from sgdata.usd.user_rooms import __all__  # noqa: F401

warn_moved("sgdata.usd.own_rooms", "sgdata.usd.user_rooms")
