"""Files in and out: measurement logs, robot models and identification results.

- :mod:`dynid.io.log_files`: the checked measurement :class:`Log`, read from and written to NPZ
  or CSV (``load_log``, ``save_log``);
- :mod:`dynid.io.preparation`: preparing a log for identification (``prepare_log``);
- :mod:`dynid.io.model_files`: robot models as JSON/YAML files or built-in names
  (``load_model``, ``save_model``);
- :mod:`dynid.io.result_files`: identification results on disk (``save_result``,
  ``load_result``).

Only the log layer is imported here; the model and result files are imported from their modules
(or from the top-level ``dynid``), so that importing ``dynid.io`` pulls in no identification code.
"""

from .log_files import Log, load_log, save_log
from .preparation import prepare_log

__all__ = ["Log", "load_log", "prepare_log", "save_log"]
