import numpy as np
import pytest

from rend3r.svo.cores import Platform, RAY_WORDS, compute_cycles, frame_time


def test_ray_loading_matches_the_thesis():
    """No work per ray: the frame is the scheduler loading 640x480 rays (130 ms in the thesis)."""
    n = 640 * 480
    p = Platform()
    load = n * p.burst(RAY_WORDS) / p.clock_hz
    assert load == pytest.approx(0.130, rel=0.03)
    ft = frame_time(np.zeros(n), np.zeros(n), 1, 4)
    assert 0.13 <= ft["frame_s"] <= 0.16  # plus pixel writes, like the thesis's 150 ms bound


def test_cores_help_until_the_bus_saturates():
    rng = np.random.default_rng(0)
    n = 20000
    compute = rng.integers(50, 300, n).astype(float)
    light = rng.poisson(0.5, n).astype(float)
    heavy = rng.poisson(15, n).astype(float)
    t_light = [frame_time(compute, light, 1, c)["frame_s"] for c in (1, 2, 3, 4)]
    t_heavy = [frame_time(compute, heavy, 1, c)["frame_s"] for c in (1, 2, 3, 4)]
    # few misses: nearly linear in the core count
    assert t_light[0] > 1.7 * t_light[1] and t_light[1] > 1.5 * t_light[3]
    # many misses: the bus is the limit and extra cores barely help
    assert t_heavy[3] > 0.8 * t_heavy[1]
    assert frame_time(compute, heavy, 1, 4)["bus_utilisation"] > 0.8
    # more misses or larger blocks never make a frame faster
    assert frame_time(compute, heavy, 1, 2)["frame_s"] > frame_time(compute, light, 1, 2)["frame_s"]
    assert frame_time(compute, light, 8, 2)["frame_s"] > frame_time(compute, light, 1, 2)["frame_s"]


def test_first_available_never_slower_than_round_robin():
    rng = np.random.default_rng(1)
    compute = rng.exponential(400, 5000)
    misses = np.zeros(5000)
    for cores in (2, 3, 4):
        rr = frame_time(compute, misses, 1, cores, "round-robin")["frame_s"]
        fa = frame_time(compute, misses, 1, cores, "first-available")["frame_s"]
        assert fa <= rr
    with pytest.raises(ValueError):
        frame_time(compute, misses, 1, 2, "random")


def test_compute_cycles():
    # one ray: INIT, root CALC-T/FIRST-IDX, 3 evaluations, 1 descent (2 cycles), 2 requests
    assert compute_cycles([3], [1], [0], [0], [2]).tolist() == [1 + 2 * 2 + 9 + 2]
