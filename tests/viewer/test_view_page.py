"""`strata view` in headless Chromium on the viewer_yard map (conftest.py): the page loads without
a console error, a fixed camera shows the known wall, car and changes in their colours, the
timeline switches sessions, a click returns the catalog's row, and the static export opens from
disk. Positions come from datasets/scenes/viewer_yard.json; colours from core::ClassColor and
tools/strata/web/tiles.js (docs/viewer.md lists them)."""
import json
import os
import sqlite3
import subprocess
import urllib.request

import cdp
from conftest import STRATA, run, save_screenshot

# Looks north over the yard from behind its south wall.
CAMERA = "camera=0,-26,20,0,-1,0"
BUILDING, VEHICLE = (255, 150, 60), (30, 110, 255)
ADDED, REMOVED, REFILLED = (0, 200, 60), (230, 30, 30), (255, 240, 0)
# The slant ramp of tiles.js: |90 - slant| / 6 degrees along blue, cyan, green, yellow, red.
VERTICAL, LEANING_4_DEG = (40, 60, 220), (173, 213, 50)
TOLERANCE = 40  # colour distance: flat shading gives the exact colour; this is slack for edges

# Boxes (min, max) around the scene's objects, map frame = scene frame (poses start at origin).
SOUTH_WALL = ((-13.5, -10.3, 0.2), (13.5, -9.3, 2.0))  # leans 4 degrees into the yard
NORTH_WALL = ((-13.5, 9.7, 0.2), (13.5, 10.3, 2.0))
PARKED_CAR = ((-8.25, -4.9, 0.0), (-3.75, -3.1, 1.5))   # stays; `strata vehicles` clears it
LEAVING_CAR = ((3.75, 3.1, 0.0), (8.25, 4.9, 1.5))      # gone in session 2
CONTAINER = ((2.97, -5.22, 0.0), (9.03, -2.78, 2.59))   # arrives in session 2
# Fewest pixels of the expected colour inside an object's outline on screen: a third of what a
# run measured at 1000 x 700 (STRATA_VIEW_COUNTS=1 prints the counts; measured: south wall 45778
# building and 31445 slant-coloured, north wall 11179, car 3765, refilled 1928, container 3720,
# car that left 2352). The colours that must be absent measured 0.
MIN_PIXELS = {"wall": 15000, "wall_slant": 10000, "north_wall": 3700, "car": 1250,
              "refilled": 640, "added": 1240, "removed": 780}


def pixels(page, png, box, color, tolerance=TOLERANCE):
    """Pixels of `color` inside the screen rectangle that holds the box's projected corners."""
    (x0, y0, z0), (x1, y1, z1) = box
    corners = [json.loads(page.evaluate(
        f"JSON.stringify(strataViewer.viewer.project({x},{y},{z}))"))
        for x in (x0, x1) for y in (y0, y1) for z in (z0, z1)]
    width, height, rows = png
    left = max(0, int(min(c["x"] for c in corners)))
    right = min(width - 1, int(max(c["x"] for c in corners)))
    top = max(0, int(min(c["y"] for c in corners)))
    bottom = min(height - 1, int(max(c["y"] for c in corners)))
    count = 0
    if os.environ.get("STRATA_VIEW_COUNTS"):
        print("\npixels", box, color, end=" ")
    for y in range(top, bottom + 1):
        for x in range(left, right + 1):
            p = rows[y][x]
            count += sum((p[k] - color[k]) ** 2 for k in range(3)) <= tolerance ** 2
    if os.environ.get("STRATA_VIEW_COUNTS"):
        print(count)
    return count


def view(open_page, url, state, name=None):
    page = open_page(f"{url}#{CAMERA}&ui=0&{state}")
    png = page.screenshot()
    if name:
        save_screenshot(png, name)
    assert page.console_errors() == []
    return page, cdp.decode_png(png)


def test_the_page_loads_without_console_errors_and_draws_the_map(server, open_page):
    page = open_page(server)
    assert page.console_errors() == []
    assert page.evaluate("strataViewer.errors") == []
    assert page.evaluate("strataViewer.cells") > 10000
    assert page.evaluate("strataViewer.firstPictureMs") > 0
    save_screenshot(page.screenshot(), "viewer_yard.png")


def test_the_known_wall_shows_building_colour_and_its_slant(server, open_page):
    page, png = view(open_page, server, "color=class&layers=")
    assert pixels(page, png, SOUTH_WALL, BUILDING) >= MIN_PIXELS["wall"]
    page, png = view(open_page, server, "color=slant&layers=", "viewer_slant.png")
    # The south wall leans 4 degrees, the north wall stands: each in its own colour.
    assert pixels(page, png, SOUTH_WALL, LEANING_4_DEG) >= MIN_PIXELS["wall_slant"]
    assert pixels(page, png, NORTH_WALL, VERTICAL) >= MIN_PIXELS["north_wall"]
    assert pixels(page, png, SOUTH_WALL, VERTICAL) < MIN_PIXELS["north_wall"] / 10


