"""Exact tests of small pieces: motion along a path, SPL, the door camera, the object camera and
the harmonic potential that the harmonic navigator climbs."""

import math

import numpy as np
import pytest

from semsearch_cli.config import DoorCameraSpec
from semsearch_cli.geometry import GridFrame
from semsearch_cli.kernels.harmonic import ascend, harmonic_field
from semsearch_cli.metrics import spl
from semsearch_cli.navigation import advance
from semsearch_cli.sensors import DoorCamera, ObjectCamera, detect_probability
from semsearch_cli.world.ground_truth import Signs, World


def test_advance_moves_one_step_along_the_waypoints():
    px, py = np.array([0.0, 1.0, 1.0]), np.array([0.0, 0.0, 1.0])
    x, y, i, h, moved = advance(px, py, 1, 0.0, 0.0, 3.0, 0.5)
    assert (x, y, i, h, moved) == (0.5, 0.0, 1, 0.0, 0.5)
    x, y, i, h, moved = advance(px, py, i, x, y, h, 0.8)  # round the corner: heading follows the new segment
    assert (x, i, h) == (1.0, 2, pytest.approx(math.pi / 2)) and y == pytest.approx(0.3) and moved == pytest.approx(0.8)
    x, y, i, h, moved = advance(px, py, i, x, y, h, 5.0)  # stops at the last waypoint
    assert (x, y, i) == (1.0, 1.0, 3) and moved == pytest.approx(0.7)
    assert advance(px, py, 3, x, y, h, 0.5)[4] == 0.0  # nothing left to travel


def test_spl_values():
    assert spl(True, 10.0, 20.0) == 0.5
    assert spl(True, 10.0, 8.0) == 1.0  # shorter than the shortest (a sign read early) counts as 1
    assert spl(False, 10.0, 10.0) == 0.0 and spl(True, 0.0, 5.0) == 0.0


def open_world(signs=((101, 2.0, 1.0, 90.0),), wall_x=None) -> World:
    """A 5 m x 5 m free square at 0.1 m (a wall column at ``wall_x`` m if given)."""
    fr = GridFrame(0.1, 0.0, 0.0, 50, 50)
    free = np.ones((50, 50), bool)
    if wall_x is not None:
        free[:, int(wall_x / 0.1)] = False
    s = Signs(tuple(n for n, *_ in signs), np.array([n for n, *_ in signs]), np.array([x for _, x, _, _ in signs]),
              np.array([y for _, _, y, _ in signs]), np.radians([f for *_, f in signs]))
    return World(fr, free, s, (2.5, 2.5), 0.0, 0.25, 3.0)


def reads(world, spec, x, y, heading_deg, seed=0):
    return DoorCamera(world, spec).read(x, y, math.radians(heading_deg), np.random.default_rng(seed))


def test_door_camera_field_of_view_facing_range_and_misreads():
    w, spec = open_world(), DoorCameraSpec(p_read=1.0)
    # robot 1 m north of a sign that faces north, heading east: the sign is abeam on the right
    assert reads(w, spec, 2.0, 2.0, 0.0) == [(0, 101)]
    assert reads(w, spec, 2.0, 2.0, 180.0) == [(0, 101)]  # abeam on the left camera
    assert reads(w, spec, 2.0, 2.0, 90.0) == []  # dead astern: outside both 60-degree cameras
    assert reads(w, spec, 2.0 + math.tan(math.radians(25)), 2.0, 0.0) == [(0, 101)]  # 25 degrees off the axis
    assert reads(w, spec, 2.0 + math.tan(math.radians(35)), 2.0, 0.0) == []  # 35 degrees: outside
    assert reads(w, spec, 2.0, 0.5, 0.0) == []  # behind the sign's face
    assert reads(w, spec, 2.0, 4.1, 0.0) == []  # 3.1 m: out of range
    assert reads(w, DoorCameraSpec(p_read=0.0), 2.0, 2.0, 0.0) == []
    labels = {reads(w, DoorCameraSpec(p_read=1.0, p_misread=1.0), 2.0, 2.0, 0.0, s)[0][1] for s in range(30)}
    assert 101 not in labels and all(sum(a != b for a, b in zip(str(v), "101")) == 1 for v in labels)


def test_door_camera_needs_line_of_sight():
    w = open_world(signs=((7, 1.0, 2.5, 0.0),), wall_x=2.0)  # sign facing east, a wall at x = 2 m
    spec = DoorCameraSpec(p_read=1.0)
    assert reads(w, spec, 1.5, 2.5, 90.0) == [(0, 7)]  # west of the wall: abeam on the left
    assert reads(w, spec, 3.0, 2.5, 90.0) == []  # 2 m away, in view, but behind the wall


def test_object_camera_field_of_view_range_and_walls():
    w = open_world(signs=(), wall_x=3.5)
    cam = ObjectCamera(w, 60.0, 2.0, [3.0, 1.0, 4.0], [2.5, 2.5, 2.5])
    assert cam.visible(2.0, 2.5, 0.0).tolist() == [0]  # ahead at 1 m; 1.0 is behind; 4.0 is past the wall
    assert cam.visible(2.0, 2.5, math.pi).tolist() == [1]
    assert cam.visible(2.0, 2.5, math.radians(35)).tolist() == []  # 35 degrees off: outside a 60-degree view
    assert cam.visible(0.5, 2.5, 0.0).tolist() == [1]  # 3.0 is 2.5 m away: out of range
    assert detect_probability(0.7, 1.0, 0.0) == 0.7


def test_harmonic_field_solves_laplace_exactly_and_ascent_reaches_the_goal():
    """A 1-cell corridor of 5 free cells between walls, the goal at its east end: each inner cell
    is the mean of its four neighbours (walls 0, goal 1), i.e. 4 u_i = u_(i-1) + u_(i+1)."""
    passable = np.zeros((3, 8), bool)
    passable[1, 1:7] = True
    goals = np.zeros_like(passable)
    goals[1, 6] = True
    u = harmonic_field(passable, goals)
    A = 4 * np.eye(5) - np.eye(5, k=1) - np.eye(5, k=-1)
    b = np.zeros(5)
    b[-1] = 1.0
    assert np.allclose(u[1, 1:6], np.linalg.solve(A, b), atol=1e-12)
    assert u[1, 6] == 1.0 and u[0].sum() == 0.0 and u[1, 0] == 0.0
    rows, cols, ok = ascend(u, 1, 1, 20)
    assert ok and cols.tolist() == [1, 2, 3, 4, 5, 6] and set(rows.tolist()) == {1}
