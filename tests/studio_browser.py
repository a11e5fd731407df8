#!/usr/bin/python3
"""rigc studio in a real browser (Debian's chromium, chromium-driver, python3-selenium).

Run by the GoogleTest StudioBrowser.* (studio/studio_browser_test.cpp), which writes the scene:
    /usr/bin/python3 tests/studio_browser.py --rigc build/rigc --scene SCENE.yaml [--screenshots DIR]
Exits 0 when every check passed; prints each check and what it measured.
"""
import argparse
import math
import os
import re
import shutil
import subprocess
import sys
import time

from selenium import webdriver
from selenium.webdriver.chrome.service import Service
from selenium.webdriver.common.action_chains import ActionChains
from selenium.webdriver.common.by import By
from selenium.webdriver.common.keys import Keys
from selenium.webdriver.support.ui import Select

# Mean linear luminance of a canvas (sRGB decoded), and a sharpness figure: the mean absolute
# horizontal difference of luma in a box (fractions of the canvas).
CANVAS_STATS_JS = """
const canvas = document.getElementById(arguments[0]);
const box = arguments[1];
const g = document.createElement('canvas');
g.width = canvas.width; g.height = canvas.height;
const ctx = g.getContext('2d');
ctx.drawImage(canvas, 0, 0);
const x0 = Math.floor(box[0] * g.width), y0 = Math.floor(box[1] * g.height);
const x1 = Math.floor(box[2] * g.width), y1 = Math.floor(box[3] * g.height);
const d = ctx.getImageData(x0, y0, x1 - x0, y1 - y0).data;
const lin = (c) => { c /= 255; return c <= 0.04045 ? c / 12.92 : Math.pow((c + 0.055) / 1.055, 2.4); };
let sum = 0, n = 0, grad = 0, red = 0, green = 0, white = 0;
const w = x1 - x0;
for (let i = 0; i < d.length; i += 4) {
  const y = 0.2126 * lin(d[i]) + 0.7152 * lin(d[i + 1]) + 0.0722 * lin(d[i + 2]);
  sum += y; ++n;
  const luma = 0.2126 * d[i] + 0.7152 * d[i + 1] + 0.0722 * d[i + 2];
  if ((i / 4) % w > 0) {
    const j = i - 4;
    grad += Math.abs(luma - (0.2126 * d[j] + 0.7152 * d[j + 1] + 0.0722 * d[j + 2]));
  }
  if (d[i] > 120 && d[i + 1] < 60 && d[i + 2] < 60) ++red;
  if (d[i + 1] > 90 && d[i] < 60 && d[i + 2] < 70) ++green;
  if (d[i] > 170 && d[i + 1] > 170 && d[i + 2] > 170) ++white;
}
return {mean: sum / n, sharpness: grad / n, red: red, green: green, white: white};
"""

SHUTTER_INDEX_JS = "return rigcStudio.state.stops.shutters.findIndex((s) => Math.abs(s - arguments[0]) < 1e-9);"


class Checks:
    def __init__(self):
        self.failed = 0

    def expect(self, ok, what):
        print(('ok:   ' if ok else 'FAIL: ') + what, flush=True)
        if not ok:
            self.failed += 1


