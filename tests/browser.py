"""A page opened in a real browser: Debian's Chromium, headless (as .ci/run installs it), with the
page's console captured. Tests skip, saying why, where Chromium is not installed."""
import os
import re
import shutil
import subprocess
import tempfile

import pytest

FLAGS = ["--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
         "--disable-background-networking", "--disable-component-update", "--disable-sync"]


def chromium():
    path = shutil.which("chromium") or shutil.which("chromium-browser")
    if path is None:
        pytest.skip("no Chromium here (apt install chromium, as .ci/run does)")
    return path


def open_page(page, screenshot=None, size=(1200, 1600)):
    """(the DOM after the page's scripts ran, [console messages]) of the HTML file `page`; with
    `screenshot`, a PNG of it too. No network is needed or used."""
    browser = chromium()
    with tempfile.TemporaryDirectory() as profile:
        args = [browser, *FLAGS, f"--user-data-dir={profile}", "--enable-logging=stderr", "--v=0",
                "--virtual-time-budget=10000", f"--window-size={size[0]},{size[1]}"]
        proc = subprocess.run([*args, "--dump-dom", f"file://{os.path.abspath(page)}"], capture_output=True,
                              text=True, timeout=120)
        console = [m.group(1) for m in re.finditer(r"INFO:CONSOLE[^\]]*\] (.*)", proc.stderr)]
        if screenshot is not None:
            subprocess.run([*args, f"--screenshot={os.path.abspath(screenshot)}",
                            f"file://{os.path.abspath(page)}"], capture_output=True, timeout=120)
    assert proc.returncode == 0, proc.stderr[-2000:]
    return proc.stdout, console
