"""Data in: measurement logs as the robots' tools write them, checked and prepared.

- :mod:`dynid.logs.log_files`: the checked measurement :class:`Log`, read from and written to NPZ
  or CSV (``load_log``, ``save_log``); :mod:`dynid.logs.columns`: the column names of a log file;
- :mod:`dynid.logs.preparation`: preparing a log for identification (``prepare_log``);
- :mod:`dynid.logs.signal`: filtering and differentiation of sampled signals.

This layer imports nothing of the model or the identification (docs/architecture.md).
"""

from .log_files import Log, load_log, save_log
from .preparation import prepare_log

__all__ = ["Log", "load_log", "prepare_log", "save_log"]
