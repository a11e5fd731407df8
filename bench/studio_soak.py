#!/usr/bin/python3
"""rigc studio under an hour of use: random edits, views, captures (30 at most, so that the scene
stays about one size), undos and saves from the browser (the browser tests' driver,
tests/studio_browser.py), on loopback.

    /usr/bin/python3 bench/studio_soak.py --rigc build/rigc [--minutes 60] [--seed 1]

Works on a copy of the scene (scenes/paper-turntable.yaml unless --scene). Samples the studio's
resident memory every --sample-s seconds and counts every answer the page got by status. Passes
(exit 0) when no answer was a 5xx, the memory after the first tenth of the run grew by at most
--most-growth-mb (the caches' bounds: 64 MB of visibility, three analyses, two renders, 500 undo
steps), and the file saved last holds the studio's state (no unsaved changes, the shots and the
exposure the page shows). Prints the samples and the counts.
"""
import argparse
import collections
import json
import os
import random
import shutil
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'tests'))
from studio_browser import browser, start_studio, wait_for  # noqa: E402

# Counts the page's answers by status: every fetch the page makes goes through window.fetch.
COUNT_STATUSES_JS = """
if (!window.soakStatuses) {
  window.soakStatuses = {};
  const original = window.fetch;
  window.fetch = async (...args) => {
    const res = await original(...args);
    window.soakStatuses[res.status] = (window.soakStatuses[res.status] || 0) + 1;
    return res;
  };
}
"""

SLIDE_JS = """
const s = document.getElementById(arguments[0]);
const max = Number(s.max), min = Number(s.min);
s.value = Math.max(min, Math.min(max, Number(s.value) + arguments[1]));
s.dispatchEvent(new Event('input'));
s.dispatchEvent(new Event('change'));
"""

STATE_JS = """
const done = arguments[arguments.length - 1];
fetch('api/state', {headers: {'X-Rigc-Token': token}}).then((r) => r.json()).then(done);
"""


def rss_mb(pid):
    with open(f'/proc/{pid}/status') as f:
        for line in f:
            if line.startswith('VmRSS:'):
                return int(line.split()[1]) / 1024
    return 0.0


def settle(driver):
    wait_for(driver, 'return !rigcStudio.frames.busy && !rigcStudio.frames.wanted && !rigcStudio.view.busy', timeout=120,
             what='the page')


WEIGHTS = {'slider': 5, 'turn': 3, 'capture': 1, 'undo': 2, 'save': 1}


def act(driver, rng, kinds):
    """One random action a user takes (of `kinds`); returns its name."""
    action = rng.choices(kinds, weights=[WEIGHTS[k] for k in kinds])[0]
    if action == 'slider':
        slider = rng.choice(['aperture', 'shutter', 'iso', 'focal', 'wb'])
        driver.execute_script(SLIDE_JS, slider, rng.choice([-2, -1, 1, 2]))
        action += ' ' + slider
    elif action == 'turn':
        driver.execute_script(SLIDE_JS, 'turntable', rng.choice([-40, -15, 15, 40]))
    elif action == 'capture':
        driver.execute_script("document.getElementById('capture').click()")
    else:
        driver.execute_script(f"document.getElementById('{action}').click()")
    settle(driver)
    return action


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    here = os.path.dirname(os.path.abspath(__file__))
    parser.add_argument('--rigc', required=True)
    parser.add_argument('--scene', default=os.path.join(here, '..', 'scenes', 'paper-turntable.yaml'))
    parser.add_argument('--minutes', type=float, default=60)
    parser.add_argument('--seed', type=int, default=1)
    parser.add_argument('--sample-s', type=float, default=30)
    parser.add_argument('--most-growth-mb', type=float, default=160)
    parser.add_argument('--most-captures', type=int, default=30,
                        help='captures at most (then the shots stay about as many)')
    parser.add_argument('--actions', default=','.join(WEIGHTS),
                        help='the kinds of action, of ' + ', '.join(WEIGHTS))
    args = parser.parse_args()

    work = tempfile.mkdtemp(prefix='rigc-soak-')
    scene = os.path.join(work, 'scene.yaml')
    shutil.copy(args.scene, scene)
    proc, url = start_studio(os.path.abspath(args.rigc), scene)
    driver = browser(1600, 1000)
    rng = random.Random(args.seed)
    samples, actions = [], collections.Counter()
    failed = []
    try:
        driver.get(url)
        wait_for(driver, 'return rigcStudio.frame.count > 0', timeout=120, what='the first frame')
        driver.execute_script(COUNT_STATUSES_JS)
        start = time.time()
        end = start + 60 * args.minutes
        next_sample = start
        while time.time() < end:
            if time.time() >= next_sample:
                samples.append((time.time() - start, rss_mb(proc.pid)))
                next_sample += args.sample_s
            kinds = [k for k in args.actions.split(',')
                     if k != 'capture' or actions['capture'] < args.most_captures]
            actions[act(driver, rng, kinds)] += 1
            if proc.poll() is not None:
                failed.append(f'the studio exited ({proc.returncode})')
                break
        samples.append((time.time() - start, rss_mb(proc.pid)))
        driver.execute_script("document.getElementById('save').click()")
        settle(driver)
        time.sleep(0.5)
        statuses = driver.execute_script('return window.soakStatuses')
        state = driver.execute_async_script(STATE_JS)
    finally:
        driver.quit()
        proc.terminate()
        proc.wait(timeout=30)

    # The file saved last, compiled on its own, against the state the page shows.
    ir = json.loads(subprocess.run([args.rigc, 'compile', scene], capture_output=True, text=True,
                                   check=True).stdout)
    server_errors = sum(n for status, n in statuses.items() if int(status) >= 500)
    warm = [rss for t, rss in samples if t >= 0.1 * 60 * args.minutes] or [samples[-1][1]]
    growth = max(warm) - warm[0]
    print(f'soak: {args.minutes:g} min, {sum(actions.values())} actions: '
          + ', '.join(f'{k} {v}' for k, v in sorted(actions.items())))
    print('answers by status: ' + ', '.join(f'{k}: {v}' for k, v in sorted(statuses.items())))
    print('resident memory (MB) by minute: '
          + ', '.join(f'{t / 60:.0f}: {rss:.0f}' for t, rss in samples))
    print(f'growth after the first tenth: {growth:.0f} MB (bound {args.most_growth_mb:g} MB)')
    if server_errors:
        failed.append(f'{server_errors} answers were 5xx')
    if growth > args.most_growth_mb:
        failed.append(f'memory grew {growth:.0f} MB after the first tenth')
    camera = ir['camera']
    saved = (not state['unsaved'] and len(ir['shots']) == state['shots'] and
             abs(camera['iso'] - state['camera']['iso']) < 1e-9 and
             abs(camera['shutter_s'] - state['camera']['shutter_s']) < 1e-12 and
             abs(camera['aperture_f_number'] - state['camera']['aperture']) < 1e-9)
    print(f'saved file holds the state: {"yes" if saved else "NO"} '
          f'({len(ir["shots"])} shots, ISO {camera["iso"]:g}, f/{camera["aperture_f_number"]:g})')
    if not saved:
        failed.append('the saved file is not the last state')
    shutil.rmtree(work, ignore_errors=True)
    for f in failed:
        print('FAIL: ' + f)
    return 1 if failed else 0


if __name__ == '__main__':
    sys.exit(main())
