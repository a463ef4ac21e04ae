#!/usr/bin/env python3
"""What each tier's tests cost a core: runs every ctest of a build directory, JOBS at a
time, and measures each test's user and system CPU (wait4 on the test's process: its
children that it waits for are counted) and its wall time. Prints, per tier (the tier
labels of tests/common/tiers.cmake), the tests, their wall and CPU seconds and the share
of a core they use while they run (100 x CPU / wall), the figure LAGSIM_TIER_RUN's share
column holds; then the tests that cost the most CPU.

    tests/common/cpu_profile.py build [--jobs 4] [--exclude-tier slow] [--tsv out.tsv]

A test's process group is killed when the test ends (a daemon it left behind), when it
runs past its TIMEOUT (then counted as failed), and when this tool ends or is stopped.
Run it on a quiet machine: a loaded one stretches the wall times and lowers the shares.
"""
import argparse
import json
import os
import signal
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))


def tiers():
    """The tiers, as structure_names reads them (tests/structure/check_structure.py)."""
    sys.path.insert(0, os.path.join(HERE, '..', 'structure'))
    import check_structure
    return check_structure.load_tiers(os.path.join(HERE, "tiers.cmake"))[0]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    ap.add_argument('build')
    ap.add_argument('--jobs', type=int, default=4)
    ap.add_argument('--exclude-tier', action='append', default=[])
    ap.add_argument('--tsv', help='one line per test: name wall user sys status labels')
    a = ap.parse_args()
    known = tiers()
    out = subprocess.run(['ctest', '--test-dir', a.build, '--show-only=json-v1'],
                         check=True, capture_output=True, text=True).stdout
    todo, alone = [], []
    for t in json.loads(out)['tests']:
        props = {p['name']: p['value'] for p in t.get('properties', [])}
        tier = next((l for l in props.get('LABELS', []) if l in known), '?')
        if tier in a.exclude_tier:
            continue
        one = (t['name'], t['command'], props, tier)
        # a resource lock, a fixture or RUN_SERIAL: one at a time, after the others
        serial = any(k in props for k in ('RUN_SERIAL', 'RESOURCE_LOCK', 'FIXTURES_SETUP',
                                           'FIXTURES_REQUIRED'))
        (alone if serial else todo).append(one)
    alone.sort(key=lambda t: 'FIXTURES_SETUP' not in t[2])
    running, rows = {}, []

    def start(t):
        env = dict(os.environ)
        for e in t[2].get('ENVIRONMENT', []):
            k, _, v = e.partition('=')
            env[k] = v
        p = subprocess.Popen(t[1], cwd=t[2].get('WORKING_DIRECTORY'), env=env,
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                             start_new_session=True)
        running[p.pid] = (t, time.monotonic(), p)  # kept: a Popen let go is reaped by subprocess

    def overdue():
        """Kills the group of each test past its TIMEOUT (its wait4 then reaps it)."""
        now = time.monotonic()
        for pid, (t, t0, _) in running.items():
            if now - t0 > float(t[2].get('TIMEOUT', 1500)):
                try:
                    os.killpg(pid, signal.SIGKILL)
                except OSError:
                    pass

    def reap():
        while True:
            pid, status, ru = os.wait4(-1, os.WNOHANG)
            if pid:
                break
            overdue()
            time.sleep(0.05)
        if pid not in running:
            return
        t, t0, _ = running.pop(pid)
        try:
            os.killpg(pid, signal.SIGKILL)
        except OSError:
            pass
        rows.append((t[0], t[3], time.monotonic() - t0, ru.ru_utime, ru.ru_stime,
                     os.waitstatus_to_exitcode(status), ','.join(t[2].get('LABELS', []))))

    try:
        for t in todo:
            while len(running) >= a.jobs:
                reap()
            start(t)
        while running:
            reap()
        for t in alone:
            start(t)
            while running:
                reap()
    finally:  # stopped (Ctrl-C) or failed: no test's processes outlive the tool
        for pid in running:
            try:
                os.killpg(pid, signal.SIGKILL)
            except OSError:
                pass
    if a.tsv:
        with open(a.tsv, 'w') as f:
            for r in rows:
                f.write(f'{r[0]}\t{r[2]:.2f}\t{r[3]:.2f}\t{r[4]:.2f}\t{r[5]}\t{r[6]}\n')
    print(f'{"tier":10} {"tests":>5} {"wall s":>8} {"CPU s":>8} {"share":>6}')
    total = [0, 0.0, 0.0]
    for tier in known:
        mine = [r for r in rows if r[1] == tier]
        if not mine:
            continue
        wall = sum(r[2] for r in mine)
        cpu = sum(r[3] + r[4] for r in mine)
        total = [total[0] + len(mine), total[1] + wall, total[2] + cpu]
        print(f'{tier:10} {len(mine):5} {wall:8.1f} {cpu:8.1f} {100 * cpu / wall:6.0f}')
    print(f'{"all":10} {total[0]:5} {total[1]:8.1f} {total[2]:8.1f}')
    print('the most CPU:')
    for r in sorted(rows, key=lambda r: -(r[3] + r[4]))[:15]:
        print(f'  {r[0]:48} {r[1]:9} wall {r[2]:6.1f} CPU {r[3] + r[4]:6.1f}')
    failed = [r[0] for r in rows if r[5] not in (0, 77)]
    if failed:
        print(f'failed here ({len(failed)}; run alone before believing it): {" ".join(failed)}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
