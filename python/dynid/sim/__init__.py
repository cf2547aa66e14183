"""Simulated robots: a closed-loop simulator and a virtual controller like the KUKA LWR's.

- :func:`simulate` runs a robot under a controller at the controller's rate (C++ integration
  loop, RK4 or semi-implicit Euler, zero-order hold on the torque, friction, torque noise,
  encoder quantisation): :mod:`~dynid.sim.closed_loop`, control laws in
  :mod:`~dynid.sim.controllers`.
- :class:`VirtualController` reports what the LWR's interface reports (numeric M(q), g(q),
  measured q and joint torques along a motion tracked in closed loop):
  :mod:`~dynid.sim.virtual_controller`.
- :func:`simulate_elastic` runs a robot with elastic joints (:class:`dynid.ElasticRobot`) the
  same way (C++ RK4, zero-order hold; zero torque, :class:`MotorPD`, the KUKA-like joint torque
  controller :class:`KukaLike` or a Python controller):
  :mod:`~dynid.sim.elastic_joints`.
- :func:`rehearse` is a dry run of an identification experiment: the arm tracks the trajectory
  and what its controller would log comes out (:mod:`~dynid.sim.rehearsal`).
"""

from .closed_loop import Simulation, plant_friction, simulate
from .controllers import PD, ComputedTorque, PDGravity
from .elastic_joints import ElasticSimulation, KukaLike, MotorPD, simulate_elastic
from .rehearsal import Rehearsal, rehearse
from .virtual_controller import (
    StaticReadings,
    TorqueRecording,
    VirtualController,
    paper_final_validation_trajectory,
    paper_validation_trajectory,
)

__all__ = [
    "PD",
    "ComputedTorque",
    "ElasticSimulation",
    "KukaLike",
    "MotorPD",
    "PDGravity",
    "Rehearsal",
    "Simulation",
    "StaticReadings",
    "TorqueRecording",
    "VirtualController",
    "paper_final_validation_trajectory",
    "paper_validation_trajectory",
    "plant_friction",
    "rehearse",
    "simulate",
    "simulate_elastic",
]
