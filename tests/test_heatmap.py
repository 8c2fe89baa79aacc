"""LSOS heat map pieces against hand-computed values (thesis Eqs. 5.3-5.6)."""

import numpy as np
import pytest

from semsearch_cli.geometry import GridFrame
from semsearch_cli.belief.objects import goal_cells, heat_map, inverted_kernel


def test_inverted_kernel_values_full_disk():
    k = inverted_kernel((7, 7), (3, 3), (3, 6), radius=2.0, weight=0.5, sector_deg=180.0)
    # Manhattan d / r, times W: 0 at the object, 0.5 * 1/2 one step away, 0.5 * 2/2 two steps away
    assert k[3, 3] == 0.0
    assert k[3, 4] == pytest.approx(0.25) and k[2, 3] == pytest.approx(0.25)
    assert k[3, 5] == pytest.approx(0.5) and k[2, 4] == pytest.approx(0.5)
    assert k[1, 4] == 0.0 and k[3, 6] == 0.0  # d = 3 > r


def test_sector_points_toward_the_robot_and_unknown_is_cold():
    k = inverted_kernel((9, 9), (4, 4), (4, 8), radius=3.0, weight=1.0, sector_deg=45.0)  # robot due east
    assert k[4, 6] == pytest.approx(2 / 3)  # east: inside the sector
    assert k[4, 2] == 0.0 and k[2, 4] == 0.0  # west and north: outside
    assert k[3, 6] > 0 and k[1, 5] == 0.0  # 26.6 degrees in, 71.6 degrees out
    known = np.ones((9, 9), bool)
    known[4, 6] = False
    assert inverted_kernel((9, 9), (4, 4), (4, 8), 3.0, 1.0, known, 45.0)[4, 6] == 0.0  # Q = 0


def test_heat_map_filters_the_class_and_weighs_the_hour():
    fr = GridFrame(1.0, 0.0, 0.0, 20, 20)
    dets = [("mug", 5.5, 14.5, 12.0, 8.5, 14.5), ("book", 5.5, 14.5, 12.0, 8.5, 14.5), ("mug", 15.5, 4.5, 23.0, 15.5, 7.5)]
    h = heat_map(dets, "mug", 1.0, fr, radius_m=3.0, sector_deg=180.0)
    # the noon mug weighs W(1, 12) = 1 - 11/12; the 23:00 mug W(1, 23) = 1 - 2/12 (across midnight)
    r, c = fr.to_index(8.5, 14.5)
    assert h[r, c] == pytest.approx(1 / 12 * 3 / 3)
    r, c = fr.to_index(15.5, 7.5)
    assert h[r, c] == pytest.approx(10 / 12)
    assert heat_map(dets, "cup", 1.0, fr).sum() == 0.0


def test_goals_in_order_of_windowed_heat():
    fr = GridFrame(1.0, 0.0, 0.0, 30, 30)
    dets = [("mug", 5.5, 24.5, 11.0, 8.5, 24.5), ("mug", 24.5, 5.5, 2.0, 24.5, 8.5)]
    noon = goal_cells(heat_map(dets, "mug", 12.0, fr, radius_m=3.0), window_cells=2.0)
    midnight = goal_cells(heat_map(dets, "mug", 0.0, fr, radius_m=3.0), window_cells=2.0)
    assert len(noon) == 2 and len(midnight) == 2
    first_noon = fr.to_world(noon[0][0], noon[0][1])
    first_midnight = fr.to_world(midnight[0][0], midnight[0][1])
    assert first_noon[0] < 12 and first_midnight[0] > 18  # at noon the 11:00 mug first, at midnight the 02:00 one
    assert noon[0][2] > noon[1][2]


def test_a_sighting_twelve_hours_away_weighs_nothing():
    fr = GridFrame(1.0, 0.0, 0.0, 20, 20)
    assert heat_map([("mug", 5.5, 5.5, 0.0, 8.5, 5.5)], "mug", 12.0, fr, radius_m=3.0).sum() == 0.0
    assert goal_cells(np.zeros((20, 20)), 2.0) == []


def test_a_kernel_wide_window_puts_the_goal_at_the_kernel_edge_toward_the_robot():
    fr = GridFrame(0.1, 0.0, 0.0, 100, 100)
    dets = [("mug", 5.05, 5.05, 12.0, 5.05, 2.05)]  # the robot saw it from 3 m south
    heat = heat_map(dets, "mug", 12.0, fr, radius_m=1.5, sector_deg=45.0)
    (r, c, phi), = goal_cells(heat, window_cells=15.0)
    orow, ocol = fr.to_index(5.05, 5.05)
    dr, dc = r - orow, c - ocol
    assert abs(dr) + abs(dc) == 15  # on the kernel's edge (Manhattan d = r), its warmest cells
    assert dr > 0 and abs(dc) <= dr  # within 45 degrees of due south, toward where the robot stood
    assert phi == pytest.approx(heat.sum())  # the window holds the whole kernel
