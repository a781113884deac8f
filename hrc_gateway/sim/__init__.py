"""The simulated cobot backend (`--backend sim`): URSim + URUA + the cell's devices, in asyncio.

- `backend.py`: SimBackend, the Backend the gateway starts; commands, faults, persistence.
- `robot.py`: the arm and its controller: power, safety, program state, joints, motion.
- `kinematics.py`: UR5e forward and inverse kinematics, URScript pose algebra, motion profiles.
- `programs.py`: the prototype's seven programs as step plans.
- `runner.py`: the running program's loop: the step handshake with fencing token and OUTCOME.
- `fencing.py`: the step request and the execution log that makes redelivery harmless.
- `registers.py`: the input and output register file.
- `devices.py`: linear axis, part detection, inspection system, display.
- `sensors.py`: the use cases' recognition camera (gestures, face, screws) and place position.
- `faults.py`: the hang and slowdown faults injected into steps.
- `state.py`: the saved controller state (atomic JSON file).
- `clock.py`, `publisher.py`: scaled time; publishing only what changed.
- `timing.py`: the cell without running it (a step's time from its plan, a device's time and
  odds), for a prediction of a pattern (hrc.engine.prediction's plant).

No asyncua here: the gateway's `GatewaySpace` and `publish` are the only doors out.
"""

from hrc_gateway.sim.backend import SimBackend

__all__ = ["SimBackend"]
