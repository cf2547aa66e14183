"""The log layer under its 0.2 name: ``dynid.io`` re-exports :mod:`dynid.logs`.

Kept so that code written against dynid 0.2 (``from dynid.io import Log, load_log``) runs
unchanged. New code imports from :mod:`dynid.logs`; the model and result files that
``dynid.io``'s submodules held are now :mod:`dynid.model.model_files` and
:mod:`dynid.export.result_files` (see docs/architecture.md).
"""

from .logs import Log, load_log, prepare_log, save_log

__all__ = ["Log", "load_log", "prepare_log", "save_log"]
