"""Identification: from a model and data to parameters.

Least squares (:mod:`~dynid.identification.identify`, :mod:`~dynid.identification.streaming`,
:mod:`~dynid.identification.recursive`), the physically consistent fit
(:mod:`~dynid.identification.physical`), a robot's log
(:mod:`~dynid.identification.log_identification`
with its column blocks, :mod:`~dynid.identification.blocks`: friction, offsets, position
torque), the paper's method from controller data
(:mod:`~dynid.identification.from_controller`), payloads, drive gains, elastic drives, the
validation metrics and the momentum observer. Imports the model and the logs layers, never the
files written from results (docs/architecture.md).
"""
