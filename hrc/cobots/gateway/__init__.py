"""The cobot gateway: one OPC UA server per cobot with URUA's address space.

`server.py` runs the asyncua server and maps client calls and writes onto a
`Backend` (`backend.py`): `sim/` simulates the cobot and the cell's devices,
`ur/` drives a Universal Robots controller through ur-rtde. Started by
`python manage.py cobot_gateway`.
"""
