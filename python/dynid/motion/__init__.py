"""Motions of a known model: uniform time scaling of a trajectory and its torques
(:mod:`~dynid.motion.time_scaling`), non-uniform time scaling r(t)
(:mod:`~dynid.motion.nonuniform_scaling`) and optimal point-to-point motion
(:mod:`~dynid.motion.optimal_motion`)."""
