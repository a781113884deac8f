import math
import random

import pytest

from hrc_gateway.sim import kinematics
from hrc_gateway.sim.kinematics import HOME, Profile, Unreachable

FLANGE = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


def close_to(a: tuple[float, ...], b: tuple[float, ...], tolerance: float = 1e-6) -> bool:
    metres, radians = kinematics.pose_distance(a, b)
    return metres < tolerance and radians < tolerance


def test_the_flange_at_zero_joints_is_where_universal_robots_puts_it() -> None:
    # UR5e, all joints 0: arm stretched along -x; x = a2 + a3, y = -(d4 + d6), z = d1 - d5.
    pose = kinematics.forward((0.0,) * 6, FLANGE)
    assert pose[:3] == pytest.approx((-0.8172, -0.2329, 0.0628), abs=1e-9)
    assert pose[3:] == pytest.approx((math.pi / 2, 0.0, 0.0), abs=1e-9)


def test_home_points_the_flange_down_in_front_of_the_base() -> None:
    flange = kinematics.forward(HOME, FLANGE)
    down = kinematics.rotation_matrix(flange[3:])
    assert [row[2] for row in down] == pytest.approx([0.0, 0.0, -1.0], abs=1e-9)
    assert flange[0] > 0.3


def test_inverse_kinematics_finds_joints_that_reach_random_reachable_poses() -> None:
    rng = random.Random(3)
    for _ in range(20):
        q = tuple(h + rng.uniform(-0.6, 0.6) for h in HOME)
        target = kinematics.forward(q)
        seed = tuple(a + rng.uniform(-0.2, 0.2) for a in q)
        solution = kinematics.inverse(target, seed)
        assert close_to(kinematics.forward(solution), target)


def test_inverse_kinematics_stays_in_the_seeds_configuration() -> None:
    q = (2.9, -1.3, 1.6, -1.9, -1.5, 0.4)
    solution = kinematics.inverse(kinematics.forward(q), (2.95, -1.35, 1.55, -1.85, -1.55, 0.45))
    assert solution == pytest.approx(q, abs=1e-5)


def test_a_pose_out_of_reach_is_refused() -> None:
    with pytest.raises(Unreachable, match="out of the UR5e's reach"):
        kinematics.inverse((1.5, 0.0, 0.5, 0.0, 0.0, 0.0), HOME)


def test_pose_trans_expresses_the_offset_in_the_feature_frame() -> None:
    feature = (0.5, 0.0, 0.2, 0.0, 0.0, math.pi / 2)  # turned a quarter about z
    moved = kinematics.pose_trans(feature, (0.1, 0.0, 0.0, 0.0, 0.0, 0.0))
    assert moved == pytest.approx((0.5, 0.1, 0.2, 0.0, 0.0, math.pi / 2), abs=1e-12)


def test_pose_trans_with_its_inverse_is_the_identity() -> None:
    pose = (0.3, -0.2, 0.4, 0.5, -1.2, 2.0)
    assert close_to(kinematics.pose_trans(pose, kinematics.pose_inv(pose)), FLANGE)


def test_rotation_vectors_survive_a_round_trip_even_near_half_a_turn() -> None:
    for rotvec in [(0.0, math.pi, 0.0), (0.0, 0.0, math.pi - 1e-9), (1.0, -2.0, 0.5), (0.0,) * 3]:
        matrix = kinematics.rotation_matrix(rotvec)
        again = kinematics.rotation_matrix(kinematics.rotation_vector(matrix))
        assert [x for row in again for x in row] == pytest.approx(
            [x for row in matrix for x in row], abs=1e-7
        )


def test_a_long_move_cruises_and_a_short_one_only_accelerates_and_brakes() -> None:
    long = Profile(3.0, 1.047, 1.396)
    assert long.duration == pytest.approx(3.0 / 1.047 + 1.047 / 1.396)
    short = Profile(0.1, 1.047, 1.396)
    assert short.duration == pytest.approx(2 * math.sqrt(0.1 / 1.396))
    for profile in (long, short):
        samples = [profile.fraction(profile.duration * i / 50) for i in range(51)]
        assert samples[0] == 0.0
        assert samples[-1] == 1.0
        assert samples == sorted(samples)
