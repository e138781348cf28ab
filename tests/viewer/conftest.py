"""Fixtures of the browser tests: the `strata` program, a test map built from the simulator's
viewer_yard scene, a `strata view` server on it and one headless Chromium.

Run through CTest (`ctest -R viewer_page`), which passes STRATA_BINARY and STRATA_SOURCE_DIR.
Chromium missing is a failure unless STRATA_ALLOW_NO_BROWSER=1 (then the browser tests skip).
STRATA_VIEW_SCREENSHOTS=DIR keeps the screenshots the tests take (docs/viewer.md's pictures).
"""
import os
import shutil
import subprocess
import sys
import tempfile

import pytest

sys.path.insert(0, os.path.dirname(__file__))
import cdp  # noqa: E402

SOURCE = os.environ.get("STRATA_SOURCE_DIR",
                        os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..")))
STRATA = os.environ.get("STRATA_BINARY", os.path.join(SOURCE, "build", "tools", "strata", "strata"))


def run(*args):
    result = subprocess.run([STRATA, *args], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            text=True)
    assert result.returncode == 0, f"strata {' '.join(args)}:\n{result.stdout}"
    return result.stdout


@pytest.fixture(scope="session")
def scratch():
    path = tempfile.mkdtemp(prefix=f"strata_viewer_{os.getpid()}_")
    yield path
    shutil.rmtree(path, ignore_errors=True)


@pytest.fixture(scope="session")
def yard(scratch):
    """The viewer_yard scene as a map: sessions 1 (before) and 2 (after: a car left, a container
    came), walls, the change set 1 -> 2 saved, then vehicles cleared (the newest commit)."""
    scene = os.path.join(SOURCE, "datasets", "scenes", "viewer_yard.json")
    sequence, map_dir = os.path.join(scratch, "yard_seq"), os.path.join(scratch, "yard_map")
    run("simulate", "--scene", scene, "--out", sequence, "--no-picture")
    run("integrate", map_dir, "--kitti", os.path.join(sequence, "session_0"), "--voxel", "0.1",
        "--name", "before")
    run("integrate", map_dir, "--kitti", os.path.join(sequence, "session_1"), "--name", "after")
    run("walls", map_dir)
    run("diff", map_dir, "--from", "1", "--to", "2", "--save")
    run("vehicles", map_dir)
    return {"map": map_dir, "sequence": sequence}


@pytest.fixture(scope="session")
def server(yard):
    process, url = cdp.start_view(STRATA, [yard["map"]])
    yield url
    cdp.stop(process)


@pytest.fixture(scope="session")
def browser():
    if cdp.find_chromium() is None:
        if os.environ.get("STRATA_ALLOW_NO_BROWSER") == "1":
            pytest.skip("chromium is not installed (STRATA_ALLOW_NO_BROWSER=1)")
        pytest.fail("chromium is not installed: tools/setup.sh installs it "
                    "(STRATA_ALLOW_NO_BROWSER=1 skips the browser tests)")
    b = cdp.Browser(1000, 700)
    yield b
    b.close()


@pytest.fixture
def open_page(browser):
    """Opens a URL in a new tab and waits until the view is drawn; closes the tab afterwards."""
    pages = []

    def opener(url, wait=True):
        page = browser.new_page(url)
        pages.append(page)
        if wait:
            page.wait_for("window.strataViewer && strataViewer.ready", 60)
            page.wait_for("strataViewer.idle", 120)
        return page

    yield opener
    for page in pages:
        browser.send("Target.closeTarget", {"targetId": page.target})


def save_screenshot(png, name):
    folder = os.environ.get("STRATA_VIEW_SCREENSHOTS")
    if folder:
        os.makedirs(folder, exist_ok=True)
        with open(os.path.join(folder, name), "wb") as f:
            f.write(png)
