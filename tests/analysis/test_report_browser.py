"""The report in a real browser: headless Chromium (Debian's chromium, chromium-driver and
python3-selenium, installed by scripts/install-deps) opens index.html. A console error or an
<img> that did not decode (naturalWidth 0) fails the test; a full-page screenshot is saved under
$SFX_TEST_OUTPUT/report_browser/ (scripts/test: build/test-output/), else pytest's tmp_path.
Run as a script, it checks any report (see the end of this file)."""

import base64
import os

import pytest

from conftest import accuracy_store
from sfx_analysis.report import write_report

CHROMIUM = "/usr/bin/chromium"
CHROMEDRIVER = "/usr/bin/chromedriver"
WINDOW_WIDTH = 1200


def missing_browser():
    """Why the browser cannot run here, or None."""
    for path, package in [(CHROMIUM, "chromium"), (CHROMEDRIVER, "chromium-driver")]:
        if not os.access(path, os.X_OK):
            return f"{path} not installed (Debian package {package}; ./scripts/install-deps)"
    try:
        import selenium  # noqa: F401
    except ImportError:
        return "selenium not importable by /usr/bin/python3 (Debian package python3-selenium)"
    return None


needs_browser = pytest.mark.skipif(missing_browser() is not None,
                                   reason=str(missing_browser()))


def output_dir(tmp_path, name):
    base = os.environ.get("SFX_TEST_OUTPUT")
    directory = os.path.join(base, "report_browser") if base else str(tmp_path)
    os.makedirs(directory, exist_ok=True)
    return os.path.join(directory, name)


def check_in_browser(index_html, screenshot, user_data_dir):
    """Opens index_html in headless Chromium; returns (console errors, broken images) and
    writes a full-page PNG screenshot."""
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    # The network is closed: nothing that phones home, a fresh profile.
    for arg in ["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
                "--disable-background-networking", "--disable-component-update",
                "--disable-sync", f"--user-data-dir={user_data_dir}",
                f"--window-size={WINDOW_WIDTH},900"]:
        options.add_argument(arg)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(service=Service(CHROMEDRIVER), options=options)
    try:
        driver.set_page_load_timeout(60)
        driver.get("file://" + os.path.abspath(index_html))  # returns after the load event
        images = driver.execute_script(
            "return Array.from(document.images).map("
            "i => [i.getAttribute('src'), i.complete, i.naturalWidth]);")
        broken = [src for src, complete, width in images if not complete or width == 0]
        errors = [e["message"] for e in driver.get_log("browser") if e["level"] == "SEVERE"]
        height = driver.execute_script("return document.documentElement.scrollHeight;")
        shot = driver.execute_cdp_cmd("Page.captureScreenshot", {
            "format": "png", "captureBeyondViewport": True,
            "clip": {"x": 0, "y": 0, "width": WINDOW_WIDTH, "height": height, "scale": 1}})
        with open(screenshot, "wb") as f:
            f.write(base64.b64decode(shot["data"]))
        return errors, broken, len(images)
    finally:
        driver.quit()


def png_height(path):
    with open(path, "rb") as f:
        head = f.read(24)
    assert head[:8] == b"\x89PNG\r\n\x1a\n"
    return int.from_bytes(head[20:24], "big")


@needs_browser
def test_report_in_browser(tmp_path):
    report = write_report(accuracy_store(tmp_path), str(tmp_path / "report"))
    assert all(p.file for p in report.plots)
    shot = output_dir(tmp_path, "report.png")
    errors, broken, images = check_in_browser(report.index, shot, str(tmp_path / "profile"))
    assert errors == [] and broken == []
    assert images == len(report.plots)
    assert png_height(shot) > 3000  # the whole page, not one window


@needs_browser
def test_browser_check_catches_a_broken_page(tmp_path):
    # The check itself can fail: a missing plot and a script error must both be reported.
    report = write_report(accuracy_store(tmp_path), str(tmp_path / "report"))
    os.remove(os.path.join(report.directory, report.plots[0].file))
    with open(report.index, "a", encoding="utf-8") as f:
        f.write("<script>undefined_function();</script>\n")
    errors, broken, _ = check_in_browser(report.index, output_dir(tmp_path, "broken.png"),
                                         str(tmp_path / "profile"))
    assert broken == [report.plots[0].file]
    assert any("undefined_function" in e for e in errors), errors


if __name__ == "__main__":
    # Checks any report, e.g. the demo's:
    #   /usr/bin/python3 tests/analysis/test_report_browser.py out/demo/report/index.html shot.png
    import sys
    import tempfile

    if missing_browser():
        sys.exit(f"no browser: {missing_browser()}")
    with tempfile.TemporaryDirectory() as profile:
        errors, broken, images = check_in_browser(sys.argv[1], sys.argv[2], profile)
    print(f"{images} images, {len(broken)} broken {broken}, {len(errors)} console errors "
          f"{errors}; screenshot {sys.argv[2]}")
    sys.exit(1 if errors or broken or not images else 0)
