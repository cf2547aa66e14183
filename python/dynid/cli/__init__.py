"""The ``dynid`` command line: :mod:`.parsers` defines the arguments, :mod:`.commands` calls the
library with them and prints; no workflow lives here."""

from .main import main

__all__ = ["main"]
