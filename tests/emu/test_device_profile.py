"""The original-device profile: registry, documentation, and each quirk's effect."""

import re
from pathlib import Path

import numpy as np
import pytest

from rend3r.emu.lighting import fixed_intensity
from rend3r.emu.options import EmuOptions
from rend3r.emu.quirks import PROFILES, QUIRKS, UNSURE, apply_quirks, contradictions, quirk_names
from rend3r.emu.run import run_program
from rend3r.errors import Rend3rError
from rend3r.isa import ShapeSet, Table, encode, lookup

from .scenes import Prog, f16

DOC = Path(__file__).resolve().parents[2] / "docs" / "device-profile.md"
SMALL = dict(width=48, height=36)


def _quirked(*names, **kw):
    return apply_quirks(EmuOptions(**{**SMALL, **kw}), names)


def _tri(prog: Prog, index: int, verts, col: int) -> Prog:
    names = ("x1", "y1", "z1", "x2", "y2", "z2", "x3", "y3", "z3")
    vals = [f16(v) for v in np.ravel(verts)] + [col]
    props = [lookup(Table.TRIANGLE, n).index for n in names] + [lookup(Table.TRIANGLE, "col").index]
    for a in range(0, 10, 2):
        prog.words += encode(ShapeSet(index, props[a], props[a + 1], vals[a], vals[a + 1]))
    return prog


def _frame(prog: Prog, options: EmuOptions, frames=None):
    return run_program(prog.words, options, frames).frames


def test_every_quirk_is_documented_and_sets_real_options():
    doc = DOC.read_text()
    fields = set(EmuOptions.__dataclass_fields__)
    for name, q in QUIRKS.items():
        assert re.search(rf"^\| `{re.escape(name)}` \|", doc, re.M), name
        assert q.changes and all(f in fields for f, _ in q.changes), name
    assert set(PROFILES["rend3r-2022"]) == set(QUIRKS) - set(UNSURE)  # the guesses stay out of the profile


def test_profile_and_quirk_selection():
    assert quirk_names("rend3r-2022", []) == [q for q in QUIRKS if q not in UNSURE]
    assert "tiny-before-rounding" in quirk_names("rend3r-2022", ["tiny-before-rounding"])  # profile + a guess
    assert quirk_names(None, ["lr-to-1", "device-camera"]) == ["device-camera", "lr-to-1"]
    with pytest.raises(Rend3rError, match="unknown device quirk 'nope'"):
        quirk_names(None, ["nope"])
    with pytest.raises(Rend3rError, match="unknown profile"):
        quirk_names("rend3r-1999", [])
    o = apply_quirks(EmuOptions(depth="painter", subnormals="ieee"), quirk_names("rend3r-2022", []))
    assert (o.camera, o.lr_target, o.clear_on_nr, o.depth, o.subnormals) == ("device", 1, False, "index", "ftz")


def test_contradictions_name_each_quirk_that_changes_a_given_field():
    profile = quirk_names("rend3r-2022", [])
    assert contradictions({"subnormals": "ieee", "depth": "painter"}, profile) == [
        ("subnormals", "flush-subnormals", "ftz"), ("depth", "raster-index-order", "index")]
    assert contradictions({"subnormals": "ftz", "depth": "index"}, profile) == []
    assert contradictions({"subnormals": "ieee"}, ["device-camera"]) == []


def test_intensity_converter_wraps_above_a_quarter():
    got = fixed_intensity(np.array([0.1, 4095 / 16384, 0.25, 0.3, 1.0]))
    assert got.tolist() == [1638, 4095, -4096, -3277, 0]


def _lit_sphere(light_col=0xFFFF, intensity=1.0):
    return (Prog().nr().sphere(0, loc=(0.0, 0.0, -3.0), col=0xFFFF)
            .dir_light(0, forward=(0.0, 0.0, -1.0), col=light_col, intensity=intensity)
            .dir_light(1, forward=(0.0, 0.0, -1.0), col=0xFFFF).nf().er())


def test_light0_only_ignores_other_lights_colour_and_intensity():
    prog = _lit_sphere(light_col=0x001F, intensity=0.5)
    spec = _frame(prog, EmuOptions(**SMALL))[0]
    dev = _frame(prog, _quirked("light0-only"))[0]
    only0 = (Prog().nr().sphere(0, loc=(0.0, 0.0, -3.0), col=0xFFFF)
             .dir_light(0, forward=(0.0, 0.0, -1.0)).nf().er())
    white = _frame(only0, EmuOptions(**SMALL))[0]
    assert np.array_equal(dev.rgb565, white.rgb565)  # channel * I: white light 0 at intensity 1
    assert not np.array_equal(spec.rgb565, white.rgb565)


