"""Helpers for the view tests: a real headless Chromium (Debian's `chromium`) driven by Playwright.

The browser tests skip, with one line saying why, when Playwright or the browser is not installed
(`.ci/run` installs Debian's chromium; nothing is ever downloaded by Playwright itself).
"""
from __future__ import annotations

import io
import os
import shutil
import time
from pathlib import Path

import pytest

CHROMIUM_ARGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-background-networking",
                 "--disable-component-update", "--no-first-run", "--disable-sync"]


def chromium_path() -> str | None:
    for name in (os.environ.get("CHROMIUM"), "/usr/bin/chromium", shutil.which("chromium"), shutil.which("chromium-browser")):
        if name and Path(name).is_file():
            return name
    return None


@pytest.fixture(scope="module")
def browser():
    """A headless Chromium (skips the test when there is none), one per test module: Playwright's sync API keeps an event
    loop marked running in this thread until it exits, which would break later tests that call asyncio.run."""
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        pytest.skip("Playwright is not installed (pip install 'gripper-twin[test]')")
    exe = chromium_path()
    if exe is None:
        pytest.skip("no Chromium installed (apt-get install chromium; .ci/run does it)")
    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=exe, args=CHROMIUM_ARGS)
        try:
            yield b
        finally:
            b.close()


def image_stats(png: bytes):
    """(width, height, distinct colours, fraction of orange pixels) of a PNG."""
    from PIL import Image
    import numpy as np

    img = np.asarray(Image.open(io.BytesIO(png)).convert("RGB")).astype(int)
    h, w, _ = img.shape
    colours = len(np.unique(img.reshape(-1, 3), axis=0))
    r, g, b = img[..., 0], img[..., 1], img[..., 2]
    orange = (r > 120) & (r > g + 40) & (g > b + 20)
    return w, h, colours, float(orange.mean())


def signal_cell(page, name: str) -> str:
    return page.locator(f'[data-signal="{name}"]').inner_text(timeout=60000)


def wait_for_cell(page, name: str, predicate, timeout: float = 60.0) -> str:
    end = time.monotonic() + timeout
    text = ""
    while time.monotonic() < end:
        text = signal_cell(page, name)
        if predicate(text):
            return text
        time.sleep(0.2)
    raise AssertionError(f"signal {name} on the page stayed {text!r}")
