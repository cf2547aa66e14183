"""The one source of dynid's version: pyproject.toml reads it from here (scikit-build-core's
regex metadata provider), and result files record it."""

__version__ = "0.2.0"


def dynid_version() -> str:
    return __version__
