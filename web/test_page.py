#!/usr/bin/env python3
"""Drives voxgi's web page in headless Chromium (WebGPU on SwiftShader) and checks it.

    python3 web/test_page.py DIR [--out SHOTS] [--chromium PATH]

DIR is what web/build.sh wrote. The page is served from DIR on a local port and opened with
no query string: the built-in Cornell box, at the page's defaults for a CPU adapter (64^3
voxels, the half-resolution gather). The test waits for frames the GPU finished, then
checks, in this order:
  - the picture: the left wall is red, the right wall green, and the ceiling, which only
    bounced light reaches (the lamp faces down), is lit; the page chose 64^3;
  - an orbit drag on the canvas changes the picture, and so does flying forward (F, W);
  - the panel: the octree instead of the dense volume shows the same picture; the split
    view shows voxgi's path tracer right of the middle, its right wall green and as bright
    as the cones' within a factor of two; setting `bounces` to 0 (direct light only) darkens
    the ceiling;
  - examples/cornell-moving.toml opened with the file button: its [settings] show in the
    panel and its animation plays (the picture changes more than it does paused);
  - a scene file whose camera flies: the view follows it until dragged by hand;
  - a broken .glb from the file button shows an error naming it while the scene shown
    stays; an OBJ with its .mtl (a white floor and a red wall, made here) opens and shows
    its red wall;
  - the page shows no error and the console logged none (but the broken file's);
  - with only WebGPU's default limits (128 MiB storage buffers), 512^3 voxels are lowered
    to 256^3 and the page says why.
Screenshots go to SHOTS (default: a temporary folder), for looking at. It prints the time to
the first frame and the frame time. Exit status 0 when every check passes.

Needs Playwright (pip install playwright; it drives the system's Chromium, no download) and
Debian's chromium. The flags are those that give headless Chromium a WebGPU adapter that can
present to a canvas on a machine without a GPU.
"""

import argparse
from pathlib import Path
import functools
import http.server
import io
import sys
import tempfile
import threading
import time

CHROMIUM_FLAGS = [
    "--enable-unsafe-webgpu",
    "--enable-unsafe-swiftshader",
    "--enable-features=Vulkan",
    "--use-vulkan=swiftshader",
    "--use-angle=swiftshader",
    "--no-sandbox",
]

# SwiftShader renders a frame of the page in seconds; the first frame also compiles every
# pipeline and builds the voxels.
FIRST_FRAMES_S = 300
FRAMES_S = 120


class Quiet(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args):
        pass

    def end_headers(self):
        # Each run serves a fresh build.
        self.send_header("Cache-Control", "no-store")
        super().end_headers()


def serve(directory):
    handler = functools.partial(Quiet, directory=directory)
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    return server


START = time.time()


def say(text):
    """Prints `text` after the seconds since the test began."""
    print(f"[{time.time() - START:5.1f} s] {text}", flush=True)


def frames(page):
    return int(page.evaluate("document.body.dataset.frames || '0'"))


def page_error(page):
    return page.evaluate("document.getElementById('error').textContent").strip()


def wait_frames(page, count, seconds):
    """Waits until the GPU finished `count` frames; fails on a page error or a timeout."""
    end = time.time() + seconds
    while time.time() < end:
        error = page_error(page)
        if error:
            raise AssertionError(f"the page shows an error: {error}")
        if frames(page) >= count:
            return
        time.sleep(0.5)
    raise AssertionError(
        f"only {frames(page)} of {count} frames after {seconds} s; status: "
        + page.evaluate("document.getElementById('status').textContent")
    )


def more_frames(page, count):
    """Waits until the GPU finished `count` more frames than it had."""
    wait_frames(page, frames(page) + count, FRAMES_S)


def wait_scene(page, name):
    """Waits until the page shows the scene `name` (`data-scene`); fails on a page error."""
    end = time.time() + FRAMES_S
    while page.evaluate("document.body.dataset.scene") != name:
        if page_error(page) or time.time() > end:
            raise AssertionError(f"{name} did not open: {page_error(page)}")
        time.sleep(0.5)


