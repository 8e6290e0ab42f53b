"""Counters and the paper's cycle models."""

from rend3r.emu.stats import FrameStats, RunStats, device_cycles, raster_cycles


def test_table_iv_estimates():
    px = 512 * 384
    for shapes, lights, seconds in ((1, 0, 0.405), (16, 0, 0.435), (256, 0, 0.906), (4096, 0, 8.456),
                                    (1, 1, 0.810), (16, 1, 0.869), (256, 1, 1.813), (4096, 1, 16.912)):
        assert round(device_cycles(shapes, lights, px) / 100e6, 3) == seconds
    assert device_cycles(2, 1, px) == 81_395_712  # the paper's 2-shape, 1-light figure


def test_raster_estimate_is_1_96_ms_per_triangle():
    assert raster_cycles(1, 512 * 384) == 196_675
    st = FrameStats(pixels=512 * 384, shapes=10, mode="raster")
    assert abs(st.device_seconds - 0.0196675) < 1e-9


def test_report_lists_counters_and_estimate():
    rs = RunStats([FrameStats(number=0, pixels=4, shapes=1, rays=4, tests=3, skipped=1, seconds=0.5)], 9, "er")
    text = rs.report()
    assert "instructions executed: 9 (halted by er)" in text
    assert "tests 3" in text and "skipped 1" in text and "device estimate 824 cycles" in text