def test_the_parked_car_is_blue_before_vehicles_ran_and_cleared_and_refilled_after(
        server, open_page):
    page, png = view(open_page, server, "color=class&session=1&layers=")
    before = pixels(page, png, PARKED_CAR, VEHICLE)
    assert before >= MIN_PIXELS["car"]
    page, png = view(open_page, server, "color=class&layers=vehicles", "viewer_vehicles.png")
    assert pixels(page, png, PARKED_CAR, VEHICLE) < before / 10
    assert pixels(page, png, PARKED_CAR, REFILLED) >= MIN_PIXELS["refilled"]


def test_the_diff_of_the_sessions_shows_the_container_green_and_the_car_that_left_red(
        server, yard, open_page):
    page, png = view(open_page, server, "diff=1,2&layers=", "viewer_diff.png")
    assert pixels(page, png, CONTAINER, ADDED) >= MIN_PIXELS["added"]
    assert pixels(page, png, LEAVING_CAR, REMOVED) >= MIN_PIXELS["removed"]
    assert pixels(page, png, LEAVING_CAR, ADDED) < MIN_PIXELS["added"] / 10
    # The saved change set shows the same voxels.
    # Its id is a product row id, unique in the map (format 5): ask the catalog's view.
    with sqlite3.connect(f"file:{yard['map']}/catalog.sqlite?mode=ro", uri=True) as db:
        saved = db.execute("SELECT id FROM change_sets ORDER BY id").fetchone()[0]
    page, png = view(open_page, server, f"changeset={saved}&layers=")
    assert pixels(page, png, CONTAINER, ADDED) >= MIN_PIXELS["added"]
    assert pixels(page, png, LEAVING_CAR, REMOVED) >= MIN_PIXELS["removed"]


def button(page, label):
    rect = page.evaluate(
        "JSON.stringify(Array.from(document.querySelectorAll('#timeline button'))"
        f".find(b => b.textContent.startsWith({json.dumps(label)})).getBoundingClientRect())")
    r = json.loads(rect)
    return r["x"] + r["width"] / 2, r["y"] + r["height"] / 2


def test_the_timeline_switches_to_a_session_and_to_the_diff_of_two(server, open_page):
    page = open_page(f"{server}#{CAMERA}&color=class&layers=")
    newest = page.evaluate("strataViewer.viewer.shown.commit")
    page.click(*button(page, "#1 before"))
    page.wait_for("strataViewer.viewer.state.session === 1 && strataViewer.idle")
    assert page.evaluate("strataViewer.viewer.shown.as_of_session") == 1
    assert page.evaluate("strataViewer.viewer.shown.commit") < newest
    assert "session=1" in page.evaluate("location.hash")
    png = cdp.decode_png(page.screenshot())
    save_screenshot(page.screenshot(), "viewer_timeline.png")
    assert pixels(page, png, PARKED_CAR, VEHICLE) >= MIN_PIXELS["car"]
    page.click(*button(page, "#2 after"), modifiers=8)  # shift
    page.wait_for("JSON.stringify(strataViewer.viewer.state.diff) === '[1,2]' && strataViewer.idle")
    png = cdp.decode_png(page.screenshot())
    assert pixels(page, png, CONTAINER, ADDED) >= MIN_PIXELS["added"]
    assert page.console_errors() == []


def catalog_row(map_dir, table, key, value):
    with sqlite3.connect(f"file:{map_dir}/catalog.sqlite?mode=ro", uri=True) as db:
        db.row_factory = sqlite3.Row
        row = db.execute(f"SELECT * FROM {table} WHERE {key} = ? ORDER BY commit_id DESC",
                         (value,)).fetchone()
        return dict(row)


def click_at(page, x, y, z):
    p = json.loads(page.evaluate(f"JSON.stringify(strataViewer.viewer.project({x},{y},{z}))"))
    picks = page.evaluate("strataViewer.picks || 0")
    page.click(p["x"], p["y"])
    page.wait_for(f"strataViewer.picks > {picks} && !strataViewer.recordPending")
    return json.loads(page.evaluate("JSON.stringify(strataViewer.lastRecord)"))


