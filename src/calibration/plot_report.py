#!/usr/bin/python3
"""Plots of `sbot_calibrate compare` (called by it; usable alone): plot_report.py REPORT_DIR

Reads REPORT_DIR/summary.json and the per-run CSV files under REPORT_DIR/data/v<i>/ written by the
C++ tool and draws REPORT_DIR/plots/*.png: heat map of the error by run and time window, trajectory
overlays, residual against time (turns shaded, contacts marked), residual against inputs and
features, parity plots, sensor residuals against distance / incidence / surface, and, when several
model variants were compared, a before/after bar chart and a waterfall.
"""
import csv
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

GROUPS = {"x": "position", "y": "position", "yaw": "yaw", "speed_left": "speed", "speed_right": "speed",
          "torque_left": "torque", "torque_right": "torque", "pitch": "tilt", "roll": "tilt"}


def group(channel):
    if channel in GROUPS:
        return GROUPS[channel]
    for g in ("ground", "ir", "light"):
        if channel.startswith(g):
            return g
    return channel


def fnum(s):
    try:
        return float(s)
    except (TypeError, ValueError):
        return math.nan


def read_samples(path):
    rows = {}
    if not os.path.exists(path):
        return rows
    with open(path) as f:
        for r in csv.DictReader(f):
            ch = r["channel"]
            d = rows.setdefault(ch, {k: [] for k in ("t", "measured", "predicted", "residual", "normalised", "v", "w",
                                                      "accel", "contact", "yaw", "distance", "incidence", "surface")})
            for k in d:
                d[k].append(r[k] if k == "surface" else fnum(r[k]))
    return {ch: {k: (np.array(v) if k != "surface" else v) for k, v in d.items()} for ch, d in rows.items()}


def read_trace(path):
    if not os.path.exists(path):
        return None
    data = np.genfromtxt(path, delimiter=",", names=True)
    return data if data.size > 1 else None


def read_summary(out):
    """REPORT_DIR/summary.json as written by `sbot_calibrate compare`; SystemExit naming what is wrong
    (it was a bare traceback for a missing folder, an empty file or a summary without variants)."""
    path = os.path.join(out, "summary.json")
    try:
        with open(path) as f:
            summary = json.load(f)
    except OSError as error:
        raise SystemExit("plot_report.py: cannot read %s: %s" % (path, error.strerror))
    except ValueError as error:
        raise SystemExit("plot_report.py: %s: not valid JSON: %s" % (path, error))
    if not isinstance(summary, dict) or not isinstance(summary.get("runs"), list) or \
            not isinstance(summary.get("variants"), list) or not summary["variants"]:
        raise SystemExit("plot_report.py: %s: expected the summary of `sbot_calibrate compare` (a 'runs' list and a "
                         "non-empty 'variants' list)" % path)
    return summary


