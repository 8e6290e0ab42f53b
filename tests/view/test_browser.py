"""``rend3r view`` in a real browser: Playwright driving Debian's Chromium (``.ci/run``
installs it; these tests skip with the reason where it or Playwright is missing)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from click.testing import CliRunner

from rend3r.cli import main

from .conftest import SPHERE, serve

CHROMIUM = "/usr/bin/chromium"
ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
        "--disable-component-update", "--disable-sync", "--no-first-run"]

sync_api = pytest.importorskip("playwright.sync_api", reason="Playwright is not installed (pip install playwright)")
if not Path(CHROMIUM).exists():
    pytest.skip(f"Debian's chromium is not installed ({CHROMIUM} missing; .ci/run installs it)", allow_module_level=True)


@pytest.fixture
def page(tmp_path):
    """A fresh Chromium page (its own user-data-dir), closed after the test. The page's
    Content-Security-Policy forbids evaluating strings, which Playwright's waits do: the
    tests bypass it, the page itself needs no eval."""
    with sync_api.sync_playwright() as pw:
        context = pw.chromium.launch_persistent_context(str(tmp_path / "profile"), executable_path=CHROMIUM,
                                                        args=ARGS, headless=True, bypass_csp=True,
                                                        viewport={"width": 1800, "height": 1200})
        try:
            yield context.new_page()
        finally:
            context.close()
    shutil.rmtree(tmp_path / "profile", ignore_errors=True)


def _click(page, x: int, y: int) -> None:
    """Click frame pixel (x, y) of the working-precision image. The viewport shows it at its
    natural size; mouse positions are whole CSS pixels, so the click is at the first whole
    position inside the pixel (the image's top may be fractional)."""
    at = page.evaluate("""([x, y]) => { const img = document.getElementById('img-a');
        const r = img.getBoundingClientRect();
        return [Math.ceil(r.left + img.clientLeft + x * img.clientWidth / img.naturalWidth),
                Math.ceil(r.top + img.clientTop + y * img.clientHeight / img.naturalHeight)]; }""", [x, y])
    page.mouse.click(*at)


def _frame_bytes(page) -> str:
    """The working-precision image as the page shows it (a data URL of its pixels)."""
    return page.evaluate("""() => { const img = document.getElementById('img-a');
        const c = document.createElement('canvas'); c.width = img.naturalWidth; c.height = img.naturalHeight;
        c.getContext('2d').drawImage(img, 0, 0); return c.toDataURL(); }""")


def test_a_clicked_pixel_shows_the_values_trace_pixel_prints_and_follows_the_precision(page, tmp_path):
    program = Path(__file__).resolve().parents[2] / "programs" / "shadow.asm"
    result = CliRunner().invoke(main, ["emulate", str(program), "-o", str(tmp_path / "f.png"), "-q",
                                       "--trace-pixel", "250,200"])
    want = [json.loads(line) for line in result.output.splitlines()]
    with serve(program) as s:
        page.goto(s.url)
        page.wait_for_function("document.getElementById('img-a').naturalWidth === 512")
        _click(page, 250, 200)
        page.wait_for_selector("#history tbody tr")
        assert page.text_content("#pixel-title").startswith("pixel 250,200")
        rows = page.eval_on_selector_all("#history tbody tr", "rows => rows.map(r => [...r.cells].map(c => c.textContent))")
        first = page.eval_on_selector_all("#history tbody tr.first", "rows => rows.map(r => r.dataset.index)")
        assert page.locator("#images .marker:not([hidden])").count() == 3  # the pixel outlined on each image
        page.fill("#precision", "fp64")
        page.dispatch_event("#precision", "change")
        page.wait_for_function("document.getElementById('pixel-summary').textContent.startsWith('fp64')")
        assert page.locator("#history tbody tr").count() == len(rows)
        assert page.locator("#history tbody tr.diverges").count() == 0  # fp64 against itself
    shown = [[r[0], r[1], r[2], r[3]] for r in rows]
    assert shown == [["" if w["shape"] is None else str(w["shape"]), w["stage"], w["hex"], _js(w["dec"])] for w in want]
    assert len(first) == 1


def _js(value) -> str:
    """A JSON number or string as JavaScript's String() shows it."""
    if isinstance(value, float) and value.is_integer():
        return str(int(value))
    return str(value)


def test_saving_the_source_changes_the_frame_and_breaking_it_shows_the_diagnostic(page, sphere_program):
    with serve(sphere_program) as s:
        page.goto(s.url)
        page.wait_for_function("document.getElementById('img-a').dataset.version === '1'")
        red = _frame_bytes(page)
        sphere_program.write_text(SPHERE.replace("COLOUR", "0x07E0"))
        page.wait_for_function("document.getElementById('img-a').dataset.version === '2'", timeout=20000)
        green = _frame_bytes(page)
        assert green != red
        sphere_program.write_text(SPHERE.replace("COLOUR", "0x07E0").replace("sp 0, zloc", "sp 0, zlok"))
        page.wait_for_selector("#diagnostics:not([hidden])", timeout=20000)
        text = page.text_content("#diagnostics")
        assert f"{sphere_program}:7:7: error:" in text and "sp 0, zlok, rrot, -3, 1" in text and "^~~~" in text
        assert "broken" in page.text_content("#state")
        assert _frame_bytes(page) == green  # the last good frame stays
