#!/usr/bin/env python3
"""docs/images/controller.png from `photonvr bench --suite controller --json FILE`: per scene,
the frame time over the walk (top) and the error against the references of the sampled views
(bottom), for the controller at each budget and for the best fixed setting that met that budget.
Given an `xr --stats` file of a run with --budget-ms instead: its frame times, predictions and
predicted error.

  plot_controller.py controller.json docs/images/controller.png
  plot_controller.py xr_stats.json docs/images/controller.png "TITLE"
"""
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def plot_loop_stats(doc, out, title):
    """An `xr --stats` / `view` file of a controlled loop: frame time and the predicted error."""
    c = doc["stats"]["controller"]
    frames = c["frames"]
    fig, (ta, ea) = plt.subplots(2, 1, figsize=(9, 6.5), sharex=True)
    ta.plot([f["ms"] for f in frames], lw=0.7, label="frame (CPU+GPU work)")
    ta.plot([f["predicted_ms"] for f in frames], lw=0.7, alpha=0.7, label="predicted")
    ta.axhline(c["budget_ms"], color="k", ls="--", lw=1, label=f"budget {c['budget_ms']:g} ms")
    ta.set_ylim(0, 2.2 * c["budget_ms"])
    ta.set_ylabel("ms")
    ta.set_title(title + f"\np99 {c['frame_ms']['p99']:.2f} ms, {c['frames_over_budget']} of {len(frames)} frames over, "
                 f"{c['changes']} changes")
    ta.legend(fontsize=8, loc="upper right")
    ea.plot([f["predicted_error"] for f in frames], lw=1)
    for k, f in enumerate(frames):
        if f["change"] not in ("hold",):
            ea.axvline(k, color="tab:red", lw=0.5, alpha=0.5)
    ea.set_yscale("log")
    ea.set_ylabel("predicted relMSE (quality model)")
    ea.set_xlabel("frame (90 Hz; red: the controller changed the setting)")
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    print("wrote", out)


def main():
    doc = json.load(open(sys.argv[1]))
    out = sys.argv[2]
    if isinstance(doc, dict) and "stats" in doc:
        plot_loop_stats(doc, out, sys.argv[3] if len(sys.argv) > 3 else doc.get("scene", ""))
        return
    rows = doc
    scenes = []
    for r in rows:
        if r.get("suite") == "controller" and r["scene"] not in scenes:
            scenes.append(r["scene"])
    fig, axes = plt.subplots(2, len(scenes), figsize=(7 * len(scenes), 7), squeeze=False, sharex="col")
    colours = ["tab:blue", "tab:orange", "tab:green", "tab:red"]
    for col, scene in enumerate(scenes):
        mine = [r for r in rows if r.get("suite") == "controller" and r["scene"] == scene]
        fixed = {json.dumps(r["setting"], sort_keys=True): r for r in mine if r["policy"] == "fixed"}
        summaries = [r for r in mine if r["policy"] == "summary"]
        ta, ea = axes[0][col], axes[1][col]
        for i, run in enumerate(r for r in mine if r["policy"] == "controller"):
            c = colours[i % len(colours)]
            budget = run["budget_ms"]
            frames = run["log"]["frames"]
            ta.plot([f["ms"] for f in frames], color=c, lw=0.7, label=f"controller, budget {budget:g} ms")
            ta.axhline(budget, color=c, ls="--", lw=1)
            sampled = [(k, f["measured_error"]) for k, f in enumerate(frames) if "measured_error" in f]
            ea.plot([k for k, _ in sampled], [e for _, e in sampled], "o-", color=c, ms=3, lw=1,
                    label=f"controller, {budget:g} ms")
            summary = next((s for s in summaries if s["budget_ms"] == budget), None)
            if summary and summary["best_fixed"] != "none":
                best = fixed.get(json.dumps(json.loads(summary["best_fixed"]), sort_keys=True))
                if best:
                    stride = best.get("frame_stride", 1)
                    index = best.get("frame_index", [k * stride for k in range(len(best["frame_ms"]))])
                    ta.plot(index, best["frame_ms"], color=c, lw=0.7, alpha=0.35, label=f"best fixed meeting {budget:g} ms")
                    ea.plot([e[0] for e in best["errors"]], [e[1] for e in best["errors"]], "x:", color=c, ms=4,
                            lw=1, alpha=0.6, label=f"best fixed, {budget:g} ms")
        ta.set_title(f"{scene}: frame time")
        ta.set_ylabel("ms (stereo frame)")
        ta.set_ylim(0, max(2.2 * max(s["budget_ms"] for s in summaries), 1))
        ta.legend(fontsize=7, loc="upper right")
        ea.set_title(f"{scene}: error of sampled frames")
        ea.set_ylabel("relMSE vs converged reference")
        ea.set_xlabel("frame (90 Hz)")
        ea.set_yscale("log")
        ea.legend(fontsize=7, loc="upper right")
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    print("wrote", out)


if __name__ == "__main__":
    main()
