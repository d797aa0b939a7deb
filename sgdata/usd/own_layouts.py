"""Deprecated home of :mod:`sgdata.usd.user_layouts` (renamed, with ``OwnFrame`` ->
``UserFrame``, ``own_frame`` -> ``user_frame``, ``override_own`` -> ``override_user``); it
re-exports the old names for one release."""

from sgdata.deprecation import warn_moved
from sgdata.usd.user_layouts import UserFrame as OwnFrame
from sgdata.usd.user_layouts import override_user as override_own
from sgdata.usd.user_layouts import user_frame as own_frame

__all__ = ["OwnFrame", "own_frame", "override_own"]

warn_moved("sgdata.usd.own_layouts", "sgdata.usd.user_layouts")