def test_a_click_returns_the_catalog_row_of_a_wall_a_vehicle_or_a_voxel(server, yard, open_page):
    page = open_page(f"{server}#{CAMERA}&color=class&layers=walls,vehicles")
    walls = json.loads(page.evaluate("JSON.stringify(strataViewer.viewer.manifest.walls)"))
    wall = max(walls, key=lambda w: w["area_m2"])
    record = click_at(page, *wall["center"])
    assert record["kind"] == "wall"
    row = catalog_row(yard["map"], "walls", "wall_id", wall["wall_id"])
    assert record["wall_id"] == row["wall_id"] and record["commit"] == row["commit_id"]
    assert record["slant_deg"] == row["slant_deg"] and record["inliers"] == row["inliers"]
    assert record["center"] == [row["center_x"], row["center_y"], row["center_z"]]

    vehicles = json.loads(page.evaluate("JSON.stringify(strataViewer.viewer.manifest.vehicles)"))
    car = min(vehicles, key=lambda v: abs(v["center"][0] + 6) + abs(v["center"][1] + 4))
    record = click_at(page, car["center"][0], car["center"][1], car["center"][2] + 0.5)
    assert record["kind"] == "vehicle"
    row = catalog_row(yard["map"], "vehicles", "vehicle_id", car["vehicle_id"])
    assert record["vehicle_id"] == row["vehicle_id"]
    assert record["size"] == [row["length_m"], row["width_m"], row["height_m"]]
    assert record["cleared_voxels"] == row["cleared_voxels"]
    save_screenshot(page.screenshot(), "viewer_record.png")

    record = click_at(page, 0.0, 3.0, 0.0)  # the yard's ground, no object near
    assert record["kind"] == "voxel" and record["observed"] and record["occupied"]
    assert record["class"] == "ground"
    assert abs(record["center"][0]) < 1.0 and abs(record["center"][1] - 3.0) < 1.5
    assert page.console_errors() == []


def test_every_colour_mode_layer_and_the_free_space_slice_draw_without_errors(server, open_page):
    for state, name in (("color=height&layers=walls,vehicles", None),
                        ("color=session&layers=cleared", None),
                        ("color=class&free=1.0&layers=walls", "viewer_free.png")):
        page, _ = view(open_page, server, state, name)
        assert page.evaluate("strataViewer.cells") > 1000, state
    assert page.evaluate("strataViewer.viewer.sets.free.cells") > 100


def test_the_static_export_opens_from_disk_with_the_same_colours(yard, scratch, open_page):
    folder = os.path.join(scratch, "yard_html")
    out = run("view", yard["map"], "--html", folder)
    assert "1 session diffs" in out
    url = "file://" + os.path.join(folder, "index.html")
    page, png = view(open_page, url, "color=class&layers=")
    assert page.evaluate("strata.isStatic()")
    assert pixels(page, png, SOUTH_WALL, BUILDING) >= MIN_PIXELS["wall"]
    page, png = view(open_page, url, "diff=1,2&layers=")
    assert pixels(page, png, CONTAINER, ADDED) >= MIN_PIXELS["added"]
    assert pixels(page, png, LEAVING_CAR, REMOVED) >= MIN_PIXELS["removed"]


def fetch(url):
    with urllib.request.urlopen(url, timeout=30) as r:
        return r.read()


def test_a_server_keeps_its_snapshot_while_another_process_commits(yard, scratch):
    copy = os.path.join(scratch, "yard_pinned")
    subprocess.run(["cp", "-r", yard["map"], copy], check=True)
    process, url = cdp.start_view(STRATA, [copy])
    try:
        manifest = fetch(url + "api/map")
        tiles = [f"api/tile/{t['x']}/{t['y']}/{t['version']}/0"
                 for t in json.loads(manifest)["snapshots"][0]["tiles"]]
        before = {t: fetch(url + t) for t in tiles}
        run("integrate", copy, "--kitti", os.path.join(yard["sequence"], "session_1"),
            "--name", "again")
        assert fetch(url + "api/map") == manifest
        assert {t: fetch(url + t) for t in tiles} == before
    finally:
        cdp.stop(process)
    process, url = cdp.start_view(STRATA, [copy])  # a new server sees the new session
    try:
        assert len(json.loads(fetch(url + "api/map"))["sessions"]) == 3
    finally:
        cdp.stop(process)


def test_bad_arguments_fail_with_the_exit_code_of_their_kind(yard, scratch):
    def code(*args):
        return subprocess.run([STRATA, "view", *args], stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL).returncode
    assert code(os.path.join(scratch, "no_map_here")) == 5
    assert code(yard["map"], "--port", "70000") == 2
    assert code(yard["map"], "--as-of", "nosuchsession") == 5
    assert code(yard["map"], "--html", yard["map"]) == 2  # a folder that is not empty
