"""URDF in and out (docs/urdf.md): :meth:`dynid.Robot.from_urdf` and :meth:`dynid.Robot.to_urdf`
call this package; it does not import :mod:`dynid.model.robot`.

- :mod:`.tree`: the XML read into links and joints, the serial chain between two links;
- :mod:`.frames`: DH frames along arbitrary joint axes (standard or modified);
- :mod:`.reading`: the chain as a DH model (table, base, tool, parameters, limits, friction);
- :mod:`.writing`: a DH model written as URDF text;
- :mod:`.consistency`: the physical rule both apply (``to_urdf`` and ``from_urdf`` refuse alike).
"""

from .reading import DHModel, dh_model_from_urdf
from .writing import urdf_text, write_urdf

__all__ = ["DHModel", "dh_model_from_urdf", "urdf_text", "write_urdf"]
