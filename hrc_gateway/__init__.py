"""The cobot gateway: one OPC UA server per cobot with URUA's address space.

`server.py` runs the asyncua server and maps client calls and writes onto a
`Backend` (`backend.py`): `sim/` simulates the cobot and the cell's devices,
`ur/` drives a Universal Robots controller through ur-rtde. `urua.py` is the
contract the web application's driver shares, `pki.py` the certificates and
users, `endpoints.py` how an endpoint is compared. Started by `hrc-gateway`
(`cli.py`), which installs and runs beside a robot without the web application;
it imports no Django and nothing of `hrc`.
"""