def shot(page, path):
    """The canvas as an RGB image (and saved to `path`)."""
    from PIL import Image

    data = page.locator("#voxgi").screenshot(path=path, timeout=FRAMES_S * 1000)
    return Image.open(io.BytesIO(data)).convert("RGB")


def box_bounds(img):
    """The Cornell box's extent in the picture: the bounding box of pixels brighter than the
    black background."""
    w, h = img.size
    px = img.load()
    xs, ys = [], []
    for y in range(0, h, 2):
        for x in range(0, w, 2):
            if sum(px[x, y]) > 45:
                xs.append(x)
                ys.append(y)
    if not xs:
        raise AssertionError("the canvas is black")
    return min(xs), min(ys), max(xs), max(ys)


def mean(img, box, fx0, fy0, fx1, fy1):
    """Mean RGB over the part (fx0..fx1, fy0..fy1) of `box`, as fractions of its size."""
    x0, y0, x1, y1 = box
    bw, bh = x1 - x0, y1 - y0
    px = img.load()
    total, n = [0, 0, 0], 0
    for y in range(int(y0 + fy0 * bh), int(y0 + fy1 * bh)):
        for x in range(int(x0 + fx0 * bw), int(x0 + fx1 * bw)):
            for c in range(3):
                total[c] += px[x, y][c]
            n += 1
    return [t / max(n, 1) for t in total]


def drag(page, offsets):
    """A left-button drag on the canvas from its centre through `offsets` (pixels from the
    centre, each reached in a few steps)."""
    canvas = page.locator("#voxgi").bounding_box()
    cx, cy = canvas["x"] + canvas["width"] / 2, canvas["y"] + canvas["height"] / 2
    page.mouse.move(cx, cy)
    page.mouse.down()
    for dx, dy in offsets:
        page.mouse.move(cx + dx, cy + dy, steps=4)
    page.mouse.up()


def change_over_frames(page, path, spans=1):
    """How much the picture changes over two frames: the canvas shot, two more frames, shot
    again (saved as `path`_0.png, _1.png, ...); over several `spans` in a row, the largest
    `difference` between consecutive shots."""
    more_frames(page, 2)
    shots = [shot(page, f"{path}_0.png")]
    for i in range(spans):
        more_frames(page, 2)
        shots.append(shot(page, f"{path}_{i + 1}.png"))
    return max(difference(a, b) for a, b in zip(shots, shots[1:]))