def start_studio(rigc, scene):
    # Reference checks go to a run folder beside the scene.
    run_folder = os.path.join(os.path.dirname(os.path.abspath(scene)), 'studio-run')
    proc = subprocess.Popen([rigc, 'studio', scene, '-o', run_folder], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    line = proc.stdout.readline()
    match = re.search(r'(http://\S+)', line)
    if not match:
        proc.kill()
        sys.exit('rigc studio printed no address: ' + line + proc.stderr.read())
    return proc, match.group(1)


def browser(width, height):
    options = webdriver.ChromeOptions()
    for flag in ('--headless=new', '--no-sandbox', '--enable-unsafe-swiftshader',
                 f'--window-size={width},{height}', '--force-device-scale-factor=1'):
        options.add_argument(flag)
    driver = webdriver.Chrome(service=Service('/usr/bin/chromedriver'), options=options)
    # The page's own size, whatever room the headless window's frame takes.
    driver.execute_cdp_cmd('Emulation.setDeviceMetricsOverride',
                           {'width': width, 'height': height, 'deviceScaleFactor': 1, 'mobile': False})
    return driver


def wait_for(driver, script, timeout=60, what='the page'):
    deadline = time.time() + timeout
    while time.time() < deadline:
        value = driver.execute_script(script)
        if value:
            return value
        time.sleep(0.05)
    raise TimeoutError(f'timed out waiting for {what}: {script}')


def frames_shown(driver):
    return driver.execute_script('return rigcStudio.frame.count')


def wait_full_frame(driver, after_count):
    """Waits for a full-width frame newer than `after_count` and for the page to settle."""
    wait_for(driver, f'return rigcStudio.frame.count > {after_count} && '
             'rigcStudio.frame.width == 1280 && !rigcStudio.frames.busy && !rigcStudio.frames.wanted',
             what='a full frame')
    time.sleep(0.2)


def set_slider(driver, element_id, index):
    count = frames_shown(driver)
    driver.execute_script(
        "const s = document.getElementById(arguments[0]); s.value = arguments[1];"
        "s.dispatchEvent(new Event('change'));", element_id, index)
    wait_full_frame(driver, count)


def stats(driver, canvas, box=(0, 0, 1, 1)):
    return driver.execute_script(CANVAS_STATS_JS, canvas, list(box))


def check_exposure_and_depth_of_field(driver, checks):
    shutter = driver.execute_script('return rigcStudio.state.camera.shutter_s')
    index = driver.execute_script(SHUTTER_INDEX_JS, shutter)
    before = stats(driver, 'view')['mean']
    set_slider(driver, 'shutter', index - 3)  # three third-stops: one stop longer
    after = stats(driver, 'view')['mean']
    stops = math.log2(after / before)
    new_shutter = driver.execute_script('return rigcStudio.state.camera.shutter_s')
    checks.expect(abs(new_shutter / shutter - 2) < 0.15, f'shutter {shutter:.5f} s -> {new_shutter:.5f} s')
    checks.expect(0.75 <= stops <= 1.25, f'one stop longer brightens the frame by {stops:.2f} stops')
    set_slider(driver, 'shutter', index)

    # The backdrop behind the object is out of focus wide open; stopped down, its edge (the
    # floor line, in the lower part of the frame) sharpens.
    apertures = driver.execute_script('return rigcStudio.state.stops.apertures')
    box = (0.0, 0.55, 1.0, 1.0)
    shutter_at = lambda s: driver.execute_script(SHUTTER_INDEX_JS, s)
    set_slider(driver, 'aperture', apertures.index(2.8))
    set_slider(driver, 'shutter', shutter_at(1 / 1000))  # the same exposure at both apertures
    wide = stats(driver, 'view', box)
    set_slider(driver, 'aperture', apertures.index(16))
    set_slider(driver, 'shutter', shutter_at(1 / 30))
    closed = stats(driver, 'view', box)
    # Gradients relative to the mean level, so that a small change of exposure does not count.
    sharp_wide = wide['sharpness'] / max(wide['mean'], 1e-6)
    sharp_closed = closed['sharpness'] / max(closed['mean'], 1e-6)
    checks.expect(sharp_closed > 1.15 * sharp_wide,
                  f'f/2.8 -> f/16: background edges sharpen (relative gradient {sharp_wide:.1f} -> '
                  f'{sharp_closed:.1f})')


def coverage_counts(driver):
    return stats(driver, 'coverage-canvas')


def capture(driver):
    shots = driver.execute_script('return rigcStudio.coverage.shots')
    driver.find_element(By.TAG_NAME, 'body').send_keys(Keys.SPACE)
    wait_for(driver, f'return rigcStudio.coverage.shots == {shots + 1}', what='the coverage')
    time.sleep(0.3)


def turn_view(driver, degrees):
    count = frames_shown(driver)
    driver.execute_script(
        "const s = document.getElementById('turntable'); s.value = Number(s.value) + arguments[0];"
        "s.dispatchEvent(new Event('change'));", degrees)
    wait_full_frame(driver, count)


def check_capture_and_coverage(driver, checks, rigc, scene, workdir):
    start = coverage_counts(driver)
    turn_view(driver, 90)
    capture(driver)
    first = coverage_counts(driver)
    checks.expect(first['red'] > start['red'] + 200,
                  f"a capture from a new side turns faces red ({start['red']} -> {first['red']} red px)")
    # Orbit by dragging the live view a little: the second view overlaps the first.
    view = driver.find_element(By.ID, 'view')
    ActionChains(driver).move_to_element(view).click_and_hold().move_by_offset(-60, 0).release().perform()
    wait_for(driver, 'return !rigcStudio.view.busy && !rigcStudio.frames.busy', what='the drag')
    capture(driver)
    second = coverage_counts(driver)
    checks.expect(second['green'] > first['green'] + 200,
                  f"a second, overlapping capture turns faces green ({first['green']} -> {second['green']} green px)")
    driver.find_element(By.ID, 'save').click()
    wait_for(driver, 'return !rigcStudio.state.unsaved', what='the save')
    out = os.path.join(workdir, 'coverage-out')
    run = subprocess.run([rigc, 'coverage', scene, '-o', out], capture_output=True, text=True)
    table = driver.execute_script('return rigcStudio.coverage.table').strip().splitlines()
    printed = [line for line in run.stdout.splitlines() if line.split()[:1] in (['shot'], ) or
               re.match(r'shot_\d+ ', line)]
    checks.expect(run.returncode == 0 and table == printed,
                  f'the page\'s table matches `rigc coverage` on the saved scene ({len(table) - 1} shots)')
    if table != printed:
        print('page:\n' + '\n'.join(table) + '\nrigc coverage:\n' + run.stdout + run.stderr)


def check_save_and_broken_file(driver, checks, rigc, scene, original):
    text = open(scene).read()
    comments = [line.strip() for line in original.splitlines() if line.strip().startswith('#')]
    checks.expect(all(c in text for c in comments), f'the saved file keeps its {len(comments)} comment lines')
    checks.expect(text.count('- pose:') == 3, 'the saved file holds the two captures as pose entries')
    run = subprocess.run([rigc, 'check', scene, '--no-advice'], capture_output=True, text=True)
    checks.expect(run.returncode == 0, 'the saved file passes `rigc check`' + run.stderr)
    broken = text.replace('iso: ', 'iso: -', 1)
    with open(scene, 'w') as f:
        f.write(broken)
    shown = wait_for(driver, "const e = document.getElementById('file-error');"
                     "return !e.hidden && e.textContent", what='the error banner')
    line = next(i for i, l in enumerate(broken.splitlines(), 1) if 'iso: -' in l)
    located = re.search(rf'{re.escape(os.path.basename(scene))}:{line}:\d+: error: ', shown)
    checks.expect(bool(located) and 'iso: -' in shown,
                  f'a broken file shows as file:{line}:col: error with its line: {shown.splitlines()[0]}')
    checks.expect(stats(driver, 'view')['mean'] > 0.005, 'the last good scene stays on screen')
    with open(scene, 'w') as f:
        f.write(text)


def check_suggest_next_shot(driver, checks):
    """The planner's next shot (rigc plan --next) becomes the view."""
    before = driver.find_element(By.ID, 'pose-readout').text
    driver.find_element(By.ID, 'suggest').click()
    wait_for(driver, "return document.getElementById('status').textContent.startsWith('suggested')",
             timeout=180, what='the suggestion')
    status = driver.find_element(By.ID, 'status').text
    after = driver.find_element(By.ID, 'pose-readout').text
    checks.expect(after != before and 'adds' in status,
                  f'"Suggest next shot" moves the view ({status}; {after})')


def check_reference(driver, checks):
    """The reference check renders the view with POV-Ray beside the preview; flicker shows one."""
    if not shutil.which('povray'):
        print('skip: the reference check needs povray')
        return
    Select(driver.find_element(By.ID, 'reference-width')).select_by_visible_text('160')
    driver.find_element(By.ID, 'reference-start').click()
    checks.expect(bool(wait_for(driver, 'return !document.getElementById("reference-cancel").disabled',
                                what='the render to start')), 'the reference check starts')
    shown = wait_for(driver, "const p = document.getElementById('reference-panel');"
                     "const r = document.getElementById('reference-image');"
                     "const v = document.getElementById('reference-preview');"
                     "return !p.hidden && r.complete && v.complete && r.naturalWidth > 0 && "
                     "v.naturalWidth > 0 && [v.naturalWidth, r.naturalWidth, r.naturalHeight]",
                     timeout=400, what='the reference')
    status = driver.find_element(By.ID, 'reference-status').text
    checks.expect(shown[0] == shown[1] == 160,
                  f'the POV-Ray reference shows beside the preview ({shown[1]} x {shown[2]} px; {status})')
    driver.find_element(By.ID, 'reference-flicker').click()
    time.sleep(0.2)
    visible = driver.execute_script(
        "return ['reference-preview', 'reference-image'].filter((id) => !document.getElementById(id).hidden)")
    checks.expect(len(visible) == 1, f'flicker shows one of the two at a time ({visible})')


def screenshots(rigc, scene, directory):
    os.makedirs(directory, exist_ok=True)
    for width, height in ((1280, 800), (1920, 1080)):
        proc, url = start_studio(rigc, scene)
        driver = browser(width, height)
        try:
            driver.get(url)
            wait_for(driver, 'return rigcStudio.frame.count > 0 && rigcStudio.coverage && '
                     "document.querySelectorAll('#advice li').length > 0", what='the page')
            time.sleep(1.0)
            path = os.path.join(directory, f'studio-{width}x{height}.png')
            if not driver.save_screenshot(path):
                raise RuntimeError(f'could not write {path}')
            print('wrote', path)
        finally:
            driver.quit()
            proc.terminate()
            proc.wait()


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument('--rigc', required=True)
    parser.add_argument('--scene', required=True)
    parser.add_argument('--screenshots')
    args = parser.parse_args()
    if args.screenshots:
        screenshots(args.rigc, args.scene, args.screenshots)
        return 0
    original = open(args.scene).read()
    checks = Checks()
    proc, url = start_studio(args.rigc, args.scene)
    driver = browser(1600, 1000)
    try:
        driver.get(url)
        wait_for(driver, 'return rigcStudio.frame.count > 0 && rigcStudio.coverage', what='the page')
        wait_full_frame(driver, 0)
        check_exposure_and_depth_of_field(driver, checks)
        check_capture_and_coverage(driver, checks, args.rigc, args.scene, os.path.dirname(args.scene))
        check_save_and_broken_file(driver, checks, args.rigc, args.scene, original)
        check_suggest_next_shot(driver, checks)
        check_reference(driver, checks)
    finally:
        driver.quit()
        proc.send_signal(2)  # Ctrl-C
        try:
            code = proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            proc.kill()
            code = None
    checks.expect(code == 0, f'Ctrl-C stops rigc studio cleanly (exit {code})')
    return 1 if checks.failed else 0


if __name__ == '__main__':
    sys.exit(main())
