#!/usr/bin/env python3
"""Plot the switching experiment's paths (seed Fig. 4.8): top, the Detailed-only runs; bottom, the
runs with dynamic model switching, each sample coloured by the level in use. Course boxes are drawn
from the scenario. Usage: plot_paths.py DIR [--scenario FILE]  -> DIR/paths.png"""
import argparse
import csv
import glob
import os

import matplotlib
matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402
import yaml  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
COLOURS = {'basic': '#2ca02c', 'simple': '#17becf', 'medium': '#ff7f0e', 'detailed': '#d62728'}


def load_runs(directory, mode):
    runs = []
    for f in sorted(glob.glob(os.path.join(directory, '%s_run*.csv' % mode))):
        with open(f) as fh:
            rows = list(csv.DictReader(fh))
        runs.append(rows)
    return runs


def draw_course(ax, scenario):
    with open(scenario) as fh:
        sc = yaml.safe_load(fh)
    import math
    for b in sc['world']['terrain'].get('boxes', []):
        cx, cy, _ = b['center']
        sx, sy, _ = b['size']
        yaw = b.get('yaw', 0.0)
        pitch = b.get('pitch', 0.0)
        sx *= abs(math.cos(pitch))
        name = b.get('name', '')
        colour = '#bbbbbb' if name.startswith('rugged') else ('#dddddd' if name != 'slope' else '#c8b4a0')
        c, s = math.cos(yaw), math.sin(yaw)
        corners = [(-sx / 2, -sy / 2), (sx / 2, -sy / 2), (sx / 2, sy / 2), (-sx / 2, sy / 2)]
        xs = [cx + c * x - s * y for x, y in corners]
        ys = [cy + s * x + c * y for x, y in corners]
        ax.fill(xs, ys, color=colour, lw=0, zorder=0)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('directory')
    ap.add_argument('--scenario', default=os.path.join(ROOT, 'config', 'scenarios', 'composite_course_switching.yaml'))
    a = ap.parse_args()
    fig, axes = plt.subplots(2, 1, figsize=(8, 11), sharex=True)
    for ax, mode, title in ((axes[0], 'detailed', 'Detailed model only'),
                            (axes[1], 'switching', 'Dynamic model switching (basic / medium / detailed)')):
        draw_course(ax, a.scenario)
        runs = load_runs(a.directory, mode)
        for rows in runs:
            xs = [float(r['x']) for r in rows]
            ys = [float(r['y']) for r in rows]
            if mode == 'detailed':
                ax.plot(xs, ys, '-', color=COLOURS['detailed'], lw=0.8, alpha=0.7)
            else:
                ax.scatter(xs, ys, s=1.5, c=[COLOURS.get(r['level'], 'k') for r in rows], zorder=2)
            ax.plot(xs[-1:], ys[-1:], 'kx', ms=6)
        ax.set_title('%s: %d runs' % (title, len(runs)))
        ax.set_aspect('equal')
        ax.set_ylabel('y [m]')
        ax.grid(alpha=0.3)
    for lvl in ('basic', 'medium', 'detailed'):
        axes[1].plot([], [], 'o', color=COLOURS[lvl], label=lvl)
    axes[1].legend(loc='upper left')
    axes[1].set_xlabel('x [m]')
    summary = os.path.join(a.directory, 'summary.txt')
    if os.path.exists(summary):
        with open(summary) as fh:
            lines = fh.read().splitlines()
        fig.text(0.02, 0.005, '\n'.join(l for l in lines if l.startswith(('wall', 'CPU'))), fontsize=8, family='monospace')
    fig.tight_layout(rect=(0, 0.03, 1, 1))
    out = os.path.join(a.directory, 'paths.png')
    fig.savefig(out, dpi=110)
    print('wrote', out)


if __name__ == '__main__':
    main()
