"""Data in: measurement logs as the robots' tools write them, checked and prepared.

- :mod:`dynid.logs.log_files`: the checked measurement :class:`Log`, loaded in any registered
  format and written to NPZ or CSV (``load_log``, ``save_log``);
- :mod:`dynid.logs.formats`: the registry of log formats (``LogFormat``, ``detect``), and
  :mod:`dynid.logs.readers`: one reader per format (UR RTDE, libfranka, pyfri/FRI, any CSV, NPZ,
  MATLAB); :mod:`dynid.logs.columns`: the column names of a log file;
- :mod:`dynid.logs.preparation`: preparing a log for identification (``prepare_log``);
- :mod:`dynid.logs.signal`: filtering and differentiation of sampled signals.

This layer imports nothing of the model or the identification (docs/architecture.md).
"""

from .log_files import Log, load_log, save_log
from .preparation import prepare_log

__all__ = ["Log", "load_log", "prepare_log", "save_log"]
