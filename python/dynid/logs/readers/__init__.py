"""The log readers, one file per format, each registered here with one line (the registry:
:mod:`dynid.logs.formats`). Formats recognised by their header come first; the generic ones
(any CSV, NPZ, MATLAB) are tried after every specific one.

Importing this package registers the formats; ``dynid.logs.formats`` does it on first use.
"""

from __future__ import annotations

from ..formats import register
from . import fri, generic_csv, libfranka, matlab, npz, ros_bag, ur_rtde

register(ur_rtde.FORMAT)
register(libfranka.FORMAT)
register(fri.FORMAT)
register(ros_bag.FORMAT)  # its own suffixes: its place in the order does not matter
register(generic_csv.FORMAT, generic=True)
register(npz.FORMAT, generic=True)
register(matlab.FORMAT, generic=True)
