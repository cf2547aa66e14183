"""Motions of a known model: uniform time scaling of a trajectory and its torques
(:mod:`~dynid.motion.time_scaling`)."""