def main(out):
    summary = read_summary(out)
    plots = os.path.join(out, "plots")
    try:
        os.makedirs(plots, exist_ok=True)
    except OSError as error:
        raise SystemExit("plot_report.py: cannot create %s: %s" % (plots, error.strerror))
    runs = summary["runs"]
    variants = summary["variants"]
    window = float(summary.get("window", 2.0))
    first, last = variants[0], variants[-1]
    samples = {v["label"]: {r["name"]: read_samples(os.path.join(out, v["dir"], r["name"] + ".csv")) for r in runs}
               for v in variants}
    traces = {v["label"]: {r["name"]: read_trace(os.path.join(out, v["dir"], r["name"] + "_trace.csv")) for r in runs}
              for v in variants}
    drive = [r for r in runs if r["kind"] == "drive"]

    # 1. Heat map: normalised RMS by run x time window (drive runs), first and last variant.
    shown = [first] if first is last else [first, last]
    grids = []
    fig, axes = plt.subplots(1, len(shown), figsize=(6 * len(shown), 0.45 * max(4, len(runs)) + 1.5), squeeze=False)
    for ax, v in zip(axes[0], shown):
        tmax = max([r["t_end"] for r in drive] + [window])
        nwin = max(1, int(math.ceil(tmax / window)))
        grid = np.full((len(runs), nwin), np.nan)
        for i, r in enumerate(runs):
            acc = np.zeros(nwin)
            cnt = np.zeros(nwin)
            for ch, d in samples[v["label"]][r["name"]].items():
                ok = np.isfinite(d["normalised"])
                if r["kind"] == "place":
                    idx = np.zeros(ok.sum(), dtype=int)
                else:
                    idx = np.minimum(nwin - 1, (d["t"][ok] / window).astype(int))
                z = np.minimum(np.abs(d["normalised"][ok]), 10.0) ** 2
                np.add.at(acc, idx, z)
                np.add.at(cnt, idx, 1)
            with np.errstate(invalid="ignore", divide="ignore"):
                grid[i] = np.sqrt(acc / cnt)
        grids.append((ax, grid, nwin))
    vmax = max([3.0] + [float(np.nanmax(g)) for _, g, _ in grids if np.isfinite(g).any()])
    for ax, grid, nwin in grids:
        im = ax.imshow(grid, aspect="auto", cmap="magma_r", vmin=0, vmax=vmax,
                       extent=(0, nwin * window, len(runs) - 0.5, -0.5), interpolation="nearest")
        ax.set_yticks(range(len(runs)))
        ax.set_yticklabels([r["name"] for r in runs], fontsize=7)
        ax.set_xlabel("time [s] (place runs: one cell)")
        fig.colorbar(im, ax=ax, label="RMS / noise (floor ~ 1)")
    for (ax, _, _), v in zip(grids, shown):
        ax.set_title("normalised RMS, %s" % v["label"], fontsize=9)
    fig.tight_layout()
    fig.savefig(os.path.join(plots, "heatmap.png"), dpi=110)
    plt.close(fig)

    # 2. Trajectories.
    n = max(1, len(drive))
    cols = min(4, n)
    rows_ = int(math.ceil(n / cols))
    fig, axes = plt.subplots(rows_, cols, figsize=(3.6 * cols, 3.4 * rows_), squeeze=False)
    for k, r in enumerate(drive):
        ax = axes[k // cols][k % cols]
        d = samples[first["label"]][r["name"]]
        if "x" in d and "y" in d:
            ax.plot(d["x"]["measured"], d["y"]["measured"], ".", ms=2, color="k", label="measured")
        for v, style in ((first, "-"), (last, "--")):
            tr = traces[v["label"]][r["name"]]
            if tr is not None:
                ax.plot(tr["x"], tr["y"], style, lw=1.2, label="sim " + v["label"])
            if first is last:
                break
        ax.set_title(r["name"], fontsize=8)
        ax.set_aspect("equal", adjustable="datalim")
        ax.tick_params(labelsize=6)
        if k == 0:
            ax.legend(fontsize=6)
    for k in range(len(drive), rows_ * cols):
        axes[k // cols][k % cols].axis("off")
    fig.suptitle("measured (dots) vs simulated open loop from the fitted start pose", fontsize=9)
    fig.tight_layout()
    fig.savefig(os.path.join(plots, "trajectories.png"), dpi=110)
    plt.close(fig)

    # 3. Residual against time, turns shaded, contacts marked.
    fig, axes = plt.subplots(rows_, cols, figsize=(3.8 * cols, 2.6 * rows_), squeeze=False)
    for k, r in enumerate(drive):
        ax = axes[k // cols][k % cols]
        tr = traces[first["label"]][r["name"]]
        d = samples[first["label"]][r["name"]]
        for ch, colour in (("x", "C0"), ("y", "C1"), ("yaw", "C2"), ("speed_left", "C3"), ("pitch", "C4")):
            if ch in d:
                ax.plot(d[ch]["t"], np.clip(d[ch]["normalised"], -10, 10), lw=0.7, color=colour, label=ch)
        if tr is not None:
            turning = np.abs(tr["w"]) > 0.5
            ax.fill_between(tr["t"], -10, 10, where=turning, color="0.85", step="mid", lw=0)
            c = tr["contact"] > 0
            if c.any():
                ax.plot(tr["t"][c], np.full(c.sum(), 9.0), "|", color="r", ms=6)
        ax.set_ylim(-10, 10)
        ax.set_title(r["name"], fontsize=8)
        ax.tick_params(labelsize=6)
        if k == 0:
            ax.legend(fontsize=5, ncol=2)
    for k in range(len(drive), rows_ * cols):
        axes[k // cols][k % cols].axis("off")
    fig.suptitle("normalised residual (%s) against time; grey: turning, red: contact" % first["label"], fontsize=9)
    fig.tight_layout()
    fig.savefig(os.path.join(plots, "residual_time.png"), dpi=110)
    plt.close(fig)

    # 4. Residual against inputs and features.
    feats = (("v", "forward speed [m/s]"), ("w", "turn rate [rad/s]"), ("accel", "acceleration [m/s^2]"), ("t", "time [s]"))
    groups_present = sorted({group(ch) for r in drive for ch in samples[first["label"]][r["name"]]})
    groups_present = [g for g in groups_present if g not in ("ir", "ground", "light")] or ["position"]
    fig, axes = plt.subplots(len(groups_present), len(feats), figsize=(3.3 * len(feats), 2.4 * len(groups_present)),
                             squeeze=False)
    for gi, g in enumerate(groups_present):
        for fi, (f, label) in enumerate(feats):
            ax = axes[gi][fi]
            xs, ys = [], []
            for r in drive:
                for ch, d in samples[first["label"]][r["name"]].items():
                    if group(ch) != g:
                        continue
                    xs.append(d[f])
                    ys.append(d["normalised"])
            if xs:
                x = np.concatenate(xs)
                y = np.concatenate(ys)
                ok = np.isfinite(x) & np.isfinite(y)
                step = max(1, ok.sum() // 6000)
                ax.plot(x[ok][::step], np.clip(y[ok][::step], -10, 10), ".", ms=1.5, alpha=0.4)
            ax.axhline(0, color="k", lw=0.5)
            ax.tick_params(labelsize=6)
            if gi == len(groups_present) - 1:
                ax.set_xlabel(label, fontsize=7)
            if fi == 0:
                ax.set_ylabel(g + " residual / sigma", fontsize=7)
    fig.suptitle("residual (%s) against inputs and features" % first["label"], fontsize=9)
    fig.tight_layout()
    fig.savefig(os.path.join(plots, "residual_features.png"), dpi=110)
    plt.close(fig)

    # 5. Parity.
    all_groups = sorted({group(ch) for r in runs for ch in samples[first["label"]][r["name"]]})
    fig, axes = plt.subplots(1, max(1, len(all_groups)), figsize=(3.2 * max(1, len(all_groups)), 3.2), squeeze=False)
    for gi, g in enumerate(all_groups):
        ax = axes[0][gi]
        for v, colour in ((first, "C0"), (last, "C1")):
            xs, ys = [], []
            for r in runs:
                for ch, d in samples[v["label"]][r["name"]].items():
                    if group(ch) == g:
                        xs.append(d["predicted"])
                        ys.append(d["measured"])
            if xs:
                x, y = np.concatenate(xs), np.concatenate(ys)
                ok = np.isfinite(x) & np.isfinite(y)
                step = max(1, ok.sum() // 5000)
                ax.plot(x[ok][::step], y[ok][::step], ".", ms=1.5, alpha=0.4, color=colour, label=v["label"])
                if ok.any():
                    lo, hi = min(x[ok].min(), y[ok].min()), max(x[ok].max(), y[ok].max())
                    ax.plot([lo, hi], [lo, hi], "k-", lw=0.5)
            if first is last:
                break
        ax.set_title(g, fontsize=8)
        ax.set_xlabel("simulated", fontsize=7)
        ax.set_ylabel("measured", fontsize=7)
        ax.tick_params(labelsize=6)
        if gi == 0:
            ax.legend(fontsize=6)
    fig.tight_layout()
    fig.savefig(os.path.join(plots, "parity.png"), dpi=110)
    plt.close(fig)

    # 6. Sensors: residual against distance, incidence angle and surface label.
    sensor_groups = [g for g in all_groups if g in ("ir", "ground", "light")]
    if sensor_groups:
        fig, axes = plt.subplots(len(sensor_groups), 3, figsize=(11, 2.8 * len(sensor_groups)), squeeze=False)
        for gi, g in enumerate(sensor_groups):
            dist, inc, res, surf = [], [], [], []
            for r in runs:
                for ch, d in samples[first["label"]][r["name"]].items():
                    if group(ch) != g:
                        continue
                    dist.append(d["distance"])
                    inc.append(d["incidence"])
                    res.append(d["normalised"])
                    surf.extend(d["surface"])
            dist, inc, res = np.concatenate(dist), np.concatenate(inc), np.concatenate(res)
            ok = np.isfinite(res)
            axes[gi][0].plot(dist[ok] * 100, np.clip(res[ok], -10, 10), ".", ms=2, alpha=0.5)
            axes[gi][0].set_xlabel("distance [cm]", fontsize=7)
            axes[gi][1].plot(np.degrees(inc[ok]), np.clip(res[ok], -10, 10), ".", ms=2, alpha=0.5)
            axes[gi][1].set_xlabel("incidence [deg]", fontsize=7)
            labels = sorted({s for s, o in zip(surf, ok) if o and s})
            if labels:
                data = [np.clip(res[[o and s == lab for s, o in zip(surf, ok)]], -10, 10) for lab in labels]
                axes[gi][2].boxplot(data, labels=labels)
                axes[gi][2].tick_params(axis="x", labelsize=6, rotation=30)
            axes[gi][2].set_xlabel("surface", fontsize=7)
            axes[gi][0].set_ylabel(g + " residual / sigma", fontsize=7)
            for ax in axes[gi]:
                ax.axhline(0, color="k", lw=0.5)
                ax.tick_params(labelsize=6)
        fig.suptitle("sensor residuals (%s)" % first["label"], fontsize=9)
        fig.tight_layout()
        fig.savefig(os.path.join(plots, "sensor_features.png"), dpi=110)
        plt.close(fig)

    # 7./8. Before/after and waterfall.
    if len(variants) > 1:
        gs = sorted({g for v in variants for g in v["group_nrms"]})
        fig, ax = plt.subplots(figsize=(1.6 + 1.2 * len(gs), 3.2))
        width = 0.8 / len(variants)
        for i, v in enumerate(variants):
            ax.bar(np.arange(len(gs)) + i * width, [v["group_nrms"].get(g, 0) for g in gs], width, label=v["label"])
        ax.axhline(1.0, color="k", lw=0.7, ls="--")
        ax.set_xticks(np.arange(len(gs)) + 0.4 - width / 2)
        ax.set_xticklabels(gs, fontsize=8)
        ax.set_ylabel("normalised RMS (floor ~ 1)")
        ax.legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(os.path.join(plots, "before_after.png"), dpi=110)
        plt.close(fig)
        fig, ax = plt.subplots(figsize=(1.5 + 1.3 * len(variants), 3.2))
        vals = [v["nrms"] for v in variants]
        for i in range(len(vals)):
            lo = vals[i] if i == 0 else min(vals[i], vals[i - 1])
            hi = vals[i] if i == 0 else max(vals[i], vals[i - 1])
            ax.bar(i, hi - lo if i else hi, bottom=lo if i else 0, color="C0" if i == 0 else ("C2" if vals[i] <= vals[i - 1] else "C3"))
            ax.text(i, vals[i], "%.2f" % vals[i], ha="center", va="bottom", fontsize=7)
        ax.axhline(1.0, color="k", lw=0.7, ls="--")
        ax.set_xticks(range(len(vals)))
        ax.set_xticklabels([v["label"] for v in variants], fontsize=7, rotation=20)
        ax.set_ylabel("normalised RMS (all channels)")
        ax.set_title("waterfall: effects added one by one", fontsize=9)
        fig.tight_layout()
        fig.savefig(os.path.join(plots, "waterfall.png"), dpi=110)
        plt.close(fig)
    return 0


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.stderr.write(__doc__)
        sys.exit(2)
    sys.exit(main(sys.argv[1]))
