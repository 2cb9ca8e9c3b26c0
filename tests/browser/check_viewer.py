#!/usr/bin/python3
"""Browser test of the mocap viewer, in a real headless Chromium.

Starts the viewer on a free loopback port with the given motion files,
drives Chromium through chromedriver (W3C WebDriver, with selenium, Debian's
python3-selenium), and checks what a person would:

- the page loads and shows one skeleton per file, with the frame and joint
  counts written in the files (read here from the BVH text, independently of
  the Rust reader);
- pressing Play advances the frames, and Pause stops them;
- the scrubber moves to a chosen frame;
- hovering a joint names it;
- a screenshot is not blank: the motions' colours are on it.

Usage: check_viewer.py --viewer PATH_TO_MOCAP_BINARY [--out DIR] FILE.bvh|FILE.glb...
Prints one line per check and "N passed, N failed"; exits 1 on a failure.
"""

import argparse
import json
import os
import re
import socket
import struct
import subprocess
import sys
import time
import urllib.request
import zlib

from selenium import webdriver
from selenium.webdriver.common.actions.action_builder import ActionBuilder
from selenium.webdriver.common.by import By

BACKGROUND = (0xF4, 0xF4, 0xF2)


# ---------- the WebDriver client (selenium, on the chromedriver started here) ----------

class WebDriver:
    def __init__(self, base):
        self.base = base
        self.browser = None

    def start(self, chromium):
        options = webdriver.ChromeOptions()
        options.binary_location = chromium
        for arg in ["--headless=new", "--no-sandbox", "--disable-gpu",
                    "--disable-dev-shm-usage", "--window-size=1200,800",
                    "--force-device-scale-factor=1"]:
            options.add_argument(arg)
        self.browser = webdriver.Remote(command_executor=self.base, options=options)

    def get(self, url):
        self.browser.get(url)

    def js(self, script, *args):
        return self.browser.execute_script(script, *args)

    def click(self, css):
        self.browser.find_element(By.CSS_SELECTOR, css).click()

    def move_pointer(self, x, y):
        actions = ActionBuilder(self.browser)
        actions.pointer_action.move_to_location(int(x), int(y))
        actions.perform()

    def screenshot(self):
        return self.browser.get_screenshot_as_png()

    def quit(self):
        if self.browser:
            try:
                self.browser.quit()
            except Exception:
                pass


# ---------- PNG decoding (8-bit RGB/RGBA, as Chromium writes) ----------

def decode_png(data):
    """Returns (width, height, channels, rows) with rows as bytearrays."""
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError("not a PNG")
    pos, idat = 8, []
    width = height = channels = None
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        chunk = data[pos + 8:pos + 8 + length]
        pos += 12 + length
        if kind == b"IHDR":
            width, height, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", chunk)
            if depth != 8 or colour not in (2, 6) or interlace != 0:
                raise ValueError(f"unsupported PNG (depth {depth}, colour type {colour}, interlace {interlace})")
            channels = 3 if colour == 2 else 4
        elif kind == b"IDAT":
            idat.append(chunk)
        elif kind == b"IEND":
            break
    raw = zlib.decompress(b"".join(idat))
    stride = width * channels
    rows, previous = [], bytearray(stride)
    for y in range(height):
        start = y * (stride + 1)
        kind, row = raw[start], bytearray(raw[start + 1:start + 1 + stride])
        if kind == 1:
            for i in range(channels, stride):
                row[i] = (row[i] + row[i - channels]) & 255
        elif kind == 2:
            for i in range(stride):
                row[i] = (row[i] + previous[i]) & 255
        elif kind == 3:
            for i in range(stride):
                left = row[i - channels] if i >= channels else 0
                row[i] = (row[i] + ((left + previous[i]) >> 1)) & 255
        elif kind == 4:
            for i in range(stride):
                a = row[i - channels] if i >= channels else 0
                b = previous[i]
                c = previous[i - channels] if i >= channels else 0
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                row[i] = (row[i] + pred) & 255
        rows.append(row)
        previous = row
    return width, height, channels, rows


