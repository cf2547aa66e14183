"""Motions of a known model: uniform time scaling of a trajectory and its torques
(:mod:`~dynid.motion.time_scaling`) and non-uniform time scaling r(t)
(:mod:`~dynid.motion.nonuniform_scaling`)."""
