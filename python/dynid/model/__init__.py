"""The robot model: :class:`~dynid.model.robot.Robot` (DH table, inertial parameters, drives),
ready-made arms (:mod:`~dynid.model.models`), URDF in and out (:mod:`dynid.model.urdf`), model
files (:mod:`~dynid.model.model_files`), elastic joints (:mod:`~dynid.model.elastic`), the
base parameters of its regressor (:mod:`~dynid.model.base_parameters`) and what follows from the
model alone (link frames, operational space, linearization, bounds on the dynamic terms).

The lowest layer above the C++ core: it imports nothing else of dynid (docs/architecture.md).
"""