def hex_rgb(colour):
    return tuple(int(colour[k:k + 2], 16) for k in (1, 3, 5))


# ---------- what the files say ----------

def gltf_counts(path):
    """(frames, joints) of a glTF or GLB file, from its JSON: the sample
    count of the first animation's time accessor, and the first skin's
    joints."""
    data = open(path, "rb").read()
    if data[:4] == b"glTF":
        length = struct.unpack_from("<I", data, 12)[0]
        data = data[20:20 + length]
    document = json.loads(data.decode("utf-8"))
    sampler = document["animations"][0]["samplers"][0]
    return document["accessors"][sampler["input"]]["count"], len(document["skins"][0]["joints"])


def file_counts(path):
    """(frames, joints) as written in a BVH file's text, in a fused
    capture (.jsonl, one frame per line) or in a glTF file's JSON."""
    if path.endswith((".glb", ".gltf")):
        return gltf_counts(path)
    text = open(path, encoding="utf-8", errors="replace").read()
    if path.endswith(".jsonl"):
        lines = [json.loads(line) for line in text.splitlines() if line.strip()]
        return len(lines), len(lines[0]["joints"])
    frames = int(re.search(r"Frames:\s*(\d+)", text).group(1))
    joints = len(re.findall(r"^\s*(?:ROOT|JOINT)\s", text, re.M))
    return frames, joints


# ---------- helpers ----------

# Kinect v2 joints (SDK order) with a height above the floor and a side, for
# the synthetic fused capture below.
KINECT = [("SpineBase", 0.95, 0), ("SpineMid", 1.2, 0), ("Neck", 1.45, 0), ("Head", 1.6, 0),
          ("ShoulderLeft", 1.4, -1), ("ElbowLeft", 1.1, -1), ("WristLeft", 0.85, -1), ("HandLeft", 0.8, -1),
          ("ShoulderRight", 1.4, 1), ("ElbowRight", 1.1, 1), ("WristRight", 0.85, 1), ("HandRight", 0.8, 1),
          ("HipLeft", 0.92, -1), ("KneeLeft", 0.5, -1), ("AnkleLeft", 0.08, -1), ("FootLeft", 0.02, -1),
          ("HipRight", 0.92, 1), ("KneeRight", 0.5, 1), ("AnkleRight", 0.08, 1), ("FootRight", 0.02, 1),
          ("SpineShoulder", 1.4, 0), ("HandTipLeft", 0.75, -1), ("ThumbLeft", 0.8, -1),
          ("HandTipRight", 0.75, 1), ("ThumbRight", 0.8, 1)]


def write_fused_capture(path, frames=90):
    """A synthetic fused capture (the format mocap-fuse writes): a figure
    swaying side to side whose left-side joints have confidence 0 and the
    others 1, to check the confidence colours. Test data, not a capture."""
    import math
    with open(path, "w") as f:
        for i in range(frames):
            sway = 0.1 * math.sin(i / 10)
            joints = [[round(sway + 0.2 * side, 4), height, 0.0] for _, height, side in KINECT]
            confidence = [0.0 if side < 0 else 1.0 for _, _, side in KINECT]
            f.write(json.dumps({"t": i / 30, "joints": joints, "confidence": confidence}) + "\n")


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wait_for(condition, timeout, what):
    deadline = time.time() + timeout
    while time.time() < deadline:
        value = condition()
        if value:
            return value
        time.sleep(0.1)
    raise TimeoutError(f"timed out after {timeout} s waiting for {what}")