def difference(a, b):
    """Mean absolute difference per channel, 0..255."""
    pa, pb = a.load(), b.load()
    w, h = a.size
    total = 0
    for y in range(0, h, 2):
        for x in range(0, w, 2):
            total += sum(abs(pa[x, y][c] - pb[x, y][c]) for c in range(3))
    return total / (3 * ((w + 1) // 2) * ((h + 1) // 2))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("dir")
    parser.add_argument("--out", default=None)
    parser.add_argument("--chromium", default="/usr/bin/chromium")
    args = parser.parse_args()
    out = args.out or tempfile.mkdtemp(prefix="voxgi-web-")

    from playwright.sync_api import sync_playwright

    server = serve(args.dir)
    url = f"http://127.0.0.1:{server.server_address[1]}/index.html"
    console_errors = []
    with sync_playwright() as p:
        browser = p.chromium.launch(
            executable_path=args.chromium, headless=True, args=CHROMIUM_FLAGS
        )
        # A small canvas: SwiftShader's frame time follows its pixels.
        page = browser.new_page(viewport={"width": 640, "height": 360})
        page.on(
            "console",
            lambda m: console_errors.append(m.text) if m.type == "error" else None,
        )
        page.on("pageerror", lambda e: console_errors.append(str(e)))
        page.goto(url)

        wait_frames(page, 4, FIRST_FRAMES_S)
        first_ms = float(page.evaluate("document.body.dataset.firstFrameMs"))
        before = shot(page, f"{out}/cornell.png")
        # The whole page too, panel and status lines with it (the README's picture).
        page.screenshot(path=f"{out}/page.png", timeout=FRAMES_S * 1000)
        box = box_bounds(before)
        left = mean(before, box, 0.02, 0.3, 0.12, 0.7)
        right = mean(before, box, 0.88, 0.3, 0.98, 0.7)
        # Between the lamp (the middle of the ceiling) and the walls.
        ceiling = mean(before, box, 0.2, 0.02, 0.32, 0.1)
        say(f"left wall {left}, right wall {right}, ceiling {ceiling}")
        # The walls' colours dominate their pixels (the reference's albedos are 0.63/0.065
        # red and 0.14/0.45 green): a margin of 1.5x holds under any exposure.
        assert left[0] > 1.5 * left[1] and left[0] > 1.5 * left[2] and left[0] > 40, (
            f"the left wall is not red: {left}"
        )
        assert right[1] > 1.5 * right[0] and right[1] > 1.5 * right[2] and right[1] > 30, (
            f"the right wall is not green: {right}"
        )
        # Bounced light alone lights the ceiling there: 20 of 255 is well above black and
        # well below what the native renders show (about 90).
        assert sum(ceiling) / 3 > 20, f"the ceiling is dark: {ceiling}"
        choices = page.evaluate("document.getElementById('choices').textContent")
        say(f"the renderer chose: {choices}")
        assert "64³" in choices, f"a CPU adapter did not get 64^3 voxels: {choices}"

        # An orbit drag turns the view.
        n = frames(page)
        drag(page, [(60, 0), (120, 10)])
        wait_frames(page, n + 2, FRAMES_S)
        turned = shot(page, f"{out}/turned.png")
        d = difference(before, turned)
        say(f"the drag changed the picture by {d:.1f} of 255 on average")
        # A 120-pixel drag turns the box by about 35 degrees: its walls move by tens of
        # pixels (19.7 measured); a still view's frames differ by under 1.
        assert d > 4, f"an orbit drag did not change the picture ({d:.1f})"

        # Flying: F, then W held for a second moves the camera forward.
        page.dblclick("#voxgi")  # back to the scene's camera
        page.keyboard.press("f")
        assert page.evaluate("document.body.dataset.camera") == "fly", "F did not fly"
        more_frames(page, 2)
        still = shot(page, f"{out}/fly_before.png")
        page.keyboard.down("w")
        time.sleep(1.0)
        page.keyboard.up("w")
        more_frames(page, 2)
        flown = shot(page, f"{out}/flown.png")
        d = difference(still, flown)
        say(f"flying forward changed the picture by {d:.1f} of 255 on average")
        # A second of flight at half the scene's radius a second: everything grows (28.9
        # measured); a still view's frames differ by under 1.
        assert d > 4, f"holding W while flying did not move the camera ({d:.1f})"
        page.keyboard.press("f")
        assert page.evaluate("document.body.dataset.camera") == "orbit", "F did not orbit"

        # The other structure: the octree, from the panel, shows the same box.
        page.dblclick("#voxgi")  # back to the scene's camera
        page.select_option("#setting-voxels", "octree")
        more_frames(page, 3)
        octree = shot(page, f"{out}/octree.png")
        d = difference(before, octree)
        say(f"octree against dense: {d:.1f} of 255 on average")
        # The two structures sample the same function (docs/QUALITY.md); what differs is
        # rounding and the accumulation's noise (0.2 of 255 measured).
        assert d < 2, f"the octree's picture differs from the dense volume's by {d:.1f}"
        assert "octree" in page.evaluate("document.getElementById('choices').textContent")

        # The split view: voxgi's path tracer right of the middle, accumulating.
        page.select_option("#display", "split: cones | path tracer")
        more_frames(page, 5)
        split = shot(page, f"{out}/split.png")
        choices = page.evaluate("document.getElementById('choices').textContent")
        say(f"split view: {choices}")
        assert "samples a pixel" in choices, f"the path tracer is not shown: {choices}"
        traced_wall = mean(split, box, 0.88, 0.3, 0.98, 0.7)
        coned_wall = mean(octree, box, 0.88, 0.3, 0.98, 0.7)
        say(f"the right wall path traced {traced_wall}, cone traced {coned_wall}")
        # Path traced, the right wall is still green, and as bright as cone tracing makes it
        # within a factor of two (both bounce twice; docs/QUALITY.md measures how close).
        assert traced_wall[1] > 1.5 * traced_wall[0] and traced_wall[1] > 1.5 * traced_wall[2], (
            f"the path-traced right wall is not green: {traced_wall}"
        )
        assert 0.5 < traced_wall[1] / max(coned_wall[1], 1) < 2, (
            f"the path-traced wall {traced_wall} is far from the cone-traced {coned_wall}"
        )
        page.select_option("#display", "cone tracing")

        # Direct light only: the ceiling has none.
        page.fill("#setting-bounces", "0")
        page.press("#setting-bounces", "Enter")
        more_frames(page, 3)
        direct = shot(page, f"{out}/direct.png")
        dark = mean(direct, box, 0.2, 0.02, 0.32, 0.1)
        say(f"ceiling with bounces = 0: {dark}")
        assert sum(dark) < 0.5 * sum(ceiling), (
            f"bounces = 0 did not darken the ceiling: {dark} against {ceiling}"
        )

        # A scene file with an animation and [settings], from the repository's examples.
        moving = Path(__file__).resolve().parent.parent / "examples" / "cornell-moving.toml"
        page.set_input_files("#file", files=[str(moving)])
        wait_scene(page, "cornell-moving.toml")
        play = page.evaluate("document.getElementById('play').textContent")
        assert play == "pause the animation", f"the animation is not playing: {play!r}"
        bounces = page.input_value("#setting-bounces")
        assert bounces == "2", f"the file's [settings] bounces = 2 is not shown: {bounces}"
        # A moving frame re-voxelizes the block and bounces twice: seconds on SwiftShader,
        # and the animation advances at most a quarter of a second a frame. Two frames
        # straddling the block's turn show it where it was (the lamp waits the first four
        # seconds), but the turns are two seconds apart: of two spans of two frames in a row,
        # one is centred half a second or more from a turn and moves the block by 4 cm or
        # more (it swings 7.5 cm either way).
        moving = change_over_frames(page, f"{out}/moving", spans=2)
        # Paused (Space), the same frames' difference is the accumulation's noise alone.
        page.keyboard.press("Space")
        play = page.evaluate("document.getElementById('play').textContent")
        assert play == "play the animation", f"Space did not pause: {play!r}"
        still = change_over_frames(page, f"{out}/paused", spans=3)
        say(
            f"cornell-moving.toml: the picture changed by {moving:.2f} of 255 playing, "
            f"{still:.2f} paused"
        )
        # The block and the lamp's light move: several times what noise does paused.
        assert moving > 3 * still + 0.1, (
            f"the animation did not move anything ({moving:.2f} playing, {still:.2f} paused)"
        )

        # A scene whose camera flies (sways sideways): the page follows it while playing,
        # and stops following once the view is dragged by hand.
        flight = (
            b'[[include]]\nbuiltin = "cornell-box"\n'
            b"[camera]\nposition = [0.278, 0.273, -0.8]\ntarget = [0.278, 0.273, 0.28]\n"
            b'[[animation]]\ntarget = "camera"\n'
            b"oscillate = { axis = [1.0, 0.0, 0.0], amplitude = 0.3, period = 4.0 }\n"
        )
        page.set_input_files(
            "#file", files=[{"name": "flight.toml", "mimeType": "text/plain", "buffer": flight}]
        )
        wait_scene(page, "flight.toml")
        flying = change_over_frames(page, f"{out}/flight")
        drag(page, [(30, 0)])
        by_hand = change_over_frames(page, f"{out}/by_hand")
        say(
            f"flight.toml: the picture changed by {flying:.2f} of 255 flying, "
            f"{by_hand:.2f} once dragged (still playing)"
        )
        # The box swept sideways by up to 0.2 m between shots, against the noise of a view
        # that stands still while the animation plays on.
        assert flying > 3 * by_hand + 0.1, (
            f"the camera did not fly ({flying:.2f} flying, {by_hand:.2f} dragged)"
        )

        frame_ms = page.evaluate("document.body.dataset.frameMs")

        # A broken file: its error on the page, the scene kept.
        shown = page.evaluate("document.body.dataset.scene")
        page.set_input_files(
            "#file",
            files=[{"name": "broken.glb", "mimeType": "model/gltf-binary", "buffer": b"not a glb"}],
        )
        end = time.time() + FRAMES_S
        while not page_error(page) and time.time() < end:
            time.sleep(0.5)
        error = page_error(page)
        say(f"the broken file's error: {error}")
        assert "broken.glb" in error, f"the error does not name the file: {error!r}"
        kept = page.evaluate("document.body.dataset.scene")
        assert kept == shown, f"after the broken file the page shows {kept}, not {shown}"
        # The page logs the error it shows, as it should.
        console_errors[:] = [e for e in console_errors if "broken.glb" not in e]
        page.click("#error")  # dismissed
        assert not page_error(page), "a click did not dismiss the error"
        more_frames(page, 2)

        # An OBJ with its material library: a white floor and a red wall.
        obj = (
            "mtllib room.mtl\n"
            "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\n"
            "v -1 0 -1\nv 1 0 -1\nv 1 2 -1\nv -1 2 -1\n"
            "usemtl white\nf 1 3 2\nf 1 4 3\n"
            "usemtl red\nf 5 6 7\nf 5 7 8\n"
        )
        mtl = "newmtl white\nKd 0.8 0.8 0.8\nnewmtl red\nKd 0.8 0.05 0.05\n"
        page.set_input_files(
            "#file",
            files=[
                {"name": "room.obj", "mimeType": "text/plain", "buffer": obj.encode()},
                {"name": "room.mtl", "mimeType": "text/plain", "buffer": mtl.encode()},
            ],
        )
        wait_scene(page, "room.obj")
        more_frames(page, 3)
        room = shot(page, f"{out}/room.png")
        px = room.load()
        w, h = room.size
        def share(test):
            hits = sum(1 for y in range(0, h, 2) for x in range(0, w, 2) if test(px[x, y]))
            return hits / (((w + 1) // 2) * ((h + 1) // 2))

        red = share(lambda p: p[0] > 40 and p[0] > 2 * p[1] and p[0] > 2 * p[2])
        green = share(lambda p: p[1] > 40 and p[1] > 1.5 * p[0] and p[1] > 1.5 * p[2])
        say(f"room.obj: {100 * red:.0f} % of the canvas is its red wall, {100 * green:.1f} % green")
        # The wall fills a good part of the default view of the room's bounds (12 % of the
        # canvas measured); the Cornell boxes before it have a green wall, the room none.
        assert green < 0.01, f"the Cornell box is still shown ({100 * green:.1f} % green)"
        assert red > 0.05, f"the OBJ's red wall is not shown ({100 * red:.1f} %)"
        say(
            f"first frame after {first_ms / 1000:.1f} s, {frame_ms} ms a frame "
            f"(SwiftShader); adapter: "
            + page.evaluate("document.getElementById('adapter').textContent")
        )
        if page_error(page):
            raise AssertionError(f"the page shows an error: {page_error(page)}")
        page.close()

        # A browser that offers only WebGPU's default limits (128 MiB storage buffers): a
        # 512³ dense volume does not fit, and the page lowers it and says so. (The first
        # frame at 256³ takes SwiftShader over a minute: the test reads the page's choice,
        # made when the renderer is, and does not wait for it.)
        small = browser.new_page(viewport={"width": 600, "height": 300})
        small.on(
            "console",
            lambda m: console_errors.append(m.text) if m.type == "error" else None,
        )
        small.goto(
            f"http://127.0.0.1:{server.server_address[1]}/index.html"
            "?webgpu_limits=default&voxel_resolution=512"
        )
        end = time.time() + FRAMES_S
        choices = ""
        while "lowered" not in choices and time.time() < end and not page_error(small):
            time.sleep(0.5)
            choices = small.evaluate("document.getElementById('choices').textContent")
        say(f"with WebGPU's default limits: {choices}")
        assert "lowered from 512³ to 256³" in choices and "128 MiB" in choices, (
            f"the page did not fit 512³ into 128 MiB storage buffers: {choices!r}, "
            f"error {page_error(small)!r}"
        )
        small.close()
        browser.close()
    server.shutdown()
    assert not console_errors, f"the console logged errors: {console_errors}"
    say(f"web page checks passed; screenshots in {out}")


if __name__ == "__main__":
    try:
        main()
    except AssertionError as e:
        print(f"test_page: FAILED: {e}", file=sys.stderr)
        sys.exit(1)
