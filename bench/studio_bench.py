#!/usr/bin/python3
"""rigc studio's responsiveness, measured in the browser with the Performance API.

    /usr/bin/python3 bench/studio_bench.py --rigc build/rigc [--scene scenes/paper-turntable.yaml]

Works on a copy of the scene (saves never touch the original). Prints:
- slider change (ISO, `change` event) to the new 1280 px frame drawn: p50 and p95 (target p95 <= 100 ms);
- capture (space bar) to the coverage view recoloured with the new table: median and max
  (target <= 150 ms);
- dragging the live view for 4 s: frames delivered per second (target >= 15).
"""
import argparse
import os
import shutil
import statistics
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'tests'))
from studio_browser import browser, start_studio, wait_for  # noqa: E402


def percentile(values, p):
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(round(p / 100 * (len(ordered) - 1))))]


def settle(driver):
    wait_for(driver, 'return !rigcStudio.frames.busy && !rigcStudio.frames.wanted && !rigcStudio.view.busy', what='the page')
    time.sleep(0.3)


def bench_slider(driver, changes):
    start = driver.execute_script('return Number(document.getElementById("iso").value)')
    for i in range(changes):
        index = start + (1 if i % 2 == 0 else 0)
        driver.execute_script("const s = document.getElementById('iso'); s.value = arguments[0];"
                              "s.dispatchEvent(new Event('change'));", index)
        wait_for(driver, f"return performance.getEntriesByName('rigc:slider').length > {i}", what='a frame')
        settle(driver)
    return driver.execute_script("return performance.getEntriesByName('rigc:slider').map((e) => e.duration)")


def bench_capture(driver, captures):
    for i in range(captures):
        driver.execute_script("const s = document.getElementById('turntable');"
                              "s.value = Number(s.value) + 25; s.dispatchEvent(new Event('change'));")
        settle(driver)
        driver.execute_script("document.getElementById('capture').click()")
        wait_for(driver, f"return performance.getEntriesByName('rigc:capture').length > {i}", what='the coverage')
        settle(driver)
    entries = "performance.getEntriesByName('rigc:capture')"
    return driver.execute_script(f'return {entries}.map((e) => e.duration)'), \
        driver.execute_script(f'return {entries}.map((e) => e.detail)')


DRAG_JS = """
const canvas = document.getElementById('view');
const r = canvas.getBoundingClientRect();
const done = arguments[arguments.length - 1];
const seconds = arguments[0];
const ev = (type, x) => canvas.dispatchEvent(new PointerEvent(type, {clientX: x, clientY: r.top + 100,
  pointerId: 1, bubbles: true}));
canvas.setPointerCapture = () => {};
ev('pointerdown', r.left + 400);
const drags = () => performance.getEntriesByName('rigc:drag');
const before = drags().length;
const t0 = performance.now();
let x = 400;
const timer = setInterval(() => {
  x += 4;
  ev('pointermove', r.left + x);
  if (performance.now() - t0 > seconds * 1000) {
    clearInterval(timer);
    const frames = drags().slice(before).filter((f) => f.startTime + f.duration <= t0 + seconds * 1000);
    ev('pointerup', r.left + x);
    done({frames: frames.length, seconds: seconds, ms: frames.map((f) => f.duration)});
  }
}, 16);
"""


def bench_drag(driver, seconds):
    driver.set_script_timeout(seconds + 30)
    return driver.execute_async_script(DRAG_JS, seconds)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument('--rigc', required=True)
    parser.add_argument('--scene', default='scenes/paper-turntable.yaml')
    parser.add_argument('--changes', type=int, default=30)
    parser.add_argument('--captures', type=int, default=8)
    args = parser.parse_args()
    workdir = tempfile.mkdtemp(prefix='rigc-studio-bench-')
    scene = os.path.join(workdir, os.path.basename(args.scene))
    shutil.copy(args.scene, scene)
    proc, url = start_studio(args.rigc, scene)
    driver = browser(1600, 1000)
    try:
        driver.get(url)
        wait_for(driver, 'return rigcStudio.frame.count > 0 && rigcStudio.coverage', timeout=300,
                 what='the page')
        settle(driver)
        slider = bench_slider(driver, args.changes)
        print(f'slider change -> 1280 px frame drawn: p50 {percentile(slider, 50):.0f} ms, '
              f'p95 {percentile(slider, 95):.0f} ms ({len(slider)} changes)')
        drag = bench_drag(driver, 4)
        print(f"drag: {drag['frames'] / drag['seconds']:.1f} frames/s delivered "
              f"({drag['frames']} in {drag['seconds']} s; view change -> frame p50 "
              f"{percentile(drag['ms'], 50):.0f} ms)")
        settle(driver)
        captures, parts = bench_capture(driver, args.captures)
        print(f'capture -> coverage view updated: median {statistics.median(captures):.0f} ms, '
              f'max {max(captures):.0f} ms ({len(captures)} captures)')
        for key in ('capture', 'coverage', 'wait', 'analysis', 'json', 'draw'):
            values = [p[key] for p in parts if key in p]
            if values:
                print(f'  of it {key}: median {statistics.median(values):.0f} ms')
    finally:
        driver.quit()
        proc.send_signal(2)
        proc.wait(timeout=10)
        shutil.rmtree(workdir, ignore_errors=True)
    return 0


if __name__ == '__main__':
    sys.exit(main())
