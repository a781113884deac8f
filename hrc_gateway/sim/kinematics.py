"""UR5e kinematics in plain Python: forward, inverse (damped least squares), pose algebra.

Poses are URScript poses, (x, y, z, rx, ry, rz) in metres and a rotation
vector (axis × angle, radians), in the robot's base frame. Joints are six
angles in radians, base first. Pure Python on purpose: the gateway needs no
numpy, and a 6×6 problem is small.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Final

Vector = tuple[float, float, float]
Matrix = tuple[Vector, Vector, Vector]  # rows
Pose = tuple[float, float, float, float, float, float]
Joints = tuple[float, float, float, float, float, float]

# UR5e standard Denavit–Hartenberg parameters (Universal Robots' published values).
D: Final = (0.1625, 0.0, 0.0, 0.1333, 0.0997, 0.0996)
A: Final = (0.0, -0.425, -0.3922, 0.0, 0.0, 0.0)
ALPHA: Final = (math.pi / 2, 0.0, 0.0, math.pi / 2, -math.pi / 2, 0.0)

# The prototype's programs set the TCP to p[0, 0, 0.1, 0, π, 0] (§4.1): 10 cm out
# of the flange, its z axis pointing back at the flange. A feature pose with no
# rotation therefore means "flange pointing down".
TCP: Final[Pose] = (0.0, 0.0, 0.1, 0.0, math.pi, 0.0)

# Home: the textbook UR pose (upper arm up, forearm level, flange pointing down)
# with the base turned to face +x, where the prototype's features lie; the TCP
# is then at (0.49, 0.13, 0.39).
HOME: Final[Joints] = (math.pi, -math.pi / 2, math.pi / 2, -math.pi / 2, -math.pi / 2, 0.0)

# UR e-series joints turn ±360°.
JOINT_LIMIT: Final = 2 * math.pi

IDENTITY: Final[Matrix] = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))


class Unreachable(ValueError):
    """No joint configuration puts the TCP at the pose (out of reach, or past a joint limit)."""


# Small vector and matrix algebra -------------------------------------------------


def _add(a: Vector, b: Vector) -> Vector:
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def _sub(a: Vector, b: Vector) -> Vector:
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def _cross(a: Vector, b: Vector) -> Vector:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def norm(v: Sequence[float]) -> float:
    return math.sqrt(sum(x * x for x in v))


def _matmul(m: Matrix, n: Matrix) -> Matrix:
    cols = tuple(zip(*n, strict=True))
    return tuple(
        tuple(sum(a * b for a, b in zip(row, col, strict=True)) for col in cols) for row in m
    )  # type: ignore[return-value]


def _apply(m: Matrix, v: Vector) -> Vector:
    return (
        m[0][0] * v[0] + m[0][1] * v[1] + m[0][2] * v[2],
        m[1][0] * v[0] + m[1][1] * v[1] + m[1][2] * v[2],
        m[2][0] * v[0] + m[2][1] * v[1] + m[2][2] * v[2],
    )


def _transpose(m: Matrix) -> Matrix:
    return tuple(zip(*m, strict=True))  # type: ignore[return-value]


def rotation_matrix(rotvec: Vector) -> Matrix:
    """The rotation a rotation vector stands for (Rodrigues' formula)."""
    angle = norm(rotvec)
    if angle < 1e-12:
        return IDENTITY
    x, y, z = (c / angle for c in rotvec)
    c, s = math.cos(angle), math.sin(angle)
    t = 1 - c
    return (
        (t * x * x + c, t * x * y - s * z, t * x * z + s * y),
        (t * x * y + s * z, t * y * y + c, t * y * z - s * x),
        (t * x * z - s * y, t * y * z + s * x, t * z * z + c),
    )


def rotation_vector(m: Matrix) -> Vector:
    """The rotation vector of a rotation matrix, angle in [0, π]."""
    cos_angle = max(-1.0, min(1.0, (m[0][0] + m[1][1] + m[2][2] - 1) / 2))
    angle = math.acos(cos_angle)
    if angle < 1e-9:
        return (0.0, 0.0, 0.0)
    if math.pi - angle > 1e-6:
        scale = angle / (2 * math.sin(angle))
        return (
            (m[2][1] - m[1][2]) * scale,
            (m[0][2] - m[2][0]) * scale,
            (m[1][0] - m[0][1]) * scale,
        )
    # Near π the antisymmetric part vanishes; the axis comes from the diagonal.
    xx, yy, zz = ((m[i][i] + 1) / 2 for i in range(3))
    if xx >= yy and xx >= zz:
        x = math.sqrt(max(xx, 0.0))
        axis = (x, (m[0][1] + m[1][0]) / (4 * x), (m[0][2] + m[2][0]) / (4 * x))
    elif yy >= zz:
        y = math.sqrt(max(yy, 0.0))
        axis = ((m[0][1] + m[1][0]) / (4 * y), y, (m[1][2] + m[2][1]) / (4 * y))
    else:
        z = math.sqrt(max(zz, 0.0))
        axis = ((m[0][2] + m[2][0]) / (4 * z), (m[1][2] + m[2][1]) / (4 * z), z)
    length = norm(axis)
    return (axis[0] / length * angle, axis[1] / length * angle, axis[2] / length * angle)


def _split(pose: Sequence[float]) -> tuple[Matrix, Vector]:
    return rotation_matrix((pose[3], pose[4], pose[5])), (pose[0], pose[1], pose[2])


def _join(rotation: Matrix, position: Vector) -> Pose:
    r = rotation_vector(rotation)
    return (position[0], position[1], position[2], r[0], r[1], r[2])


def pose_trans(p_from: Sequence[float], p_from_to: Sequence[float]) -> Pose:
    """URScript's pose_trans: `p_from_to` expressed in the frame `p_from` (feature ⊕ offset)."""
    r1, t1 = _split(p_from)
    r2, t2 = _split(p_from_to)
    return _join(_matmul(r1, r2), _add(_apply(r1, t2), t1))


def pose_inv(pose: Sequence[float]) -> Pose:
    """URScript's pose_inv."""
    r, t = _split(pose)
    rt = _transpose(r)
    minus = _apply(rt, t)
    return _join(rt, (-minus[0], -minus[1], -minus[2]))


def pose_distance(a: Sequence[float], b: Sequence[float]) -> tuple[float, float]:
    """(metres, radians) between two poses: translation and rotation apart."""
    ra, ta = _split(a)
    rb, tb = _split(b)
    return norm(_sub(ta, tb)), norm(rotation_vector(_matmul(rb, _transpose(ra))))


# Forward kinematics -------------------------------------------------------------


def _frames(q: Sequence[float]) -> list[tuple[Matrix, Vector]]:
    """Base-frame rotation and origin of the base and of each link frame 1..6."""
    rotation, origin = IDENTITY, (0.0, 0.0, 0.0)
    frames = [(rotation, origin)]
    for theta, d, a, alpha in zip(q, D, A, ALPHA, strict=True):
        ct, st = math.cos(theta), math.sin(theta)
        ca, sa = math.cos(alpha), math.sin(alpha)
        link: Matrix = ((ct, -st * ca, st * sa), (st, ct * ca, -ct * sa), (0.0, sa, ca))
        origin = _add(origin, _apply(rotation, (a * ct, a * st, d)))
        rotation = _matmul(rotation, link)
        frames.append((rotation, origin))
    return frames


def _tcp_of(flange: tuple[Matrix, Vector], tcp: Sequence[float]) -> tuple[Matrix, Vector]:
    r_tcp, t_tcp = _split(tcp)
    rotation, origin = flange
    return _matmul(rotation, r_tcp), _add(origin, _apply(rotation, t_tcp))


def forward(q: Sequence[float], tcp: Sequence[float] = TCP) -> Pose:
    """The TCP pose for joint angles `q` (what get_actual_tcp_pose reports)."""
    rotation, origin = _tcp_of(_frames(q)[-1], tcp)
    return _join(rotation, origin)


# Inverse kinematics ---------------------------------------------------------------


def _solve(m: list[list[float]], b: list[float]) -> list[float]:
    """x with m·x = b, by Gaussian elimination with partial pivoting (m is well conditioned)."""
    n = len(b)
    rows = [[*m[i], b[i]] for i in range(n)]
    for col in range(n):
        pivot = max(range(col, n), key=lambda r: abs(rows[r][col]))
        rows[col], rows[pivot] = rows[pivot], rows[col]
        for r in range(col + 1, n):
            factor = rows[r][col] / rows[col][col]
            for c in range(col, n + 1):
                rows[r][c] -= factor * rows[col][c]
    x = [0.0] * n
    for r in range(n - 1, -1, -1):
        x[r] = (rows[r][n] - sum(rows[r][c] * x[c] for c in range(r + 1, n))) / rows[r][r]
    return x


def _error_and_jacobian(
    q: Sequence[float], rotation: Matrix, position: Vector, tcp: Sequence[float]
) -> tuple[list[float], list[list[float]]]:
    """The 6-vector from the TCP to the target (position; rotation vector) and the geometric Jacobian."""
    frames = _frames(q)
    r_tcp, p_tcp = _tcp_of(frames[-1], tcp)
    position_error = _sub(position, p_tcp)
    rotation_error = rotation_vector(_matmul(rotation, _transpose(r_tcp)))
    columns = []
    for r, o in frames[:-1]:
        z = (r[0][2], r[1][2], r[2][2])
        columns.append((*_cross(z, _sub(p_tcp, o)), *z))
    jacobian = [[columns[j][i] for j in range(6)] for i in range(6)]
    return [*position_error, *rotation_error], jacobian


def _clamped(error: list[float]) -> list[float]:
    # Far from the target a full step overshoots; limit it to 10 cm and 0.5 rad.
    p, w = norm(error[:3]), norm(error[3:])
    sp = min(1.0, 0.1 / p) if p > 0 else 1.0
    sw = min(1.0, 0.5 / w) if w > 0 else 1.0
    return [e * sp for e in error[:3]] + [e * sw for e in error[3:]]


def _near(angle: float, reference: float) -> float:
    """The angle equivalent to `angle` (mod 2π) nearest to `reference`."""
    return reference + math.remainder(angle - reference, 2 * math.pi)


def _descend(
    target: Sequence[float], seed: Sequence[float], tcp: Sequence[float], iterations: int
) -> list[float] | None:
    """Joints from `seed` by damped least squares until the TCP is at `target`; None if it stalls."""
    rotation, position = _split(target)
    q = list(seed)
    damping = 0.02
    for _ in range(iterations):
        error, jacobian = _error_and_jacobian(q, rotation, position, tcp)
        if norm(error[:3]) < 1e-7 and norm(error[3:]) < 1e-6:
            return q
        step = _clamped(error)
        # Δq = Jᵀ (J Jᵀ + λ² I)⁻¹ e: the damping keeps the step bounded near singularities.
        jjt = [
            [sum(jacobian[i][k] * jacobian[j][k] for k in range(6)) for j in range(6)]
            for i in range(6)
        ]
        for i in range(6):
            jjt[i][i] += damping**2
        y = _solve(jjt, step)
        for k in range(6):
            q[k] += sum(jacobian[i][k] * y[i] for i in range(6))
    return None


def _within_limits(q: Sequence[float], seed: Sequence[float]) -> Joints | None:
    """`q` with each joint the equivalent angle nearest its seed (the elbow folded into ±π)."""
    result = [_near(a, s) for a, s in zip(q, seed, strict=True)]
    # Past ±180° the forearm would pass through the upper arm; same geometry mod 2π.
    result[2] = math.remainder(result[2], 2 * math.pi)
    if all(abs(a) <= JOINT_LIMIT for a in result):
        return tuple(result)  # type: ignore[return-value]
    return None


def inverse(target: Sequence[float], seed: Sequence[float], tcp: Sequence[float] = TCP) -> Joints:
    """Joint angles that put the TCP at `target`, near `seed` (the current joints).

    Like the controller's get_inverse_kin: the solution the numeric search
    reaches from `seed` (so usually the same arm configuration), each joint
    within half a turn of its seed. Raises Unreachable when no start converges.
    """
    for start in (seed, HOME, _flipped(seed)):
        solution = _descend(target, start, tcp, iterations=200)
        if solution is not None and (joints := _within_limits(solution, seed)) is not None:
            return joints
    raise Unreachable(
        "No inverse kinematics solution for p[{}]: out of the UR5e's reach.".format(
            ", ".join(f"{v:.4f}" for v in target)
        )
    )


def _flipped(seed: Sequence[float]) -> Joints:
    # The other elbow: a second start for targets the first search can't reach.
    return (seed[0], seed[1] + seed[2], -seed[2], seed[3], seed[4], seed[5])


# Motion ---------------------------------------------------------------------------


@dataclass(frozen=True)
class Profile:
    """A trapezoidal velocity profile over `distance` (rad or m) at `speed` and `acceleration`."""

    distance: float
    speed: float
    acceleration: float

    @property
    def _cruises(self) -> bool:
        return self.distance >= self.speed**2 / self.acceleration

    @property
    def duration(self) -> float:
        """Seconds from rest to rest at 100 % speed."""
        if self.distance <= 0:
            return 0.0
        if self._cruises:
            return self.distance / self.speed + self.speed / self.acceleration
        return 2 * math.sqrt(self.distance / self.acceleration)

    def fraction(self, t: float) -> float:
        """How much of the distance is covered `t` seconds after the start, 0..1."""
        total = self.duration
        if t >= total or self.distance <= 0:
            return 1.0
        a = self.acceleration
        ramp = self.speed / a if self._cruises else total / 2
        if t < ramp:
            covered = a * t * t / 2
        elif t < total - ramp:
            covered = a * ramp * ramp / 2 + a * ramp * (t - ramp)
        else:
            covered = self.distance - a * (total - t) ** 2 / 2
        return max(0.0, min(1.0, covered / self.distance))


def tcp_velocity(before: Sequence[float], after: Sequence[float], seconds: float) -> Pose:
    """The TCP speed (vx, vy, vz, wx, wy, wz) of moving from pose `before` to `after` in `seconds`."""
    if seconds <= 0:
        return (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    rb, tb = _split(before)
    ra, ta = _split(after)
    v = _sub(ta, tb)
    w = rotation_vector(_matmul(ra, _transpose(rb)))
    return (
        v[0] / seconds,
        v[1] / seconds,
        v[2] / seconds,
        w[0] / seconds,
        w[1] / seconds,
        w[2] / seconds,
    )