def test_intensity_13bit_blackens_bright_points_and_keeps_dim_ones():
    prog = _lit_sphere()
    dev = _frame(prog, _quirked("light0-only", "intensity-13bit"))[0]
    plain = _frame(prog, _quirked("light0-only"))[0]
    hit = dev.provenance >= 0
    c = (SMALL["height"] // 2, SMALL["width"] // 2)
    assert int(dev.rgb565[c]) == 0  # I ~ 1 wraps to 0
    assert (dev.rgb565[hit] != plain.rgb565[hit]).any()
    assert ((dev.rgb565[hit] > 0) & (dev.rgb565[hit] <= 0xFFFF // 3)).any()  # rim: I < 0.25, dim


# Two overlapping triangles: 0 near (red), 1 far (green) and drawn later.
NEAR = [(-2, -2, -2), (2, -2, -2), (0, 2, -2)]
FAR = [(-3, -3, -4), (3, -3, -4), (0, 3, -4)]


def _tris(cam=None, light=True):
    p = Prog().nr()
    if cam:
        p.cam(**cam)
    _tri(p, 0, NEAR, 0xF800)
    _tri(p, 1, FAR, 0x07E0)
    if light:
        p.dir_light(0, forward=(0.0, 1.0, -1.0))
    return p.nf().er()


def _raster(*names, prog=None, frames=None, **kw):
    return _frame(prog or _tris(), _quirked(*names, mode="raster", **kw), frames)


def test_raster_unshaded_and_index_order():
    c = (SMALL["height"] // 2, SMALL["width"] // 2)
    spec = _raster()[0]
    assert spec.provenance[c] == 0 and int(spec.rgb565[c]) not in (0xF800, 0)  # z-buffer, shaded
    dev = _raster("raster-unshaded", "raster-index-order")[0]
    assert dev.provenance[c] == 1 and int(dev.rgb565[c]) == 0x07E0  # later wins, flat colour


def test_raster_fixed_camera_ignores_camera_properties():
    moved = _tris(cam=dict(xloc=1.5, hfov=0.5))
    assert not np.array_equal(_raster(prog=moved)[0].provenance, _raster()[0].provenance)
    assert np.array_equal(_raster("raster-fixed-camera", prog=moved)[0].provenance, _raster()[0].provenance)


def test_raster_column_offset_shifts_three_columns():
    a = _raster("raster-unshaded")[0].rgb565
    b = _raster("raster-unshaded", "raster-column-offset")[0].rgb565
    assert np.array_equal(b[:, 3:], a[:, :-3]) and (b[:, :3] == 0).all()


def test_raster_next_triangle_draws_the_following_slot():
    f = _raster("raster-unshaded", "raster-next-triangle")[0]
    # Slot 0 shows triangle 1's data; slot 1 reads the unwritten slot 2 (all zero: not drawn).
    assert set(np.unique(f.provenance)) == {-1, 0}
    assert set(np.unique(f.rgb565[f.provenance == 0])) == {0x07E0}


def test_raster_pixel_snap_zero_area_covers_the_screen():
    p = _tri(Prog().nr(), 0, [(0.5, 0.5, -2)] * 3, 0x001F).nf().er()
    assert (_raster("raster-unshaded", "raster-pixel-snap", prog=p)[0].provenance == 0).all()
    assert (_raster("raster-unshaded", prog=p)[0].provenance == -1).all()


def test_frames_not_cleared_keep_old_pixels():
    p = _tri(Prog().nr(), 0, NEAR, 0xF800).nf().nr()
    _tri(p, 0, [(1, 1, -2), (3, 1, -2), (2, 3, -2)], 0x07E0).nf().er()
    cleared = _raster("raster-unshaded", prog=p)
    kept = _raster("raster-unshaded", "frames-not-cleared", prog=p)
    first = cleared[0].provenance >= 0
    second = cleared[1].provenance >= 0
    assert (cleared[1].rgb565[first & ~second] == 0).all()
    assert (kept[1].rgb565[first & ~second] == 0xF800).all()
    assert (kept[1].rgb565[second] == 0x07E0).all()


def test_rgb444_display_shows_the_low_12_bits():
    f = _raster("raster-unshaded", "rgb444-display")[0]
    red = f.rgb565[f.provenance == 0]  # stored 0xF800: low 12 bits 0x800 -> r=8, g=0, b=0
    want = (((8 << 1) | (8 >> 3)) << 11)
    assert set(np.unique(red)) == {want}
