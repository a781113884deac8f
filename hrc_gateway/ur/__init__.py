"""The `ur-rtde` gateway backend: a real Universal Robots controller through ur-rtde.

`backend.URBackend` is the entry point; REGISTERS.md explains the register map,
the frame protocol that stands in for URUA's Bit64 handshake, and how to
install hrc_step_program.script on the robot.
"""