class Checks:
    def __init__(self):
        self.passed = 0
        self.failed = 0

    def check(self, name, ok, detail=""):
        print(("ok   " if ok else "FAIL ") + name + (f": {detail}" if detail else ""), flush=True)
        if ok:
            self.passed += 1
        else:
            self.failed += 1
        return ok


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--viewer", required=True, help="the mocap binary (run as `mocap view`)")
    parser.add_argument("--chromium", default="/usr/bin/chromium")
    parser.add_argument("--chromedriver", default="/usr/bin/chromedriver")
    parser.add_argument("--out", default=None, help="folder for the screenshot")
    parser.add_argument("--with-fused", action="store_true",
                        help="add a synthetic fused capture with confidence (written to --out)")
    parser.add_argument("files", nargs="+")
    args = parser.parse_args()
    out = args.out or os.environ.get("OUT") or "."
    os.makedirs(out, exist_ok=True)
    if args.with_fused:
        fused = os.path.join(out, "fused-test.jsonl")
        write_fused_capture(fused)
        args.files.append(fused)

    expected = [file_counts(f) for f in args.files]
    checks = Checks()
    processes = []
    driver = None
    try:
        # The viewer, on a free port of its choosing (port 0); it prints the
        # address on standard error.
        server = subprocess.Popen([args.viewer, "view", "--port", "0", *args.files],
                                  stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        processes.append(server)
        line = server.stderr.readline()
        match = re.search(r"http://127\.0\.0\.1:\d+/", line)
        if not match:
            raise RuntimeError(f"the viewer did not start: {line.strip()}")
        url = match.group(0)
        print(f"viewer at {url}", flush=True)

        port = free_port()
        chromedriver = subprocess.Popen([args.chromedriver, f"--port={port}"],
                                        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        processes.append(chromedriver)
        driver = WebDriver(f"http://127.0.0.1:{port}")
        wait_for(lambda: _status_ok(driver), 30, "chromedriver")
        driver.start(args.chromium)
        driver.get(url)

        # The page loads and reads the scene.
        wait_for(lambda: driver.js("return document.body.dataset.ready === '1'"), 30, "the scene")
        error = driver.js("return getComputedStyle(document.getElementById('error')).display")
        checks.check("page loads without error", error == "none")

        motions = driver.js("return window.mocapViewer.motionCount()")
        legend_rows = driver.js("return document.querySelectorAll('#motions .motion').length")
        checks.check("one skeleton per file", motions == len(args.files) and legend_rows == len(args.files),
                     f"{motions} motions, {legend_rows} legend rows, {len(args.files)} files")
        frames = driver.js("return window.mocapViewer.frameCounts()")
        checks.check("frame counts match the files", frames == [f for f, _ in expected],
                     f"page {frames}, files {[f for f, _ in expected]}")
        joints = driver.js("return window.mocapViewer.jointCounts()")
        checks.check("joint counts match the files", joints == [j for _, j in expected],
                     f"page {joints}, files {[j for _, j in expected]}")
        label = driver.js("return document.getElementById('frame-label').textContent")
        checks.check("frame label shows frame 0 and the first file's frame count",
                     label.startswith(f"frame 0 · {expected[0][0]} frames"), repr(label))

        # Play advances the frames; pause stops them.
        start_frames = driver.js("return window.mocapViewer.currentFrames()")
        driver.click("#play")
        time.sleep(1.5)
        playing_frames = driver.js("return window.mocapViewer.currentFrames()")
        playing = driver.js("return window.mocapViewer.playing()")
        checks.check("playing advances frames",
                     playing and playing_frames[0] > start_frames[0],
                     f"{start_frames} -> {playing_frames} after 1.5 s")
        checks.check("the frame label follows",
                     driver.js("return document.getElementById('frame-label').textContent") != label)
        driver.click("#play")
        paused = driver.js("return window.mocapViewer.currentFrames()")
        time.sleep(0.5)
        still = driver.js("return window.mocapViewer.currentFrames()")
        checks.check("pause stops", paused == still and not driver.js("return window.mocapViewer.playing()"),
                     f"{paused} -> {still}")

        # The scrubber jumps to a frame (the middle of the first motion).
        target = expected[0][0] // 2
        driver.js("const s = document.getElementById('scrubber'); s.value = arguments[0];"
                  "s.dispatchEvent(new Event('input'));", target)
        time.sleep(0.2)
        scrubbed = driver.js("return window.mocapViewer.currentFrames()")
        checks.check("the scrubber sets the frame", scrubbed[0] == target, f"wanted {target}, got {scrubbed[0]}")

        # Hovering a joint names it.
        time.sleep(0.2)
        root = driver.js("return window.mocapViewer.bodyRoot(0)")
        spot = driver.js("const p = window.mocapViewer.jointOnScreen(0, arguments[0]);"
                         "const r = document.getElementById('view').getBoundingClientRect();"
                         "return p && {x: r.left + p.x / devicePixelRatio, y: r.top + p.y / devicePixelRatio};", root)
        if spot:
            driver.move_pointer(spot["x"], spot["y"])
            time.sleep(0.3)
            tip = driver.js("const t = document.getElementById('tooltip');"
                            "return t.style.display === 'block' ? t.textContent : '';")
            name = driver.js("return window.mocapViewer.pointName(0, arguments[0])", root)
            checks.check("hovering a joint shows its name", name in tip, f"tooltip {tip!r}, joint {name!r}")
            driver.move_pointer(5, 5)
        else:
            checks.check("hovering a joint shows its name", False, f"joint {root} of motion 0 is not on screen")

        # Side by side: each motion on its own spot, left to right.
        if len(args.files) > 1:
            driver.js("const l = document.getElementById('layout'); l.value = 'side';"
                      "l.dispatchEvent(new Event('change'));")
            time.sleep(0.3)
            xs = driver.js("const v = window.mocapViewer;"
                           "return v.frameCounts().map((_, i) => { const p = v.jointOnScreen(i, v.bodyRoot(i));"
                           "return p ? p.x : null; });")
            checks.check("side by side puts the motions left to right",
                         None not in xs and all(a + 20 < b for a, b in zip(xs, xs[1:])), f"hips at x = {xs}")

        # The screenshot is not blank: each motion's colour is on it.
        png = driver.screenshot()
        shot_path = os.path.join(out, "viewer-screenshot.png")
        with open(shot_path, "wb") as f:
            f.write(png)
        width, height, channels, rows = decode_png(png)
        # Motions with confidence are drawn in confidence colours (the page
        # starts in that mode when a motion has confidence): look for red
        # (0) and green (1) instead of their own colour.
        has_confidence = driver.js("return window.mocapViewer.hasConfidence()")
        colour_mode = driver.js("return document.getElementById('colour-by').value")
        if any(has_confidence):
            checks.check("confidence colouring is on for a fused capture", colour_mode == "confidence", colour_mode)
        colours = [hex_rgb(c) for c, conf in zip(driver.js("return window.mocapViewer.colours()"), has_confidence)
                   if not conf]
        if any(has_confidence):
            colours += [(212, 17, 17), (15, 188, 15)]  # hsl(0,85%,45%) and hsl(120,85%,40%)
        near = [0] * len(colours)
        not_background = 0
        for row in rows:
            for i in range(0, width * channels, channels):
                pixel = (row[i], row[i + 1], row[i + 2])
                if max(abs(pixel[k] - BACKGROUND[k]) for k in range(3)) > 24:
                    not_background += 1
                for m, c in enumerate(colours):
                    if max(abs(pixel[k] - c[k]) for k in range(3)) < 25:
                        near[m] += 1
        share = not_background / (width * height)
        checks.check("screenshot is not blank", share > 0.01,
                     f"{width}x{height}, {100 * share:.1f}% of pixels are not background; saved {shot_path}")
        checks.check("every skeleton's colour (and red and green for confidence) is on the screenshot",
                     all(n >= 50 for n in near), f"pixels per colour {near}")
    except Exception as e:  # a check that could not run is a failure
        checks.check("the browser test ran to the end", False, f"{type(e).__name__}: {e}")
    finally:
        if driver:
            driver.quit()
        for p in reversed(processes):
            p.terminate()
            try:
                p.wait(timeout=10)
            except subprocess.TimeoutExpired:
                p.kill()
    print(f"{checks.passed} passed, {checks.failed} failed", flush=True)
    return 1 if checks.failed else 0


def _status_ok(driver):
    try:
        with urllib.request.urlopen(driver.base + "/status", timeout=2) as response:
            return json.loads(response.read()).get("value", {}).get("ready")
    except Exception:
        return False


if __name__ == "__main__":
    sys.exit(main())
